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

#include <nlohmann/json.hpp>
#include <span>

#include "engine/accel/eval.h"
#include "engine/accel/irregular/camera_frame.h"
#include "engine/accel/irregular/region_hit.h"
#include "engine/accel/irregular/screen_bsp.h"

namespace lancer {

class ProjectiveZones {
  public:
    /// Build over the camera-frame boxes `box` (padded) of the primitives `live`; empty when no
    /// box reaches in front of the eye. Figures go to `extra`.
    static ProjectiveZones build(const Scene& scene, const CameraFrame& frame,
                                 const std::vector<Box3>& box, const std::vector<uint32_t>& live,
                                 const ScreenBspParams& sp, nlohmann::json& extra,
                                 size_t maxSlabBytes = 0, size_t maxRegions = 0);

    /// This structure answers the ray: it starts exactly at the eye and its (u, v) is inside the
    /// screen rectangle. `rc` is the ray in the camera frame.
    bool covers(const Ray& world, const Ray& rc, double& u, double& v) const {
        if (zones_ == 0 || world.o != eyePoint_ || !(rc.d.z > 0.0)) return false;
        u = rc.d.x / rc.d.z;
        v = rc.d.y / rc.d.z;
        return u >= lo_.x && u <= hi_.x && v >= lo_.y && v <= hi_.y;
    }

    /// Walk a covered ray: the near region, then the slabs of its zone in depth. Region ids
    /// reported to the observer start at `firstId`.
    template <class Obs>
    bool intersect(const Ray& ray, const Ray& rc, double u, double v, double tmin, double tmax,
                   uint32_t firstId, TraceContext& ctx, Obs& obs, Hit& hit) const;

    size_t regionCount() const { return zones_ == 0 ? 0 : slabRoot_.size() + 1; }
    size_t memoryBytes() const;
    size_t zoneCount() const { return zones_; }
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
    double slabLo(uint32_t i) const { return slabLo_[i]; }
    int32_t slabRoot(uint32_t i) const { return slabRoot_[i]; }
    int nearRoot() const { return nearRoot_; }
    const CsgTree& treePool() const { return pool_; }
    /// Primitives of slab i (those whose projected box overlaps it).
    std::span<const uint32_t> slabPrimitives(uint32_t i) const {
        uint32_t l = slabList_[i];
        return {listPrims_.data() + listFirst_[l], listPrims_.data() + listFirst_[l + 1]};
    }
    /// What slab i adds to the slab before it in its zone (all of the first slab's): the
    /// primitives of its restricted tree (union-only: its list) that the tree of the slab before
    /// lacks. A walk stepping from slab i - 1 fetches only these; the others it already holds.
    std::span<const uint32_t> slabEntering(uint32_t i) const {
        return {enterPrims_.data() + enterFirst_[i], enterPrims_.data() + enterFirst_[i + 1]};
    }
    /// Primitives of the near region.
    std::span<const uint32_t> nearPrimitives() const { return nearPrims_; }

  private:
    void buildEntering();

    const Scene* scene_ = nullptr;
    CameraFrame frame_;  ///< the camera frame the walk's events are told in the world from
    Vec3 eyePoint_{0.0};
    glm::dvec2 lo_{0.0}, hi_{0.0};     ///< the screen rectangle in (u, v)
    double zNear_ = 0.0, zFar_ = 0.0;  ///< depth range of the slabs
    int nearRoot_ = -1;  ///< restricted tree of the primitives reaching in front of zNear
    size_t zones_ = 0;
    ScreenBsp bsp_;
    std::vector<uint32_t> zoneFirst_;  ///< zone z: slabs [zoneFirst_[z], zoneFirst_[z + 1])
    std::vector<double> slabLo_;       ///< depth where each slab starts; the last one ends at zFar_
    std::vector<int32_t> slabRoot_;    ///< restricted tree of each slab (-1: empty)
    CsgTree pool_;
    // The slabs' primitive lists, which the walk tests (hitInIrregularRegion), and their trees.
    std::vector<uint32_t> slabList_;  ///< list of each slab
    std::vector<uint32_t> listFirst_, listPrims_;
    std::vector<uint32_t> nearPrims_;
    std::vector<uint32_t> enterFirst_, enterPrims_;  ///< slab i's entering list (slabEntering)
    bool unionOnly_ = false;
};

template <class Obs>
bool ProjectiveZones::intersect(const Ray& ray, const Ray& rc, double u, double v, double tmin,
                                double tmax, uint32_t firstId, TraceContext& ctx, Obs& obs,
                                Hit& hit) const {
    const Scene& scene = *scene_;
    const double dz = rc.d.z;
    // The walk's events as the camera-frame walk tells them: the region the walk starts in
    // (Locate), then each region left before tmax through its far depth plane (Exit: axis 2,
    // the high side), the point exactly on that plane. The next region is the next slab of the
    // zone (the near region's next is the zone's first slab): no pointer to follow.
    [[maybe_unused]] bool located = false;
    [[maybe_unused]] auto enter = [&](uint32_t id, double t0) {
        if constexpr (Obs::kActive) {
            if (!located) obs.locate(frame_.toWorld(rc.at(t0)), id);
            located = true;
        }
    };
    [[maybe_unused]] auto leave = [&](double z) {
        if constexpr (Obs::kActive) {
            const double te = z / dz;
            if (te < tmax) obs.regionExit(te, frame_.toWorld({u * z, v * z, z}), 2, 4);
        }
    };
    double t = tmin;
    ctx.beginLeafWalk();
    if (hasNearRegion()) {
        double t1 = std::min(zNear_ / dz, tmax);
        if (t <= t1) {
            const uint32_t id = firstId + uint32_t(slabRoot_.size());
            enter(id, t);
            ++ctx.counters.regionVisits;
            obs.region(id, t, t1);
            if (hitInIrregularRegion(scene, unionOnly_, nearPrims_, pool_, nearRoot_, ray, tmin, t,
                                     t1, ctx, obs, hit))
                return true;
            leave(zNear_);
        }
    }
    uint32_t zone = bsp_.locate(u, v, 0, 0);
    uint32_t i = zoneFirst_[zone], last = zoneFirst_[zone + 1];
    // Skip the slabs wholly before tmin (a primary ray has tmin = 0: none).
    while (i + 1 < last && slabLo_[i + 1] / dz < t) ++i;
    // The first slab walked fetches its whole list, each later one what it adds, unless the
    // slab before it was evaluated lazily (hitInLeaf), fetching only part.
    bool heldBefore = false;
    for (; i < last; ++i) {
        double t0 = std::max(slabLo_[i] / dz, t);
        double z1 = i + 1 < last ? slabLo_[i + 1] : zFar_;
        double t1 = std::min(z1 / dz, tmax);
        if (t0 > tmax) return false;
        enter(firstId + i, t0);
        ++ctx.counters.regionVisits;
        obs.region(firstId + i, t0, t1);
        const std::span<const uint32_t> prims = slabPrimitives(i);
        std::optional<std::span<const uint32_t>> tests;
        if (heldBefore) tests = slabEntering(i);
        if (hitInIrregularRegion(scene, unionOnly_, prims, pool_, slabRoot_[i], ray, tmin, t0, t1,
                                 ctx, obs, hit, tests))
            return true;
        heldBefore = ctx.pending.tested;
        leave(z1);
    }
    return false;
}

}  // namespace lancer
