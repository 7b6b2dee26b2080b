#include "engine/accel/irregular/projective_zones.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "engine/accel/build_guard.h"
#include "engine/accel/irregular/depth_slabs.h"
#include "engine/accel/irregular/primitive_hulls.h"
#include "engine/model/restriction.h"

namespace lancer {

ProjectiveZones ProjectiveZones::build(const Scene& scene, const CameraFrame& frame,
                                       const std::vector<Box3>& box,
                                       const std::vector<uint32_t>& live, const ScreenBspParams& sp,
                                       nlohmann::json& extra, size_t maxSlabBytes,
                                       size_t maxRegions) {
    const Camera& cam = scene.camera;
    if (cam.projection != Projection::Perspective) {
        ProjectiveZones s;
        s.scene_ = &scene;
        s.frame_ = frame;
        s.eyePoint_ = frame.origin;
        return s;
    }
    // The screen rectangle: every pixel of the scene's camera for any aspect ratio up to 4:1
    // (wider images, and rays outside it, take the camera-frame walk).
    double half = std::tan(glm::radians(cam.fov) * 0.5);
    double aspect = std::max(4.0, double(scene.width) / double(std::max(scene.height, 1)));
    glm::dvec2 limLo(-half * aspect, -half * (1.0 + 1e-6)),
        limHi(half * aspect, half * (1.0 + 1e-6));
    // The walk model's rays: a pixel's each, over the image's rectangle in (u, v).
    ScreenBspParams eyeSp = sp;
    ZoneWalkModel eyeWalk;
    if (sp.walk) {
        eyeWalk = *sp.walk;
        const double w = std::max(scene.width, 1), h = std::max(scene.height, 1);
        eyeWalk.raysPerArea = w * h / (4.0 * half * half * w / h);
        eyeWalk.rays = 0.0;
        eyeSp.walk = &eyeWalk;
    }
    ProjectiveZones s =
        buildCentred(scene, frame, limLo, limHi, false, box, live, eyeSp, maxSlabBytes, maxRegions);
    if (s.zones_ == 0) return s;
    extra["projective_zones"] = s.zones_;
    extra["projective_slabs"] = s.slabCount();
    extra["projective_empty_slabs"] = s.emptySlabs_;
    extra["projective_bsp_stopped"] = s.bsp_.stopped;
    extra["projective_merged_zones"] = s.mergedZones_;
    extra["projective_coarse_zones"] = s.coarseZones_;
    extra["projective_near_primitives"] = s.nearPrims_.size();
    extra["projective_znear"] = s.zNear_;
    return s;
}

ProjectiveZones ProjectiveZones::buildForLight(const Scene& scene, const CameraFrame& frame,
                                               const std::vector<Box3>& box,
                                               const std::vector<uint32_t>& live,
                                               const ScreenBspParams& sp, size_t maxSlabBytes,
                                               size_t maxRegions) {
    // Every direction from the light: a shadow ray's zone is where its origin's (u, v) falls.
    return buildCentred(scene, frame, glm::dvec2(-kInf), glm::dvec2(kInf), true, box, live, sp,
                        maxSlabBytes, maxRegions);
}

ProjectiveZones ProjectiveZones::buildCentred(const Scene& scene, const CameraFrame& frame,
                                              glm::dvec2 limLo, glm::dvec2 limHi, bool inward,
                                              const std::vector<Box3>& box,
                                              const std::vector<uint32_t>& live,
                                              const ScreenBspParams& sp, size_t maxSlabBytes,
                                              size_t maxRegions) {
    ProjectiveZones s;
    s.scene_ = &scene;
    s.frame_ = frame;
    s.eyePoint_ = frame.origin;
    s.inward_ = inward;
    s.limLo_ = limLo;
    s.limHi_ = limHi;

    // zNear: the nearest box wholly in front of the centre.
    double zNear = kInf, zFar = 0.0;
    for (uint32_t p : live) {
        if (box[p].lo.z > 0.0) zNear = std::min(zNear, box[p].lo.z);
        zFar = std::max(zFar, box[p].hi.z);
    }
    if (!(zFar > 0.0)) return s;  // nothing in front of the centre
    if (zNear == kInf) zNear = 1e-3 * zFar;

    // Projected boxes: x/z over a box in front of the eye is extreme at its corners. A relative
    // pad of 1e-12 covers the rounding of these divisions (the camera-frame padding gives the
    // hit points a margin above 1e-9).
    std::vector<Box3> pbox(scene.prims.size());
    std::vector<uint32_t> inside, nearPrims;
    glm::dvec2 lo(kInf), hi(-kInf);
    for (uint32_t p : live) {
        if (sp.guard && (p & 8191) == 0) sp.guard->poll();
        const Box3& b = box[p];
        if (b.lo.z < zNear) nearPrims.push_back(p);
        if (!(b.hi.z > zNear)) continue;
        double z0 = std::max(b.lo.z, zNear), z1 = b.hi.z;
        Box3 q;
        q.lo.z = z0;
        q.hi.z = z1;
        for (int a = 0; a < 2; ++a) {
            double c[4] = {b.lo[a] / z0, b.lo[a] / z1, b.hi[a] / z0, b.hi[a] / z1};
            double mn = std::min({c[0], c[1], c[2], c[3]}), mx = std::max({c[0], c[1], c[2], c[3]});
            mn -= 1e-12 * std::max(1.0, std::abs(mn));
            mx += 1e-12 * std::max(1.0, std::abs(mx));
            q.lo[a] = std::max(mn, limLo[a]);
            q.hi[a] = std::min(mx, limHi[a]);
        }
        if (!(q.lo.x < q.hi.x && q.lo.y < q.hi.y)) continue;  // outside the screen rectangle
        pbox[p] = q;
        inside.push_back(p);
        lo = glm::min(lo, glm::dvec2(q.lo));
        hi = glm::max(hi, glm::dvec2(q.hi));
    }
    if (inside.empty()) return s;
    s.lo_ = lo;
    s.hi_ = hi;
    s.zNear_ = zNear;
    s.zFar_ = zFar;
    ScreenBspParams eyeParams = sp;
    eyeParams.column = ZoneColumn::FromEye;
    ZoneWalkModel walk;
    if (sp.walk && sp.walk->rays > 0.0) {
        // Rays spread evenly over the zones' rectangle (a light's shadow rays).
        walk = *sp.walk;
        walk.raysPerArea = walk.rays / ((hi.x - lo.x) * (hi.y - lo.y));
        eyeParams.walk = &walk;
    }
    s.bsp_ = ScreenBsp::build(pbox, inside, lo, hi, eyeParams);
    const std::vector<glm::dvec2> depth =
        sp.hulls
            ? narrowZones(s.bsp_, *sp.hulls, ZoneColumn::FromEye, pbox, zNear, zFar, sp.hullPad,
                          sp.guard)
            : narrowZones(s.bsp_, PrimitiveHulls{}, ZoneColumn::FromEye, pbox, zNear, zFar, 0.0);
    DepthSlabs slabs =
        buildDepthSlabs(scene, s.bsp_, depth, zNear, zFar, sp.guard, maxSlabBytes, maxRegions);
    s.zones_ = s.bsp_.zoneCount();
    s.zoneFirst_ = std::move(slabs.zoneFirstRegion);
    if (sp.guard) sp.guard->poll();
    s.pool_ = std::move(slabs.pool);
    s.unionOnly_ = slabs.unionOnly;
    // Each slab keeps where its list lies (its length, then its entries): the walk reads the
    // list from one place, no table of list starts kept. A union-only scene's slab has no
    // tree: its record keeps the list's length there instead.
    std::vector<uint32_t> heads;
    s.listPrims_ = headedLists(slabs.listFirst, slabs.listPrims, {}, heads);
    s.slabs_.reserve(slabs.regions.size());
    for (const IrregularRegion& r : slabs.regions) {
        const uint32_t h = heads[r.list];
        s.slabs_.push_back({r.zlo, h, s.unionOnly_ ? int32_t(s.listPrims_[h]) : r.root});
    }
    s.buildEntering();
    std::sort(nearPrims.begin(), nearPrims.end());
    if (!nearPrims.empty() && !s.unionOnly_)
        s.nearRoot_ = TreeRestrictor(scene.tree).restrict(nearPrims, s.pool_);
    s.nearPrims_ = nearPrims;
    s.emptySlabs_ = slabs.emptySlabs + slabs.emptyZones;
    s.mergedZones_ = slabs.mergedZones;
    s.coarseZones_ = slabs.coarseZones;
    return s;
}

void ProjectiveZones::buildEntering() {
    // A slab's tree primitives: a restriction drops those that cannot change its result, so a
    // walk need not fetch them (its list keeps every primitive whose box overlaps it).
    auto treePrims = [&](uint32_t i, std::vector<uint32_t>& out) {
        if (unionOnly_) {
            std::span<const uint32_t> l = slabPrimitives(i);
            out.assign(l.begin(), l.end());
        } else {
            out = pool_.primitives(slabRoot(i));
            std::sort(out.begin(), out.end());
            out.erase(std::unique(out.begin(), out.end()), out.end());
        }
    };
    // Slab i's entering list is against the slab the walk comes from: the one before it in
    // depth from the eye, the one after it toward a light (a zone's lists are made in the
    // walk's order, then stored in the slabs' order).
    enterFirst_.assign(1, 0);
    enterPrims_.clear();
    std::vector<uint32_t> before, here, zonePrims, zoneCount;
    for (size_t z = 0; z < zones_; ++z) {
        before.clear();
        zonePrims.clear();
        zoneCount.clear();
        const uint32_t n = zoneFirst_[z + 1] - zoneFirst_[z];
        for (uint32_t k = 0; k < n; ++k) {
            treePrims(inward_ ? zoneFirst_[z + 1] - 1 - k : zoneFirst_[z] + k, here);
            const size_t at = zonePrims.size();
            std::set_difference(here.begin(), here.end(), before.begin(), before.end(),
                                std::back_inserter(zonePrims));
            zoneCount.push_back(uint32_t(zonePrims.size() - at));
            std::swap(before, here);
        }
        if (!inward_) {
            enterPrims_.insert(enterPrims_.end(), zonePrims.begin(), zonePrims.end());
            for (uint32_t c : zoneCount) enterFirst_.push_back(enterFirst_.back() + c);
            continue;
        }
        // Walked from the last slab down: slab k's list is the (n - 1 - k)-th piece.
        std::vector<size_t> start(n + 1, 0);
        for (uint32_t k = 0; k < n; ++k) start[k + 1] = start[k] + zoneCount[k];
        for (uint32_t k = n; k-- > 0;) {
            enterPrims_.insert(enterPrims_.end(), zonePrims.begin() + ptrdiff_t(start[k]),
                               zonePrims.begin() + ptrdiff_t(start[k + 1]));
            enterFirst_.push_back(uint32_t(enterPrims_.size()));
        }
    }
}

size_t ProjectiveZones::memoryBytes() const {
    return bsp_.memoryBytes() + zoneFirst_.size() * sizeof(uint32_t) +
           slabs_.size() * sizeof(Slab) + pool_.nodes.size() * sizeof(CsgNode) +
           (listPrims_.size() + nearPrims_.size() + enterFirst_.size() + enterPrims_.size()) *
               sizeof(uint32_t);
}

}  // namespace lancer
