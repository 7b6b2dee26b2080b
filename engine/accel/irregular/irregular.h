// The irregular subdivision of Arnaldi, Priol and Bouatouch (report, section 2; docs/design.md
// section 4): a screen BSP of the primitives' projected boxes (screen_bsp.h), each zone cut in
// depth slabs (depth_slabs.h), the slabs linked by corner pointers (corner_pointers.h), and a
// walk that follows a ray from region to region by those pointers alone.
//
// Everything lives in the camera frame (camera_frame.h): screen x, screen y, depth z. The frame
// is orthonormal and camera-relative, so every ray, primary (orthographic or perspective) or
// secondary, from any origin, is walked the same way; t is the same in both frames.
//
// Why the six corner pointers of region.h are enough. Zones tile the screen rectangle and every
// zone is a full-depth column of slabs, so:
//  - across a depth face the neighbour is unique: the next slab of the same column (lo[2]/hi[2]);
//  - across a screen face, say x = xhi, the neighbours form a column of zones stacked along y
//    (a T-junction: several neighbours per face). hi[0] lands on the topmost of them (it holds
//    the point just above xhi, just below yhi). From a neighbour N, N.lo[1] holds the point just
//    right of N.xlo = xhi and just below N.ylo: while N.ylo is above the exit point that point is
//    still on our face, so it is the next neighbour down. The walk down the face therefore
//    visits only face neighbours and stops at the one holding the exit point's y. The other
//    faces are symmetric: a low face starts at lo[a] (the lowest neighbour) and walks up by hi[b].
//    The depth is then found in that zone's column by lo[2]/hi[2].
//  - an exit through an edge or a corner: the walk crosses one of the tied faces; the exit point
//    lies on a border of the face, where the face walk stops on a neighbour that only touches
//    the point. The ray spends a zero-length interval there, and that region's own exit has the
//    same t (its far plane is the same coordinate, so the same floating-point division), so the
//    next crossing takes the next tied axis. At most three crossings per point.
// Ties use the ray's direction: a point on a plane belongs to the side the ray goes to, so a walk
// never steps back; t never decreases and the number of steps is bounded, beyond which the ray
// ends with a counted walk error.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <span>

#include "engine/accel/build_params.h"
#include "engine/accel/eval.h"
#include "engine/accel/irregular/camera_frame.h"
#include "engine/accel/irregular/projective_zones.h"
#include "engine/accel/irregular/region.h"
#include "engine/accel/irregular/region_hit.h"
#include "engine/accel/irregular/screen_bsp.h"

namespace lancer {

class BuildGuard;    // build_guard.h
struct FrameChoice;  // regular/grid_frame.h

class IrregularSubdivision {
  public:
    static constexpr SchemeKind kKind = SchemeKind::Irregular;  ///< its row of kSchemeTable
    /// Its knobs in `p`.
    static const IrregularConfig& config(const BuildParams& p) { return p.irregular; }

    /// Build over a prepared scene from scene.camera; scheme figures go to `extra`. Throws
    /// std::invalid_argument for refused parameters or a structure over its limits,
    /// BuildCancelled when `guard`'s stop is requested. Within the guard's memory budget the 2D
    /// step stops and slabs merge. `guard` null: a default BuildGuard (the default budget, no
    /// cancellation). `previous`: a structure built over a copy of the same prepared scene
    /// for another camera (BuildControl::previous), whose lights' structures are taken (copied)
    /// when they were built with the same knobs, budget and image size; null: none.
    static IrregularSubdivision build(const Scene& scene, const IrregularConfig& params,
                                      nlohmann::json& extra, BuildGuard* guard = nullptr,
                                      const IrregularSubdivision* previous = nullptr);

    template <class Obs>
    bool intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                   Hit& hit) const;
    /// intersect()'s answer for a shadow ray toward scene light `light` (its direction points at
    /// the light): walked in the light's projective structure when it has one and covers the
    /// ray (in double precision), else as intersect() walks it.
    template <class Obs>
    bool intersectTowardLight(const Ray& ray, uint32_t light, double tmin, double tmax,
                              TraceContext& ctx, Obs& obs, Hit& hit) const;

