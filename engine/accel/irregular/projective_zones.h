// The report's perspective reading of the irregular scheme, for primary rays: zones and depth
// slabs in the camera's projective space (u = x/z, v = y/z, depth z; docs/design.md section 4).
// Every ray from the eye has constant (u, v), so it stays in the zone of its pixel and only walks
// in depth: no corner pointer, no exit computation, the next slab is the next array entry.
//
// Boxes must lie in front of the eye: each camera-frame box is clipped to z >= zNear, and every
// primitive whose box reaches in front of zNear (for example a floor under the eye) is listed in
// one near region covering the depth [0, zNear] of every pixel. zNear is the smallest zmin of the
// boxes wholly in front of the eye, so scenes seen from outside have an empty near region.
//
// Why the lists are exact. A visible hit lies in its primitive's box, which the camera-frame box
// holds with a margin of 1e-9 of the scene scale (irregular.cpp). Along a ray from the eye a
// point at depth z has (u, v) = (dx/dz, dy/dz), and x/z over a box in front of the eye is
// extreme at its corners, so the hit's (u, v) lies strictly inside the projected rectangle (the
// margin, divided by a depth at most the scene scale, is over 1e-9, far beyond the rounding of
// the divisions), and its depth strictly inside the box's depth range. Region intervals are
// t = z / dz for the slab boundaries z, computed the same way for both neighbours, so they tile
// the ray without gap.
#pragma once

#include <algorithm>
#include <nlohmann/json.hpp>
#include <span>

#include "engine/accel/eval.h"
#include "engine/accel/irregular/camera_frame.h"
#include "engine/accel/irregular/region_hit.h"
#include "engine/accel/irregular/screen_bsp.h"

namespace lancer {

class ProjectiveZones {
  public:
    /// A slab as the walk reads it: where it starts in depth, where its list lies, and its tree
    /// or, in a union-only scene (no trees), its list's length. 16 bytes aligned to 16, so one
    /// line holds all three, the line the search for the walk's first slab ends on
    /// (docs/irregular.md, "Cache misses at 3 bounces").
    struct alignas(16) Slab {
        double lo = 0.0;    ///< depth where the slab starts
        uint32_t head = 0;  ///< where its list (its length, then its entries) lies in the lists
        /// Its restricted tree (-1: empty); the list's length when the scene is union-only.
        int32_t rootOrLength = -1;
    };

    /// Build over the camera-frame boxes `box` (padded) of the primitives `live`; empty when no
    /// box reaches in front of the eye. Figures go to `extra`.
    static ProjectiveZones build(const Scene& scene, const CameraFrame& frame,
                                 const std::vector<Box3>& box, const std::vector<uint32_t>& live,
                                 const ScreenBspParams& sp, nlohmann::json& extra,
                                 size_t maxSlabBytes = 0, size_t maxRegions = 0);
    /// Build centred on a point light, `frame`'s origin (its depth axis toward the scene), over
    /// the boxes `box` of that frame (padded): the structure shadow rays toward the light walk
    /// (covered by coversFromCentre), slab by slab toward the light. Unbounded in (u, v).
    static ProjectiveZones buildForLight(const Scene& scene, const CameraFrame& frame,
                                         const std::vector<Box3>& box,
                                         const std::vector<uint32_t>& live,
                                         const ScreenBspParams& sp, size_t maxSlabBytes = 0,
                                         size_t maxRegions = 0);

    /// This structure answers the ray: it starts exactly at the eye and its (u, v) is inside the
    /// rectangle the build projected the scene's boxes over (limLo_, limHi_; outside the zones'
    /// rectangle such a ray can meet only the near region's primitives). `rc` is the ray in the
    /// camera frame.
    bool covers(const Ray& world, const Ray& rc, double& u, double& v) const {
        if (zones_ == 0 || inward_ || world.o != eyePoint_ || !(rc.d.z > 0.0)) return false;
        u = rc.d.x / rc.d.z;
        v = rc.d.y / rc.d.z;
        return u >= limLo_.x && u <= limHi_.x && v >= limLo_.y && v <= limHi_.y;
    }
    /// A light's structure answers the ray `rc` (in its frame) that heads for the centre from in
    /// front of it: the caller's shadow ray toward this light, whose line passes through the
    /// centre to rounding. Every direction from the light was projected, so every such ray is.
    bool coversFromCentre(const Ray& rc, double& u, double& v) const {
        if (zones_ == 0 || !inward_ || !(rc.o.z > 0.0) || !(rc.d.z < 0.0)) return false;
        u = rc.o.x / rc.o.z;
        v = rc.o.y / rc.o.z;
        return u >= limLo_.x && u <= limHi_.x && v >= limLo_.y && v <= limHi_.y;
    }
    /// (u, v) lies in the zones' rectangle: the union of the projected boxes of every primitive
    /// reaching beyond zNear, so a covered ray outside it meets the near region's alone.
    bool inZones(double u, double v) const {
        return u >= lo_.x && u <= hi_.x && v >= lo_.y && v <= hi_.y;
    }

