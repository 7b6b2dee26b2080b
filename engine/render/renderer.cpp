#include "engine/render/renderer.h"

#include <tbb/blocked_range2d.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#if defined(__x86_64__) || defined(__i386__)
#include <x86intrin.h>
#endif

#include "engine/util/task_fence.h"

namespace lancer {

namespace {

/// A cheap per-pixel clock: the time-stamp counter where there is one (a few nanoseconds a read,
/// against 60 ns for steady_clock's on this VM: 4% of a balls4 render), else steady_clock's
/// nanoseconds. Ticks are turned into microseconds per tile, against steady_clock over the tile.
inline uint64_t ticks() {
#if defined(__x86_64__) || defined(__i386__)
    return __rdtsc();
#else
    return uint64_t(std::chrono::steady_clock::now().time_since_epoch().count());
#endif
}

/// fn(x) for each x in [begin, end) of row y that `pass` contains, in order: the lattice's
/// columns stepped through, the remainders taken only where the previous pass's lattice may
/// hold the pixel (a remainder per pixel was a division: 7% of the pixel loop's time).
template <class Fn>
inline void forRow(const PassLattice& pass, int y, int begin, int end, Fn&& fn) {
    const int stride = pass.stride, prev = pass.previousStride;
    if (y % stride) return;
    const bool skipPrevious = prev != 0 && y % prev == 0;  // the previous pass did its columns
    for (int x = begin + (stride - begin % stride) % stride; x < end; x += stride)
        if (!skipPrevious || x % prev) fn(x);
}

}  // namespace

TraceContext workerContext(const Scene& scene, const Accelerator& accel, int treeDepth,
                           Precision precision) {
    TraceContext c(scene.prims.size(), treeDepth);
    c.useMailboxes = accel.usesMailboxes();
    c.precision = precision;
    return c;
}

int effectiveThreads(int requested) {
    int cores = tbb::info::default_concurrency();
    return requested > 0 ? requested : cores;
}

RenderStats render(const Scene& scene, const Accelerator& accel, const RenderOptions& opt,
                   Image& img, PassLattice pass, const std::atomic<bool>* cancel,
                   std::atomic<size_t>* progress, const LightBuffer* eyeGiven) {
    using Clock = std::chrono::steady_clock;
    RenderStats stats;
    stats.threads = effectiveThreads(opt.threads);
    const Camera& cam = opt.camera ? *opt.camera : scene.camera;
    const int w = img.width, h = img.height;
    const Tracer tracer(scene, accel, opt.shading);
    const PrimaryRays primary(cam, w, h);
    // Where each primary ray can first meet a box (empty unless the scheme uses one).
    const std::shared_ptr<const LightBuffer> eyeBuilt =
        eyeGiven ? nullptr : accel.eyeBuffer(scene, cam);
    const LightBuffer& eye = eyeGiven ? *eyeGiven : *eyeBuilt;
    const int depth = accel.info().treeDepth >= 0 ? accel.info().treeDepth : scene.tree.depth();
    tbb::enumerable_thread_specific<TraceContext> contexts(
        [&] { return workerContext(scene, accel, depth, opt.shading.precision); });
    auto start = Clock::now();
    std::atomic<bool> stopped{false};
    // oneTBB orders what is written here before the tiles, and the tiles' writes (pixels,
    // counters) before what follows the loop, where ThreadSanitizer does not see it.
    TaskFence fence;
    // A tile holds about tile x tile pixels of the pass's lattice, however sparse it is.
    const int tile = std::max(1, opt.tile) * std::max(1, pass.stride);
    tbb::task_arena arena(stats.threads);
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range2d<int>(std::clamp(pass.rowBegin, 0, h),
                                      pass.rowEnd < 0 ? h : std::clamp(pass.rowEnd, 0, h), tile, 0,
                                      w, tile),
            fence.task([&](const tbb::blocked_range2d<int>& r) {
                if (stopped.load(std::memory_order_relaxed)) return;
                if (cancel && cancel->load(std::memory_order_relaxed)) {
                    stopped = true;
                    return;
                }
                TraceContext& ctx = contexts.local();
                NullObserver obs;
                size_t done = 0;
                // One counter read per pixel: a pixel's time runs from the previous one's end.
                // Held in timeUs as ticks until the tile ends.
                const auto tileStart = Clock::now();
                const uint64_t tileTicks = ticks();
                int rowsDone = r.rows().begin();
                for (int y = r.rows().begin(); y < r.rows().end(); ++y, rowsDone = y) {
                    // Checked per row too, so a cancel lands within a row of slow pixels.
                    if (cancel && cancel->load(std::memory_order_relaxed)) {
                        stopped = true;
                        break;
                    }
                    uint64_t t0 = ticks();
                    forRow(pass, y, r.cols().begin(), r.cols().end(), [&](int x) {
                        // Only the two counters the image keeps, not the whole struct.
                        const uint64_t testsBefore = ctx.counters.primTests;
                        const uint64_t visitsBefore = ctx.counters.regionVisits;
                        Hit hit;
                        Vec3 c = tracer.pixel(primary, eye, x, y, ctx, obs, hit);
                        size_t i = img.index(x, y);
                        img.color[i] = glm::vec3(c);
                        img.depth[i] =
                            hit.valid() ? float(hit.t) : std::numeric_limits<float>::infinity();
                        img.hitPrim[i] = hit.prim;
                        img.primTests[i] = uint32_t(ctx.counters.primTests - testsBefore);
                        img.regionVisits[i] = uint32_t(ctx.counters.regionVisits - visitsBefore);
                        const uint64_t t1 = ticks();
                        img.timeUs[i] = float(t1 - t0);
                        t0 = t1;
                        ++done;
                    });
                }
                const uint64_t spent = ticks() - tileTicks;
                const double us =
                    std::chrono::duration<double, std::micro>(Clock::now() - tileStart).count();
                const float usPerTick = spent > 0 ? float(us / double(spent)) : 0.0f;
                for (int y = r.rows().begin(); y < rowsDone; ++y)
                    forRow(pass, y, r.cols().begin(), r.cols().end(),
                           [&](int x) { img.timeUs[img.index(x, y)] *= usPerTick; });
                if (progress) progress->fetch_add(done, std::memory_order_relaxed);
            }),
            tbb::simple_partitioner());
    });
    stats.renderMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    stats.cancelled = stopped.load();
    fence.acquire();
    for (const TraceContext& c : contexts) stats.counters += c.counters;
    return stats;
}

}  // namespace lancer