    size_t regionCount() const {
        return lightFirstRegion_.empty() ? regions_.size() + projective_.regionCount()
                                         : lightFirstRegion_.back();
    }
    size_t memoryBytes() const;
    bool usesMailboxes() const { return true; }

    // Inspection (tests, viewer).
    const CameraFrame& frame() const { return frame_; }
    /// The structure's box in the camera frame: the scene bounds' bound there, padded.
    const Box3& bounds() const { return bounds_; }
    const std::vector<IrregularRegion>& regions() const { return regions_; }
    const ScreenBsp& screen() const { return bsp_; }
    /// The projective zones that primary rays walk (empty with --irregular-frame camera).
    const ProjectiveZones& projective() const { return projective_; }
    /// Per scene light, the projective structure centred on it that shadow rays toward it walk
    /// (empty: the light lies inside the scene's bounds, or its structure was not built; the
    /// rays take the camera-frame walk).
    const std::vector<ProjectiveZones>& lights() const { return lights_; }
    /// Region ids of light i's structure start at lightFirstRegion()[i] (after the camera
    /// frame's and the eye's); the last entry is regionCount().
    const std::vector<uint32_t>& lightFirstRegion() const { return lightFirstRegion_; }
    /// Zone z's regions are [zoneFirstRegion()[z], zoneFirstRegion()[z + 1]), by depth.
    const std::vector<uint32_t>& zoneFirstRegion() const { return zoneFirstRegion_; }
    /// The pool of the regions' restricted trees (empty when unionOnly()).
    const CsgTree& treePool() const { return pool_; }
    /// The scene is union-only: regions keep their primitive lists and no tree (root -1); the
    /// walk merges the listed primitives' spans (hitInLeaf, flatUnion).
    bool unionOnly() const { return unionOnly_; }
    /// Primitives of a region (the shared ones, shared(), are not among them).
    std::span<const uint32_t> primitives(uint32_t region) const {
        const std::span<const uint32_t> all = heldPrimitives(region);
        return all.first(all.size() - shared_.size());
    }
    /// The primitives the walk merges in region r: its list, then shared() (the structure view
    /// and dump show these as the region's).
    std::span<const uint32_t> heldPrimitives(uint32_t region) const {
        return listAt(regions_[region].first);
    }
    /// List l as the list table gives it (its own primitives, then shared()): the one each
    /// region whose `list` is l reads from its `first`.
    std::span<const uint32_t> list(uint32_t l) const { return listAt(listFirst_[l]); }
    /// Zone z's rectangle as the walk reads it (region.h): the screen BSP's, in one line.
    const IrregularZoneRect& zoneRect(uint32_t z) const { return zoneRect_[z]; }
    /// The primitives that no camera-frame list holds and that every camera-frame region
    /// tests (union-only scenes: those whose projected box covers a large share of the
    /// structure's screen rectangle, such as a floor; docs/irregular.md, "Secondary rays in the
    /// camera frame"). Empty in a CSG scene.
    std::span<const uint32_t> shared() const { return shared_; }
    /// The bound of the listed primitives' camera-frame boxes, padded: with shared primitives,
    /// a walk past it goes on only while one of theirs has a boundary ahead.
    const Box3& occupied() const { return occupied_; }
    /// Region r's box in the camera frame: its zone's rectangle times its depth range.
    Box3 regionBox(uint32_t r) const { return boxOf(regions_[r]); }
    /// Region r's corner pointer across its face on axis a, at its high corner (`high`) or its
    /// low one (region.h): stored on the screen axes, the next or previous slab of its zone in
    /// depth; -1 where that face is the structure's border.
    int32_t pointer(uint32_t r, int a, bool high) const {
        const IrregularRegion& R = regions_[r];
        if (a < 2) return high ? R.hi[a] : R.lo[a];
        if (high) return R.zhi < bounds_.hi.z ? int32_t(r + 1) : -1;
        return R.zlo > bounds_.lo.z ? int32_t(r - 1) : -1;
    }
    /// Does region r hold camera point p, on the side of direction d where p lies on a cut?
    bool holds(uint32_t r, const Vec3& p, const Vec3& d) const {
        for (int a = 0; a < 3; ++a)
            if (below(r, a, p, d) || above(r, a, p, d)) return false;
        return true;
    }
    /// The region holding camera point p (side of d): screen BSP and binary search over the
    /// zone's slabs. Only the start of a walk uses it.
    uint32_t locate(const Vec3& p, const Vec3& d) const;
    /// The region holding camera point p, reached from region `from` by corner pointers alone
    /// (walking the segment from its centre to p); -1 after a walk error.
    int64_t walkTo(uint32_t from, const Vec3& p) const;