    /// Walk a covered ray: from the eye, the near region, then the slabs of its zone in depth;
    /// toward a light, the slabs of its zone from its origin's depth down, then the near region.
    /// Region ids reported to the observer start at `firstId`.
    template <class Obs>
    bool intersect(const Ray& ray, const Ray& rc, double u, double v, double tmin, double tmax,
                   uint32_t firstId, TraceContext& ctx, Obs& obs, Hit& hit) const;

    /// The zone holding (u, v), inside the zones' rectangle, as bsp_.locate(u, v, 0, 0) finds
    /// it: first the zone this structure's last walk in `ctx` located (a point on a line
    /// belongs to the zone below it, so the rectangle test is exact: lo < u <= hi on each axis,
    /// lo <= u on the rectangle's low border).
    uint32_t locate(double u, double v, TraceContext& ctx) const {
        uint32_t& hint = ctx.zoneHint[hintSlot_];
        const uint32_t z = hint;
        if (z < bsp_.zoneCount()) {
            const glm::dvec2 zl = bsp_.zoneLo[z], zh = bsp_.zoneHi[z];
            if ((u > zl.x || zl.x == lo_.x) && u <= zh.x && (v > zl.y || zl.y == lo_.y) &&
                v <= zh.y)
                return z;
        }
        hint = bsp_.locate(u, v, 0, 0);
        return hint;
    }
    /// The slot of ctx.zoneHint this structure's walks keep their last zone in.
    void setHintSlot(uint32_t slot) {
        hintSlot_ = slot % uint32_t(std::tuple_size_v<decltype(TraceContext::zoneHint)>);
    }

    size_t regionCount() const { return zones_ == 0 ? 0 : slabCount() + 1; }
    /// Walk over `scene`'s primitives from now on: a copy of the scene it was built over
    /// (the same Scene::preparedId), for a structure another build lends (BuildControl::previous).
    void rebind(const Scene& scene) { scene_ = &scene; }
    size_t memoryBytes() const;
    size_t zoneCount() const { return zones_; }
    /// Slabs that list nothing, zones with none but empty slabs.
    size_t emptySlabs() const { return emptySlabs_; }
    /// Built around a light: walked toward the centre (coversFromCentre), not from it.
    bool inward() const { return inward_; }
    /// The frame the structure is built in (the camera's, or the light's).
    const CameraFrame& frame() const { return frame_; }
    double zNear() const { return zNear_; }
    /// The zones, in (u, v).
    const ScreenBsp& screen() const { return bsp_; }
    /// Primitives listed in the near region [0, zNear].
    bool hasNearRegion() const { return unionOnly_ ? !nearPrims_.empty() : nearRoot_ >= 0; }
    /// The scene is union-only: slabs keep their primitive lists and no tree (roots -1).
    bool unionOnly() const { return unionOnly_; }

    // Inspection (structure_view.h).
    /// The screen rectangle in (u, v) that the zones tile.
    glm::dvec2 rectLo() const { return lo_; }
    glm::dvec2 rectHi() const { return hi_; }
    double zFar() const { return zFar_; }
    /// Zone z's slabs are [zoneFirst()[z], zoneFirst()[z + 1]).
    const std::vector<uint32_t>& zoneFirst() const { return zoneFirst_; }
    /// Depth where slab i starts; it ends where slab i + 1 of its zone starts, or at zFar().
    double slabLo(uint32_t i) const { return slabs_[i].lo; }
    int32_t slabRoot(uint32_t i) const { return unionOnly_ ? -1 : slabs_[i].rootOrLength; }
    /// Slab i's record, as the walk reads it.
    const Slab& slab(uint32_t i) const { return slabs_[i]; }
    /// The slabs' lists, each its length then its entries, at the slabs' heads (Slab::head).
    std::span<const uint32_t> lists() const { return listPrims_; }
    int nearRoot() const { return nearRoot_; }
    const CsgTree& treePool() const { return pool_; }
    /// Primitives of slab i (those whose projected box overlaps it).
    std::span<const uint32_t> slabPrimitives(uint32_t i) const {
        const Slab& s = slabs_[i];
        // Union-only: the length from the record, so a slab left by the pending check (most
        // of a shadow ray's) never reads its list's line.
        return {listPrims_.data() + s.head + 1,
                unionOnly_ ? uint32_t(s.rootOrLength) : listPrims_[s.head]};
    }
    /// What slab i adds to the slab the walk leaves for it (the one before it in depth, or, in a
    /// light's structure, the one after it; all of the zone's first slab walked): the primitives
    /// of its restricted tree (union-only: its list) that the tree of that slab lacks. A walk
    /// stepping from there fetches only these; the others it already holds.
    std::span<const uint32_t> slabEntering(uint32_t i) const {
        return {enterPrims_.data() + enterFirst_[i], enterPrims_.data() + enterFirst_[i + 1]};
    }
    /// Primitives of the near region.
    std::span<const uint32_t> nearPrimitives() const { return nearPrims_; }

