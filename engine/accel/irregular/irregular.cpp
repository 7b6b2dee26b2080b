#include "engine/accel/irregular/irregular.h"

#include <tbb/task_group.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "engine/accel/accelerator.h"
#include "engine/accel/build_guard.h"
#include "engine/accel/irregular/corner_pointers.h"
#include "engine/accel/irregular/depth_slabs.h"
#include "engine/accel/irregular/primitive_hulls.h"
#include "engine/accel/regular/axis_planner.h"
#include "engine/accel/regular/grid_frame.h"
#include "engine/util/format.h"
#include "engine/util/task_fence.h"

namespace lancer {

namespace {

int sign(double v) { return v > 0.0 ? 1 : (v < 0.0 ? -1 : 0); }

double maxAbs(const Vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

/// The screen BSP stops at about this many zones: a BSP that large means the 2D step should stop
/// earlier (see docs/irregular.md, "Growth").
constexpr size_t kMaxZones = 4'000'000;
/// The regions one frame's slabs may make (camera frame, projective zones): a work bound, so a
/// build's time stays within seconds at the defaults; past it further zones keep one slab.
/// Primary rays need about a zone per pixel, secondary rays about a region per primitive:
/// 16 times their sum, within 2^20..2^23 (docs/irregular.md, "Budget and stopping rule").
size_t regionBudget(size_t prims, size_t pixels) {
    return std::clamp<size_t>(16 * (prims + pixels), size_t(1) << 20, size_t(1) << 23);
}
/// Refuses a build past `guard`'s budget: `what` says what would take how much.
[[noreturn]] void refuseOverBudget(const BuildGuard& guard, const std::string& what) {
    throw std::invalid_argument("--memory-budget " + guard.describe() +
                                ": the irregular subdivision " + what + "; raise --memory-budget");
}
/// The primitives' hulls (primitive_hulls.h) are made when they take at most this share of the
/// memory budget.
constexpr size_t kHullShare = 16;
/// Regions beyond this many are refused: pointers are 32-bit and memory would run out first.
constexpr size_t kMaxRegions = 50'000'000;

/// The projective structures' cost stop (ZoneWalkModel), in instructions of the render and of
/// the build (docs/irregular.md, "A cost estimate that follows the walk"): a slab visit and a
/// test about 250 each (callgrind, drilled:6), a BSP level about 12 (ScreenBsp::locate, 190 at
/// depth 16). The build is charged 500 a zone and 1,000 a reference for the eye (uncharged, a
/// 128x128 image of balls4 builds 13,870 eye zones instead of 4,051, 23.4 MiB against 20.0,
/// for 2.7% fewer instructions), twice that for a light (300 and 600 instead: 0.4% fewer on
/// balls4 and drilled:6, with 1.5 times drilled's light slabs). The rays: a pixel's each for
/// the eye (ProjectiveZones::build), and for each light kLightRays of the pixels, spread over
/// its zones' rectangle.
ZoneWalkModel walkModel() {
    ZoneWalkModel m;
    m.visit = 250.0;
    m.test = 250.0;
    m.level = 12.0;
    m.fill = 0.5;
    m.zone = 500.0;
    m.ref = 1000.0;
    return m;
}
/// A light's shadow rays, as a share of the pixels (those that hit something, and the light
/// buffer clears about half of them on balls4).
constexpr double kLightRays = 0.5;
/// What a light's zone and reference cost to build, as a share of the eye's (walkModel).
constexpr double kLightBuild = 2.0;

/// In a union-only scene, a primitive whose camera-frame box covers at least this share of the
/// structure's screen rectangle is kept out of the camera frame's lists and tested by every
/// camera-frame walk (IrregularSubdivision::shared): listed, it cuts a slab at each end of its
/// depth range in every zone under it, and its edges split the screen, so a secondary ray
/// crosses regions that hold only it (docs/irregular.md, "Secondary rays in the camera frame").
constexpr double kSharedArea = 0.25;
/// At most this many are shared, the largest first: each costs every camera-frame walk a test.
constexpr size_t kMaxShared = 4;

/// The primitives of `live` to share (kSharedArea, kMaxShared), by decreasing area; none when
/// they would be every primitive.
std::vector<uint32_t> sharedPrimitives(const std::vector<Box3>& box,
                                       const std::vector<uint32_t>& live, const Box3& bounds) {
    const double screen = (bounds.hi.x - bounds.lo.x) * (bounds.hi.y - bounds.lo.y);
    auto area = [&](uint32_t p) {
        return (box[p].hi.x - box[p].lo.x) * (box[p].hi.y - box[p].lo.y);
    };
    std::vector<uint32_t> big;
    for (uint32_t p : live)
        if (area(p) >= kSharedArea * screen) big.push_back(p);
    std::stable_sort(big.begin(), big.end(),
                     [&](uint32_t a, uint32_t b) { return area(a) > area(b); });
    if (big.size() > kMaxShared) big.resize(kMaxShared);
    if (big.size() == live.size()) big.clear();
    return big;
}

/// Lights beyond this many (outside the bounds) get no structure of their own: each costs about
/// as much to build as the eye's zones.
constexpr size_t kMaxLightStructures = 8;

/// The primitives' boxes in `frame`, padded by `eps`: the bound there of each minimized box, cut
/// in a turned scene by the bound of its box along the turn's own axes (grid_frame.h), an
/// oriented box of the world much smaller than its world box.
std::vector<Box3> frameBoxes(const Scene& scene, const CameraFrame& frame,
                             const FrameChoice& turned, const std::vector<uint32_t>& live,
                             double eps) {
    std::vector<Box3> box(scene.prims.size());
    for (uint32_t p : live) {
        box[p] = frame.box(scene.minBox[p]);
        if (turned.frame.turned) {
            const Box3& fb = turned.boxes[p];
            Box3 c;
            for (int i = 0; i < 8 && !fb.isEmpty(); ++i)
                c.expand(frame.point(turned.frame.toWorld(boxCorner(fb, i))));
            box[p] = overlap(box[p], c);
        }
        box[p].lo -= eps;
        box[p].hi += eps;
    }
    return box;
}

/// The frame of a point light outside `bounds`: origin at the light, depth along the world axis
/// it lies farthest beyond, toward the scene (the axis its light buffer looks along), so every
/// box lies in front of it. None for a light inside the bounds (no one frustum holds the scene).
std::optional<CameraFrame> lightFrame(const Box3& bounds, const Vec3& light) {
    int axis = -1;
    double beyond = 0.0, sign = 1.0;
    for (int a = 0; a < 3; ++a) {
        if (bounds.lo[a] - light[a] > beyond) axis = a, beyond = bounds.lo[a] - light[a], sign = 1;
        if (light[a] - bounds.hi[a] > beyond) axis = a, beyond = light[a] - bounds.hi[a], sign = -1;
    }
    if (axis < 0) return std::nullopt;
    CameraFrame f;
    f.origin = light;
    f.z = Vec3(0.0);
    f.z[axis] = sign;
    f.x = Vec3(0.0);
    f.x[(axis + 1) % 3] = 1.0;
    f.y = Vec3(0.0);
    f.y[(axis + 2) % 3] = 1.0;
    return f;
}

/// Which scene lights get a structure of their own: those outside the bounds, at most
/// kMaxLightStructures (frames[i] set); the others' shadow rays take the camera-frame walk.
struct LightPlan {
    std::vector<std::optional<CameraFrame>> frames;
    size_t outside = 0, inside = 0, overLimit = 0;
};

LightPlan planLights(const Scene& scene) {
    LightPlan plan;
    for (const Light& light : scene.lights) {
        std::optional<CameraFrame> f = lightFrame(scene.bounds, light.position);
        if (!f)
            ++plan.inside;
        else if (plan.outside == kMaxLightStructures)
            f.reset(), ++plan.overLimit;
        else
            ++plan.outside;
        plan.frames.push_back(f);
    }
    return plan;
}

/// The structure of the light whose frame is `f` (lightFrame), within `share` bytes as the
/// frames keep within theirs: the screen BSP a ninth, the slabs two ninths. Its boxes and hulls
/// are those of the camera frame made in the light's frame.
ProjectiveZones buildLightZones(const Scene& scene, const CameraFrame& f, const FrameChoice& turned,
                                const std::vector<uint32_t>& live, const ScreenBspParams& frameSp,
                                size_t share, size_t maxRegions) {
    // The padding of the camera-frame boxes, from this frame's coordinates: a shadow ray's line
    // passes through the light to rounding of its length, far below it.
    const Box3 b = f.box(scene.bounds);
    const double eps = 1e-9 * std::max({maxAbs(b.lo), maxAbs(b.hi), maxAbs(scene.bounds.lo),
                                        maxAbs(scene.bounds.hi), maxAbs(f.origin), 1e-300});
    const std::vector<Box3> box = frameBoxes(scene, f, turned, live, eps);
    // The hulls are scratch: within a sixteenth of the light's share, as each frame's within a
    // sixteenth of the budget, so the tasks running at once stay within it.
    const size_t hullBytes = PrimitiveHulls::bytesFor(live.size(), scene.prims.size());
    const PrimitiveHulls hulls =
        hullBytes <= share / kHullShare
            ? PrimitiveHulls::make(scene, f, turned, live, eps, frameSp.guard,
                                   share / kHullShare - hullBytes)
            : PrimitiveHulls{};
    ScreenBspParams sp = frameSp;
    ZoneWalkModel walk;
    std::vector<float> stops;
    if (frameSp.walk) {
        walk = *frameSp.walk;
        walk.rays = kLightRays * double(std::max(scene.width, 1)) * std::max(scene.height, 1);
        walk.zone *= kLightBuild;
        walk.ref *= kLightBuild;
        sp.walk = &walk;
        stops = stopShares(scene, f);  // faces as the light sees them
        sp.stops = &stops;
    }
    sp.hulls = hulls.empty() ? nullptr : &hulls;
    sp.hullPad = eps;
    sp.maxBytes = std::max<size_t>(share / 9, 1);
    return ProjectiveZones::buildForLight(scene, f, box, live, sp,
                                          std::max<size_t>(2 * share / 9, 1), maxRegions);
}

}  // namespace

IrregularSubdivision IrregularSubdivision::build(const Scene& scene, const IrregularConfig& params,
                                                 nlohmann::json& extra, BuildGuard* guardIn,
                                                 const IrregularSubdivision* previous) {
    BuildGuard ownGuard;
    BuildGuard& guard = guardIn ? *guardIn : ownGuard;
    using Clock = std::chrono::steady_clock;
    auto ms = [](Clock::time_point a) {
        return std::chrono::duration<double, std::milli>(Clock::now() - a).count();
    };
    if (std::string err = scene.camera.validate(); !err.empty())
        throw std::invalid_argument("--scheme irregular: the camera is invalid: " + err);
    if (params.maxObjects < 0 && params.maxObjects != kAutoObjects)
        throw std::invalid_argument(
            "--max-objects " + std::to_string(params.maxObjects) +
            ": must be >= 0 (0: split the screen until no segment is left) or auto");

    IrregularSubdivision s;
    s.scene_ = &scene;
    s.frame_ = CameraFrame::of(scene.camera);
    std::vector<uint32_t> live = scene.livePrimitives();
    if (live.empty() || scene.bounds.isEmpty()) {
        extra["zones"] = 0;
        extra["stop_reasons"] = {{"max_objects", 0}, {"max_level", 0}, {"cost", 0}, {"memory", 0}};
        return s;
    }

    const size_t frames = params.frame == IrregularFrame::Projective ? 2 : 1;
    // The least a frame's build holds: the primitives' boxes, the screen BSP's root cell, and
    // one zone whose one region lists every primitive. A budget too small for it is refused
    // before anything is built; the limits below are at least a byte, since 0 would mean none.
    const size_t least =
        scene.prims.size() * sizeof(Box3) + ScreenBsp::rootBytes(live.size()) + kMergedZoneBytes +
        live.size() * (mergedRefBytes(scene.tree.unionOnly()) + sizeof(glm::dvec2));
    // Each light outside the bounds gets a projective structure of its own (shadow rays toward
    // it), built beside the two frames' with an equal share of the budget; when the shares
    // would be smaller than the least a frame holds, none is built (lights_over_budget).
    const LightPlan lights =
        params.frame == IrregularFrame::Projective ? planLights(scene) : LightPlan{};
    size_t lightShares = lights.outside;
    if (lightShares > 0 && least > guard.budget() / (frames + lightShares)) lightShares = 0;
    const size_t share = guard.budget() / (frames + lightShares);
    if (least > share)
        refuseOverBudget(guard, "needs at least " + formatBytes(least) + " a frame (" +
                                    std::to_string(frames) + " frame" + (frames > 1 ? "s" : "") +
                                    ")");
    // Camera-frame boxes, padded by a few thousand rounding errors of the largest coordinate
    // involved, so that a hit point and the ray's own camera-frame point never fall outside the
    // box of the primitive they belong to; the structure's box is padded twice as much so every
    // primitive box lies strictly inside it.
    auto t0 = Clock::now();
    Box3 cam = s.frame_.box(scene.bounds);
    double scale = std::max({maxAbs(cam.lo), maxAbs(cam.hi), maxAbs(scene.bounds.lo),
                             maxAbs(scene.bounds.hi), maxAbs(scene.camera.from), 1e-300});
    double eps = 1e-9 * scale;
    guard.poll();
    const FrameChoice turned = chooseGridFrame(scene);
    const std::vector<Box3> box = frameBoxes(scene, s.frame_, turned, live, eps);
    s.bounds_ = {cam.lo - 2.0 * eps, cam.hi + 2.0 * eps};

    const size_t pixels = size_t(std::max(scene.width, 1)) * size_t(std::max(scene.height, 1));
    const size_t maxRegions = regionBudget(live.size(), pixels);
    // 2D step. The memory budget is shared by the camera-frame structure and the projective
    // zones (when built). Of each share, the screen BSP may take a ninth (then it stops) and the
    // slabs two ninths (then each further zone's slabs merge into one): a third in all, so the
    // arrays can still double (BuildGuard::fits).
    ScreenBspParams sp;
    sp.heuristic = params.heuristic;
    sp.stopObjects = params.objects();
    sp.stepCost = params.usesCostStop() ? params.stepCost : 0.0;
    sp.maxZones = kMaxZones;
    sp.maxBytes = std::max<size_t>(share / 9, 1);
    sp.zoneBytes = kMergedZoneBytes;
    // Each zone reference also gets its depth range for the slabs (narrowZones).
    sp.refBytes = mergedRefBytes(scene.tree.unionOnly()) + sizeof(glm::dvec2);
    sp.guard = &guard;
    // Zones list what the primitives' hulls meet, slabs cut at the depths the hulls take over
    // each zone (primitive_hulls.h).
    // They are the build's scratch, made only when they take at most a sixteenth of the budget
    // (a tighter budget builds on the boxes alone, as it did before them).
    // Their faces clipped by each other box are kept within what is left of that sixteenth.
    const size_t hullBytes = PrimitiveHulls::bytesFor(live.size(), scene.prims.size());
    const PrimitiveHulls hulls =
        hullBytes <= guard.budget() / kHullShare
            ? PrimitiveHulls::make(scene, s.frame_, turned, live, eps, &guard,
                                   guard.budget() / kHullShare - hullBytes)
            : PrimitiveHulls{};
    if (!hulls.empty()) sp.hulls = &hulls;
    sp.column = ZoneColumn::Parallel;
    sp.hullPad = eps;
    // A polygon's test costs more than a sphere's (gears2's faces have up to 144 vertices): the
    // cost stop weighs each as the regular scheme's planner does.
    const std::vector<float> weights = regular_build::testWeights(scene);
    sp.weights = &weights;

    // The two frames' structures are independent (each within its half of the budget): the
    // projective zones are built as a task beside the camera frame's, which halves the build's
    // wall time on two cores (balls:6: the camera frame 14.7 s, the projective zones 14.0 s).
    const size_t slabBytes = std::max<size_t>(2 * share / 9, 1);
    // The projective structures' zones are walked in depth: their cost stop follows the walk
    // (the camera frame's keeps the count of stepCost: its rays cross zones by pointers).
    const ZoneWalkModel walk = walkModel();
    ScreenBspParams projSp = sp;
    std::vector<float> stops;
    if (params.usesCostStop()) {
        stops = stopShares(scene, s.frame_);
        projSp.walk = &walk;
        projSp.stops = &stops;
        // The model decides down to one primitive: a zone of a few still costs a ray a slab
        // for each of their ranges it crosses.
        projSp.stopObjects = 1;
    }
    tbb::task_group tasks;
    TaskFence fence;
    nlohmann::json eyeExtra;
    double eyeMs = 0.0;
    if (params.frame == IrregularFrame::Projective) {
        tasks.run(fence.task([&] {
            auto t3 = Clock::now();
            s.projective_ = ProjectiveZones::build(scene, s.frame_, box, live, projSp, eyeExtra,
                                                   slabBytes, maxRegions);
            eyeMs = ms(t3);
        }));
    }
    // The lights' structures, each a task of its own beside the frames' (gears2: five lights).
    // They do not depend on the camera: a structure built over the same prepared scene with the
    // same key lends its own (copied, about a millisecond a megabyte, where balls4's three
    // lights take 0.9 s of CPU to build).
    s.lightKey_ = {scene.preparedId, params, share, maxRegions, pixels};
    const bool lend = previous && scene.preparedId != 0 && previous->lightKey_ == s.lightKey_ &&
                      previous->lights_.size() == scene.lights.size();
    s.lightsInside_ = lend ? previous->lightsInside_ : lights.inside;
    s.lightsOverLimit_ = lend ? previous->lightsOverLimit_ : lights.overLimit;
    s.lightOver_.assign(scene.lights.size(), 0);
    std::vector<double> lightMs(lend ? 0 : scene.lights.size(), 0.0);
    if (lend) {
        s.lights_ = previous->lights_;
        for (ProjectiveZones& lz : s.lights_) lz.rebind(scene);
        s.lightOver_ = previous->lightOver_;
    } else {
        s.lights_.assign(scene.lights.size(), ProjectiveZones{});
    }
    for (size_t i = 0; i < lights.frames.size() && !lend; ++i) {
        if (!lights.frames[i]) continue;
        if (lightShares == 0) {
            s.lightOver_[i] = 1;
            continue;
        }
        tasks.run(fence.task([&, i] {
            auto t4 = Clock::now();
            ProjectiveZones lz =
                buildLightZones(scene, *lights.frames[i], turned, live, projSp, share, maxRegions);
            // A structure over its share is not kept: its shadow rays take the camera frame.
            if (lz.memoryBytes() > share)
                s.lightOver_[i] = 1;
            else
                s.lights_[i] = std::move(lz);
            s.lights_[i].setHintSlot(uint32_t(i) + 1);  // the eye's is 0
            lightMs[i] = ms(t4);
        }));
    }
    double bspMs = 0.0, slabMs = 0.0, linkMs = 0.0;
    DepthSlabs slabs;
    // The camera frame's lists leave the shared primitives out (union-only scenes only: a CSG
    // region's restricted tree needs every primitive it meets).
    if (scene.tree.unionOnly()) s.shared_ = sharedPrimitives(box, live, s.bounds_);
    std::vector<uint32_t> listed = live;
    if (!s.shared_.empty())
        std::erase_if(listed, [&](uint32_t p) {
            return std::find(s.shared_.begin(), s.shared_.end(), p) != s.shared_.end();
        });
    // Padded once more than the boxes: a boundary of a listed primitive lies inside its box.
    for (uint32_t p : listed) s.occupied_.expand(box[p]);
    s.occupied_ = {s.occupied_.lo - eps, s.occupied_.hi + eps};
    try {
        s.bsp_ = ScreenBsp::build(box, listed, {s.bounds_.lo.x, s.bounds_.lo.y},
                                  {s.bounds_.hi.x, s.bounds_.hi.y}, sp);
        bspMs = ms(t0);

        // 3D step.
        guard.poll();
        auto t1 = Clock::now();
        const std::vector<glm::dvec2> depth = narrowZones(
            s.bsp_, hulls, ZoneColumn::Parallel, box, s.bounds_.lo.z, s.bounds_.hi.z, eps, &guard);
        slabs = buildDepthSlabs(scene, s.bsp_, depth, s.bounds_.lo.z, s.bounds_.hi.z, &guard,
                                slabBytes, maxRegions);
        if (slabs.regions.size() > kMaxRegions)
            throw std::invalid_argument(
                "--scheme irregular: " + std::to_string(slabs.regions.size()) +
                " regions is over the limit of " + std::to_string(kMaxRegions) +
                "; stop the 2D step earlier with --max-objects");
        slabMs = ms(t1);

        auto t2 = Clock::now();
        guard.poll();
        linkCorners(s.bsp_, s.bounds_, slabs, &guard);
        guard.poll();
        linkMs = ms(t2);
    } catch (...) {
        // The projective task polls the same guard: a cancellation ends it as soon; any other
        // error waits for it to finish (its own error, if any, is dropped for this one).
        try {
            tasks.wait();
        } catch (...) {
        }
        fence.acquire();
        throw;
    }
    try {
        tasks.wait();  // rethrows the projective task's error (its cancellation)
    } catch (...) {
        fence.acquire();
        throw;
    }
    fence.acquire();
    if (eyeExtra.is_object()) extra.update(eyeExtra);

    s.regions_ = std::move(slabs.regions);
    s.zoneFirstRegion_ = std::move(slabs.zoneFirstRegion);
    s.pool_ = std::move(slabs.pool);
    // Each list after its length and followed by the shared primitives, which the walk merges
    // in every region.
    s.listPrims_ = headedLists(slabs.listFirst, slabs.listPrims, s.shared_, s.listFirst_);
    for (IrregularRegion& R : s.regions_) R.first = s.listFirst_[R.list];
    s.zoneRect_.resize(s.bsp_.zoneCount());
    for (uint32_t z = 0; z < s.bsp_.zoneCount(); ++z)
        s.zoneRect_[z] = {s.bsp_.zoneLo[z], s.bsp_.zoneHi[z]};
    s.unionOnly_ = slabs.unionOnly;
    s.budget_ = 16 * s.regions_.size() + 1024;
    s.finishLights(lightMs, extra);

    extra["frame"] = irregularFrameName(params.frame);

    size_t refs = 0, most = 0;
    for (uint32_t r = 0; r < s.regions_.size(); ++r) {
        size_t n = s.primitives(r).size();
        refs += n;
        most = std::max(most, n);
    }
    extra["zones"] = s.bsp_.zoneCount();
    extra["segments"] = s.bsp_.segments;
    extra["cut_segments"] = s.bsp_.cuts;
    extra["cost_stops"] = s.bsp_.costStops;
    // Why each zone of the camera frame's BSP was not split (docs/irregular.md, "Stop
    // reasons"): zones inside all their rectangles count as cost (no split separates them).
    extra["stop_reasons"] = {{"max_objects", s.bsp_.objectStops},
                             {"max_level", 0},
                             {"cost", s.bsp_.costStops + s.bsp_.coveredStops},
                             {"memory", s.bsp_.limitStops}};
    extra["covered_zones"] = s.bsp_.coveredStops;
    extra["cost_stop"] = params.usesCostStop();
    extra["bsp_nodes"] = s.bsp_.nodes.size();
    extra["bsp_depth"] = s.bsp_.depth;
    extra["slabs"] = slabs.slabs;
    extra["empty_zones"] = slabs.emptyZones;
    extra["empty_slabs"] = slabs.emptySlabs;
    // Where the memory budget stopped the 2D step or merged slabs (README, "Bounded builds").
    extra["memory_budget"] = guard.budget();
    extra["region_budget"] = maxRegions;
    extra["bsp_stopped"] = s.bsp_.stopped;
    extra["merged_zones"] = slabs.mergedZones;
    extra["coarse_zones"] = slabs.coarseZones;
    // Union-only scenes: regions hold their primitive lists alone (no tree, distinct_trees 0).
    extra["flat_regions"] = s.unionOnly_;
    extra["distinct_lists"] = s.listFirst_.size() - 1;
    extra["shared_primitives"] = s.shared_.size();
    extra["distinct_trees"] = s.unionOnly_ ? 0 : s.listFirst_.size() - 1;
    extra["pool_nodes"] = s.pool_.nodes.size();
    extra["prims_per_region"] = double(refs) / double(s.regions_.size());
    extra["max_prims_per_region"] = most;
    extra["screen_bsp_ms"] = bspMs;
    extra["slabs_ms"] = slabMs;
    extra["pointers_ms"] = linkMs;
    extra["projective_ms"] = eyeMs;
    // The 2D step and the slabs keep within a third of the budget; what they cannot stop (the
    // regions' fixed part, the trees) is checked here, so no structure over it is returned.
    if (s.memoryBytes() > guard.budget())
        refuseOverBudget(guard, "takes " + formatBytes(s.memoryBytes()) + " at its coarsest");
    return s;
}

double IrregularSubdivision::exitOf(const IrregularRegion& r, const Ray& rc, double t, int& axis,
                                    int& ties, Vec3& p) const {
    const Box3 box = boxOf(r);
    const Vec3 &lo = box.lo, &hi = box.hi;
    double ta[3];
    double te = kInf;
    axis = 0;
    for (int a = 0; a < 3; ++a) {
        if (rc.d[a] > 0.0)
            ta[a] = (hi[a] - rc.o[a]) / rc.d[a];
        else if (rc.d[a] < 0.0)
            ta[a] = (lo[a] - rc.o[a]) / rc.d[a];
        else
            ta[a] = kInf;
        if (ta[a] < te) {
            te = ta[a];
            axis = a;
        }
    }
    double tc = std::max(te, t);
    ties = 0;
    for (int a = 0; a < 3; ++a) {
        if (ta[a] == te) ties |= 1 << a;
        if (ta[a] == te)
            p[a] = rc.d[a] > 0.0 ? hi[a] : lo[a];
        else
            p[a] = std::clamp(rc.o[a] + tc * rc.d[a], lo[a], hi[a]);
    }
    return tc;
}

uint32_t IrregularSubdivision::locate(const Vec3& p, const Vec3& d) const {
    uint32_t zone = bsp_.locate(p.x, p.y, sign(d.x), sign(d.y));
    return slabAt(regions_, zoneFirstRegion_, zone, p.z, sign(d.z));
}

int64_t IrregularSubdivision::walkTo(uint32_t from, const Vec3& p) const {
    const Vec3 c = regionBox(from).center();
    Ray rc{c, p - c};
    uint32_t r = from;
    double t = 0.0;
    size_t budget = budget_;
    uint64_t steps = 0;
    NullObserver obs;
    // Stop on the region that holds p (exact comparisons) or where the segment ends (a point
    // a few ulps off a cut may round to the other side of it).
    for (;;) {
        if (holds(r, p, rc.d)) return r;
        int axis, ties;
        Vec3 q;
        double te = exitOf(regions_[r], rc, t, axis, ties, q);
        if (te > 1.0) return r;
        // p on the structure's border: cross a tied face that is not on it.
        axis = -1;
        for (int a = 0; a < 3 && axis < 0; ++a)
            if ((ties >> a & 1) && !onBorder(regions_[r], a, rc.d)) axis = a;
        if (axis < 0) return r;
        int64_t next = cross(r, axis, q, rc.d, obs, steps, budget);
        if (next < 0 || budget == 0) return -1;
        --budget;
        r = uint32_t(next);
        t = te;
    }
}

size_t IrregularSubdivision::memoryBytes() const {
    return sizeof(*this) + regions_.size() * sizeof(IrregularRegion) + bsp_.memoryBytes() +
           zoneFirstRegion_.size() * sizeof(uint32_t) +
           zoneRect_.size() * sizeof(IrregularZoneRect) + pool_.nodes.size() * sizeof(CsgNode) +
           (listFirst_.size() + listPrims_.size() + shared_.size()) * sizeof(uint32_t) +
           projective_.memoryBytes() + lightBytes();
}

size_t IrregularSubdivision::lightBytes() const {
    size_t n = lightFirstRegion_.size() * sizeof(uint32_t);
    for (const ProjectiveZones& lz : lights_) n += sizeof(lz) + lz.memoryBytes();
    return n;
}

void IrregularSubdivision::finishLights(const std::vector<double>& ms, nlohmann::json& extra) {
    lightFirstRegion_.assign(1, uint32_t(regions_.size() + projective_.regionCount()));
    size_t built = 0, zones = 0, slabs = 0, empty = 0, overBudget = 0;
    double total = 0.0;
    for (size_t i = 0; i < lights_.size(); ++i) {
        const ProjectiveZones& lz = lights_[i];
        lightFirstRegion_.push_back(lightFirstRegion_.back() + uint32_t(lz.regionCount()));
        built += lz.zoneCount() > 0;
        zones += lz.zoneCount();
        slabs += lz.zoneFirst().empty() ? 0 : lz.zoneFirst().back();
        empty += lz.emptySlabs();
        overBudget += size_t(lightOver_[i]);
    }
    for (double m : ms) total += m;
    extra["light_structures"] = built;
    extra["lights_inside"] = lightsInside_;
    extra["lights_over_limit"] = lightsOverLimit_;
    // Taken from the build given as BuildControl::previous: light_ms is then 0.
    extra["lights_lent"] = ms.empty() && built > 0;
    extra["lights_over_budget"] = overBudget;
    extra["light_zones"] = zones;
    extra["light_slabs"] = slabs;
    extra["light_empty_slabs"] = empty;
    extra["light_regions"] = lightFirstRegion_.back() - lightFirstRegion_.front();
    extra["light_bytes"] = lightBytes();
    extra["light_ms"] = total;
}

}  // namespace lancer