  private:
    /// Region ids of the lights' structures (lights_, with lightsInside_, lightsOverLimit_ and
    /// lightOver_ set) and their figures to `extra`: ms[i] light i's build time (empty: taken
    /// from `previous` build, not built).
    void finishLights(const std::vector<double>& ms, nlohmann::json& extra);
    /// Bytes of the lights' structures.
    size_t lightBytes() const;

    /// What the lights' structures depend on besides the scene's geometry and lights (none of
    /// it the camera): a build over the same prepared scene with an equal key takes them.
    struct LightKey {
        uint64_t scene = 0;  ///< Scene::preparedId
        IrregularConfig config;
        size_t share = 0;       ///< each structure's share of the budget
        size_t maxRegions = 0;  ///< the slabs' region bound (it follows the image size)
        size_t pixels = 0;      ///< the image's: the cost stop's rays toward each light
        bool operator==(const LightKey&) const = default;
    };
    /// The list whose length is listPrims_[head], its entries after it.
    std::span<const uint32_t> listAt(uint32_t head) const {
        return {listPrims_.data() + head + 1, listPrims_[head]};
    }
    /// Region R's box: its zone's rectangle times its depth range (region.h).
    Box3 boxOf(const IrregularRegion& R) const {
        const IrregularZoneRect& z = zoneRect_[R.zone];
        return {Vec3(z.lo, R.zlo), Vec3(z.hi, R.zhi)};
    }
    /// Region R's low and high bounds on axis a: its zone's on the screen axes, its own in depth.
    double lowOf(const IrregularRegion& R, int a) const {
        return a < 2 ? zoneRect_[R.zone].lo[a] : R.zlo;
    }
    double highOf(const IrregularRegion& R, int a) const {
        return a < 2 ? zoneRect_[R.zone].hi[a] : R.zhi;
    }
    /// p is below region r on axis a (or on its low face, going down).
    bool below(uint32_t r, int a, const Vec3& p, const Vec3& d) const {
        const double lo = lowOf(regions_[r], a);
        return p[a] < lo || (p[a] == lo && d[a] < 0.0 && lo > bounds_.lo[a]);
    }
    bool above(uint32_t r, int a, const Vec3& p, const Vec3& d) const {
        const double hi = highOf(regions_[r], a);
        return p[a] > hi || (p[a] == hi && d[a] > 0.0 && hi < bounds_.hi[a]);
    }
    /// Where the ray leaves region r after t: the exit parameter, the axis crossed (the first
    /// of the tied ones), the tied axes (a bit mask), and the exit point, exactly on every tied
    /// plane.
    double exitOf(const IrregularRegion& r, const Ray& rc, double t, int& axis, int& ties,
                  Vec3& p) const;
    /// A boundary of a shared primitive (fetched by this walk) lies in [t0, t1] after tmin.
    bool sharedAhead(double tmin, double t0, double t1, TraceContext& ctx) const {
        for (uint32_t p : shared_) {
            const Mailbox* m = ctx.heldMailbox(p);
            for (int k = 0; m && k < m->count; ++k)
                for (const Boundary& b : {m->spans[k].in, m->spans[k].out})
                    if (b.t >= t0 && b.t <= t1 && b.t > tmin) return true;
        }
        return false;
    }
    /// The face of r that a ray going along d leaves through on axis a is the structure's border.
    bool onBorder(const IrregularRegion& r, int a, const Vec3& d) const {
        return d[a] > 0.0 ? highOf(r, a) == bounds_.hi[a] : lowOf(r, a) == bounds_.lo[a];
    }
    /// The region beyond region r's face on `axis` that holds p, by corner pointers.
    template <class Obs>
    int64_t cross(uint32_t r, int axis, const Vec3& p, const Vec3& d, Obs& obs, uint64_t& steps,
                  size_t& budget) const;