  private:
    /// The zones and slabs over `box` seen from `frame`'s origin, within [limLo, limHi] in (u, v).
    static ProjectiveZones buildCentred(const Scene& scene, const CameraFrame& frame,
                                        glm::dvec2 limLo, glm::dvec2 limHi, bool inward,
                                        const std::vector<Box3>& box,
                                        const std::vector<uint32_t>& live,
                                        const ScreenBspParams& sp, size_t maxSlabBytes,
                                        size_t maxRegions);
    void buildEntering();

    const Scene* scene_ = nullptr;
    CameraFrame frame_;  ///< the camera frame the walk's events are told in the world from
    Vec3 eyePoint_{0.0};
    glm::dvec2 lo_{0.0}, hi_{0.0};        ///< the zones' rectangle in (u, v)
    glm::dvec2 limLo_{0.0}, limHi_{0.0};  ///< the rectangle the boxes were projected over
    double zNear_ = 0.0, zFar_ = 0.0;     ///< depth range of the slabs
    int nearRoot_ = -1;  ///< restricted tree of the primitives reaching in front of zNear
    size_t zones_ = 0;
    ScreenBsp bsp_;
    std::vector<uint32_t> zoneFirst_;  ///< zone z: slabs [zoneFirst_[z], zoneFirst_[z + 1])
    /// The slabs, zone by zone in depth; the last one of a zone ends at zFar_.
    std::vector<Slab> slabs_;
    size_t slabCount() const { return slabs_.size(); }
    CsgTree pool_;
    // The slabs' primitive lists, which the walk tests (hitInIrregularRegion), and their trees.
    /// The slabs' lists (Slab::head): each its length, then its entries (headedLists).
    std::vector<uint32_t> listPrims_;
    std::vector<uint32_t> nearPrims_;
    std::vector<uint32_t> enterFirst_, enterPrims_;  ///< slab i's entering list (slabEntering)
    bool unionOnly_ = false;
    bool inward_ = false;    ///< a light's structure (coversFromCentre)
    uint32_t hintSlot_ = 0;  ///< its slot of TraceContext::zoneHint
    size_t emptySlabs_ = 0, mergedZones_ = 0, coarseZones_ = 0;
};

template <class Obs>
bool ProjectiveZones::intersect(const Ray& ray, const Ray& rc, double u, double v, double tmin,
                                double tmax, uint32_t firstId, TraceContext& ctx, Obs& obs,
                                Hit& hit) const {
    const Scene& scene = *scene_;
    // A slab boundary at depth z is crossed at t = (z - oz) / dz, computed the same way for both
    // neighbours, so the intervals tile the ray (from the eye oz is 0 exactly: t = z / dz).
    const double oz = rc.o.z, dz = rc.d.z;
    auto tAt = [&](double z) { return (z - oz) / dz; };
    // The walk's events as the camera-frame walk tells them: the region the walk starts in
    // (Locate), then each region left before tmax through its far depth plane (from the eye) or
    // its near one (toward a light) (Exit: axis 2), the point (u z, v z, z) exactly on that
    // plane. The next region is the next slab of the zone in the walk's direction (the near
    // region's next is the zone's first slab, from the eye): no pointer to follow.
    [[maybe_unused]] bool located = false;
    [[maybe_unused]] auto enter = [&](uint32_t id, double t0) {
        if constexpr (Obs::kActive) {
            if (!located) obs.locate(frame_.toWorld(rc.at(t0)), id);
            located = true;
        }
    };
    [[maybe_unused]] auto leave = [&](double z) {
        if constexpr (Obs::kActive) {
            const double te = tAt(z);
            if (te < tmax) obs.regionExit(te, frame_.toWorld({u * z, v * z, z}), 2, 4);
        }
    };
    auto nearRegion = [&](double t0, double t1) {
        const uint32_t id = firstId + uint32_t(slabCount());
        enter(id, t0);
        ++ctx.counters.regionVisits;
        obs.region(id, t0, t1);
        return hitInIrregularRegion(scene, unionOnly_, nearPrims_, pool_, nearRoot_, ray, tmin, t0,
                                    t1, ctx, obs, hit, false);
    };
    // The first slab walked fetches its whole list, each later one what it adds, unless the
    // slab before it was evaluated lazily (hitInLeaf), fetching only part.
    bool heldBefore = false;
    auto slab = [&](uint32_t i, double t0, double t1) {
        enter(firstId + i, t0);
        ++ctx.counters.regionVisits;
        obs.region(firstId + i, t0, t1);
        std::optional<std::span<const uint32_t>> tests;
        if (heldBefore) tests = slabEntering(i);
        // The list's length from the record in a union-only scene (slabPrimitives), told apart
        // once here, so each inlined test keeps one path.
        const Slab& s = slabs_[i];
        const uint32_t* list = listPrims_.data() + s.head;
        const bool found =
            unionOnly_
                ? hitInIrregularRegion(scene, true, {list + 1, uint32_t(s.rootOrLength)}, pool_, -1,
                                       ray, tmin, t0, t1, ctx, obs, hit, false, tests)
                : hitInIrregularRegion(scene, false, {list + 1, list[0]}, pool_, s.rootOrLength,
                                       ray, tmin, t0, t1, ctx, obs, hit, false, tests);
        heldBefore = ctx.pending.tested;
        return found;
    };
    double t = tmin;
    ctx.beginLeafWalk();
    if (!inZones(u, v)) {
        // Outside every projected box beyond zNear: only the near region's primitives remain,
        // met before zNear from the eye, after it toward a light.
        if (!hasNearRegion()) return false;
        const double t0 = inward_ ? std::max(tAt(zNear_), t) : t;
        const double t1 = inward_ ? tmax : std::min(tAt(zNear_), tmax);
        return t0 <= t1 && nearRegion(t0, t1);
    }
    const uint32_t zone = locate(u, v, ctx);
    const uint32_t first = zoneFirst_[zone], last = zoneFirst_[zone + 1];
    if (!inward_) {
        if (hasNearRegion()) {
            const double t1 = std::min(tAt(zNear_), tmax);
            if (t <= t1) {
                if (nearRegion(t, t1)) return true;
                leave(zNear_);
            }
        }
        uint32_t i = first;
        // Skip the slabs wholly before tmin (a primary ray has tmin = 0: none).
        while (i + 1 < last && tAt(slabs_[i + 1].lo) < t) ++i;
        for (; i < last; ++i) {
            const double t0 = std::max(tAt(slabs_[i].lo), t);
            const double z1 = i + 1 < last ? slabs_[i + 1].lo : zFar_;
            const double t1 = std::min(tAt(z1), tmax);
            if (t0 > tmax) return false;
            if (slab(i, t0, t1)) return true;
            leave(z1);
        }
        return false;
    }
    // Toward the light: depth falls as t grows. Skip the slabs wholly before tmin (those beyond
    // the origin's depth), then walk down to the zone's first slab and the near region, whose
    // interval runs to tmax (the ray ends at the light, where only near primitives can lie).
    // The slab's start is crossed later the nearer the slab: a binary search for the last slab
    // whose start is not crossed before t (a shadow ray from deep in a zone of many slabs).
    const uint32_t i0 =
        uint32_t(std::partition_point(slabs_.begin() + first + 1, slabs_.begin() + last,
                                      [&](const Slab& s) { return !(tAt(s.lo) < t); }) -
                 slabs_.begin());
    uint32_t i = i0 - 1;
    // Slab i ends where slab i + 1 starts: that depth is the one the step before read.
    double z1 = i0 < last ? slabs_[i0].lo : zFar_;
    for (;; --i) {
        const double z0 = slabs_[i].lo;
        const double t0 = std::max(tAt(z1), t);
        const bool lastSlab = i == first && !hasNearRegion();
        const double t1 = lastSlab ? tmax : std::min(tAt(z0), tmax);
        if (t0 > tmax) return false;
        if (t0 <= t1) {
            if (slab(i, t0, t1)) return true;
            if (!lastSlab) leave(z0);
        }
        if (i == first) break;
        z1 = z0;
    }
    if (!hasNearRegion()) return false;
    const double t0 = std::max(tAt(zNear_), t);
    return t0 <= tmax && nearRegion(t0, tmax);
}

}  // namespace lancer
