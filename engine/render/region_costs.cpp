#include "engine/render/region_costs.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <stdexcept>
#include <string>

#include "engine/util/task_fence.h"

namespace lancer {

namespace {

/// Counts the walk's region entries and primitive tests by region, into arrays shared by the
/// threads (relaxed atomic adds: a per-thread copy of millions of regions would cost more than
/// the contention on the few regions every ray enters). Every other event is the null
/// observer's.
struct CostObserver : NullObserver {
    static constexpr bool kActive = true;
    uint32_t* visits = nullptr;
    uint32_t* tests = nullptr;
    size_t regions = 0;
    CostRays rays = CostRays::All;
    bool counting = true;  ///< the current ray is one of `rays`
    int64_t current = -1;  ///< the region the walk is in (-1: none yet for this ray)
    uint64_t unplacedTests = 0;
    uint64_t outOfRange = 0;  ///< region ids at or beyond `regions` (a bug: reported)

    void rayBegin(RayKind kind, int /*depth*/, int /*light*/, const Ray& /*ray*/, double /*tmin*/,
                  double /*tmax*/) {
        counting = rays == CostRays::All || kind == RayKind::Primary;
        current = -1;
    }
    void region(uint32_t id, double /*t0*/, double /*t1*/) {
        if (!counting) return;
        if (id >= regions) {
            ++outOfRange;
            current = -1;
            return;
        }
        current = id;
        std::atomic_ref<uint32_t>(visits[id]).fetch_add(1, std::memory_order_relaxed);
    }
    void primTest(uint32_t /*prim*/, const Span* /*spans*/, int /*n*/) {
        if (!counting) return;
        if (current < 0) {
            ++unplacedTests;
            return;
        }
        std::atomic_ref<uint32_t>(tests[size_t(current)]).fetch_add(1, std::memory_order_relaxed);
    }
};

std::vector<uint64_t> prefixSums(const std::vector<uint32_t>& v) {
    std::vector<uint64_t> out(v.size() + 1, 0);
    for (size_t i = 0; i < v.size(); ++i) out[i + 1] = out[i] + v[i];
    return out;
}

}  // namespace

const char* costRaysName(CostRays r) { return r == CostRays::All ? "all rays" : "primary rays"; }

bool countRegionCosts(const Scene& scene, const Accelerator& accel, const RenderOptions& opt,
                      size_t regions, CostRays rays, RegionCosts& out,
                      const std::atomic<bool>* cancel) {
    // render()'s set-up: the same tracer, primary rays, eye buffer and trace contexts.
    const Camera& cam = opt.camera ? *opt.camera : scene.camera;
    const int w = opt.width, h = opt.height;
    const Tracer tracer(scene, accel, opt.shading);
    const PrimaryRays primary(cam, w, h);
    const std::shared_ptr<const LightBuffer> eye = accel.eyeBuffer(scene, cam);
    const int depth = accel.info().treeDepth >= 0 ? accel.info().treeDepth : scene.tree.depth();
    tbb::enumerable_thread_specific<TraceContext> contexts(
        [&] { return workerContext(scene, accel, depth, opt.shading.precision); });
    std::vector<uint32_t> visits(regions, 0), tests(regions, 0);
    std::atomic<uint64_t> unplaced{0}, outOfRange{0};
    std::atomic<bool> stopped{false};
    TaskFence fence;
    tbb::task_arena arena(effectiveThreads(opt.threads));
    arena.execute([&] {
        const int tile = std::max(1, opt.tile);
        tbb::parallel_for(tbb::blocked_range2d<int>(0, h, tile, 0, w, tile),
                          fence.task([&](const tbb::blocked_range2d<int>& r) {
                              TraceContext& ctx = contexts.local();
                              CostObserver obs;
                              obs.visits = visits.data();
                              obs.tests = tests.data();
                              obs.regions = regions;
                              obs.rays = rays;
                              for (int y = r.rows().begin(); y < r.rows().end(); ++y) {
                                  if (stopped.load(std::memory_order_relaxed) ||
                                      (cancel && cancel->load(std::memory_order_relaxed))) {
                                      stopped = true;
                                      break;
                                  }
                                  for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                                      Hit hit;
                                      tracer.pixel(primary, *eye, x, y, ctx, obs, hit);
                                  }
                              }
                              unplaced.fetch_add(obs.unplacedTests, std::memory_order_relaxed);
                              outOfRange.fetch_add(obs.outOfRange, std::memory_order_relaxed);
                          }),
                          tbb::simple_partitioner());
    });
    fence.acquire();
    if (stopped.load()) return false;
    if (outOfRange.load() > 0)
        throw std::logic_error(
            "countRegionCosts: the walk reported " + std::to_string(outOfRange.load()) +
            " region entries beyond the structure's " + std::to_string(regions) + " regions");
    out.width = w;
    out.height = h;
    out.rays = rays;
    out.visitsBefore = prefixSums(visits);
    out.testsBefore = prefixSums(tests);
    out.unplacedTests = unplaced.load();
    return true;
}

}  // namespace lancer