    const Scene* scene_ = nullptr;
    CameraFrame frame_;
    Box3 bounds_;
    Box3 occupied_;  ///< occupied()
    ScreenBsp bsp_;
    ProjectiveZones projective_;              ///< primary rays (region ids from regions_.size() on)
    std::vector<ProjectiveZones> lights_;     ///< per scene light: shadow rays toward it
    std::vector<uint32_t> lightFirstRegion_;  ///< region ids of lights_[i] from [i] on
    LightKey lightKey_;                       ///< what lights_ were built for
    /// Lights inside the bounds, beyond the limit, and whether each was over its share: the
    /// counts of the build that made lights_, reported again by one that takes them.
    size_t lightsInside_ = 0, lightsOverLimit_ = 0;
    std::vector<char> lightOver_;
    std::vector<IrregularRegion> regions_;
    std::vector<uint32_t> zoneFirstRegion_;    ///< zone z: regions [zoneFirstRegion_[z], [z + 1])
    std::vector<IrregularZoneRect> zoneRect_;  ///< bsp_'s zone rectangles, one line each
    CsgTree pool_;
    /// List l lies at listFirst_[l] in listPrims_: its length, its own primitives, then the
    /// shared ones, so a region's walk merges both without copying and reads the length from
    /// the line that holds the first entries (IrregularRegion::first is listFirst_[list]).
    std::vector<uint32_t> listFirst_, listPrims_;
    std::vector<uint32_t> shared_;  ///< shared(): in no list, tested by every camera-frame walk
    size_t budget_ = 0;             ///< steps allowed to one walk
    bool unionOnly_ = false;
};

template <class Obs>
int64_t IrregularSubdivision::cross(uint32_t r, int axis, const Vec3& p, const Vec3& d, Obs& obs,
                                    uint64_t& steps, size_t& budget) const {
    auto follow = [&](uint32_t from, int32_t to, int corner) -> bool {
        if (to < 0 || budget == 0) return false;
        --budget;
        ++steps;
        obs.pointer(from, uint32_t(to), corner);
        return true;
    };
    bool up = d[axis] > 0.0;
    int32_t n = pointer(r, axis, up);
    if (!follow(r, n, up ? kHighCorner : kLowCorner)) return -1;
    if (axis < 2) {
        // Along the face: down from the high corner's neighbour, up from the low corner's.
        int b = 1 - axis;
        if (up) {
            while (below(uint32_t(n), b, p, d)) {
                int32_t m = regions_[n].lo[b];
                if (!follow(uint32_t(n), m, kLowCorner)) return -1;
                n = m;
            }
        } else {
            while (above(uint32_t(n), b, p, d)) {
                int32_t m = regions_[n].hi[b];
                if (!follow(uint32_t(n), m, kHighCorner)) return -1;
                n = m;
            }
        }
    }
    // In depth, inside the zone's column: its slabs share its footprint, so both ways are open.
    while (below(uint32_t(n), 2, p, d)) {
        int32_t m = pointer(uint32_t(n), 2, false);
        if (!follow(uint32_t(n), m, kLowCorner)) return -1;
        n = m;
    }
    while (above(uint32_t(n), 2, p, d)) {
        int32_t m = pointer(uint32_t(n), 2, true);
        if (!follow(uint32_t(n), m, kHighCorner)) return -1;
        n = m;
    }
    return n;
}

template <class Obs>
bool IrregularSubdivision::intersectTowardLight(const Ray& ray, uint32_t light, double tmin,
                                                double tmax, TraceContext& ctx, Obs& obs,
                                                Hit& hit) const {
    // A float test (--precision float) strays by up to floatSlack, far beyond the boxes'
    // padding: near its origin a shadow ray may meet in float a primitive whose padded box it
    // never enters (its own surface, offset 1e-7 off it), which the light's slab, cut at that
    // box's depth, does not list. Those rays keep the camera-frame walk.
    if (light < lights_.size() && ctx.precision == Precision::Double) {
        const ProjectiveZones& lz = lights_[light];
        const Ray rl = lz.frame().ray(ray);
        if (double u, v; lz.coversFromCentre(rl, u, v))
            return lz.intersect(ray, rl, u, v, tmin, tmax, lightFirstRegion_[light], ctx, obs, hit);
    }
    return intersect(ray, tmin, tmax, ctx, obs, hit);
}

template <class Obs>
bool IrregularSubdivision::intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx,
                                     Obs& obs, Hit& hit) const {
    if (regions_.empty()) return false;
    Ray rc = frame_.ray(ray);
    if (double u, v; projective_.covers(ray, rc, u, v))
        return projective_.intersect(ray, rc, u, v, tmin, tmax, uint32_t(regions_.size()), ctx, obs,
                                     hit);
    double tw0, tw1;
    if (!clipLine(rc, bounds_, tw0, tw1)) return false;
    double t = std::max(tw0, tmin), tend = std::min(tw1, tmax);
    if (!(t <= tend)) return false;
    // No listed primitive has a boundary beyond the box of their boxes (occupied()): past
    // where the ray leaves it, only the shared primitives can be met (below).
    double tOut = tend;
    if (double o0, o1; !shared_.empty()) tOut = clipLine(rc, occupied_, o0, o1) ? o1 : -kInf;
    uint32_t r = locate(glm::clamp(rc.at(t), bounds_.lo, bounds_.hi), rc.d);
    if constexpr (Obs::kActive)
        obs.locate(frame_.toWorld(glm::clamp(rc.at(t), bounds_.lo, bounds_.hi)), r);
    size_t budget = budget_;
    ctx.beginLeafWalk();
    bool first = true;
    for (;;) {
        const IrregularRegion& R = regions_[r];
        int axis, ties;
        Vec3 p;
        double te = exitOf(R, rc, t, axis, ties, p);
        double t1 = std::min(te, tend);
        ++ctx.counters.regionVisits;
        obs.region(r, t, t1);
        // The shared primitives are merged in every region, fetched in the first one; after it
        // only the region's own list is fetched (the others are in their mailboxes).
        const std::span<const uint32_t> all = listAt(R.first);
        std::optional<std::span<const uint32_t>> fetch;
        if (!shared_.empty() && !first) fetch = all.first(all.size() - shared_.size());
        first = false;
        if (hitInIrregularRegion(*scene_, unionOnly_, all, pool_, R.root, ray, tmin, t, t1, ctx,
                                 obs, hit, true, fetch))
            return true;
        if (te >= tend) return false;
        // Beyond the listed primitives' box only the shared ones can be met: with none of
        // their boundaries ahead, the ray meets nothing more.
        if (te >= tOut && !sharedAhead(tmin, te, tend, ctx)) return false;
        if constexpr (Obs::kActive) obs.regionExit(te, frame_.toWorld(p), axis, ties);
        // Out through the structure's border (a face, or an edge or corner touching it).
        for (int a = 0; a < 3; ++a)
            if ((ties >> a & 1) && onBorder(R, a, rc.d)) return false;
        int64_t next =
            budget > 0 ? cross(r, axis, p, rc.d, obs, ctx.counters.pointerSteps, budget) : -1;
        if (next < 0) {
            ++ctx.counters.walkErrors;
            obs.walkError(budget == 0 ? "irregular walk: step budget exhausted"
                                      : "irregular walk: no corner pointer toward the exit point");
            return false;
        }
        if (budget > 0) --budget;
        r = uint32_t(next);
        t = te;
    }
}

}  // namespace lancer
