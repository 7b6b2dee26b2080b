// Progressive rendering on a worker thread: coarse passes first (one pixel in stride x stride,
// shown as blocks), refined to every pixel; a new job cancels the one in flight at once.
// No GL here: the viewer displays the snapshots, the benchmark can time the passes.
#pragma once

#include <array>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "engine/render/renderer.h"

namespace lancer {

/// What a progressive job renders: a scene, a structure built over it, and the options.
/// `accel` must have been built over `*scene`; both are kept alive by the job.
struct ProgressiveJob {
    std::shared_ptr<const Scene> scene;
    std::shared_ptr<const Accelerator> accel;
    RenderOptions options;
};

/// One finished pass of a job.
struct PassRecord {
    int stride = 1;
    double renderMs = 0.0;      ///< the pass alone
    double sinceStartMs = 0.0;  ///< from start() to the pass being available
    RayCounters counters;
};

/// Lower the calling thread's scheduling priority (nice 19 on Linux), so an interactive thread
/// stays responsive beside it; threads it starts (oneTBB's workers, on first use) inherit it.
/// Nice 19 rather than 5: under a render on both cores the viewer's frames took 15 ms instead
/// of 17-19 (54-55 fps instead of 50-53), and the render, which gets every cycle the UI leaves,
/// finished as soon (builtin:balls:5 at 1280x720, 3 alternated runs).
void lowerThreadPriority();

/// Copy rows [rowBegin, rowEnd) (-1: to the last) of `src` into `dst`, each pixel taking the
/// values of the pixel at the corner of its stride x stride block: how a pass that rendered only
/// that lattice is shown. `dst` is resized (and then wholly filled) if its size differs.
void fillBlocks(const Image& src, int stride, Image& dst, int rowBegin = 0, int rowEnd = -1);

class ProgressiveRenderer {
  public:
    using Clock = std::chrono::steady_clock;

    /// The default passes. The first, 1 pixel in 256, is 3,600 pixels at 1280x720: on screen
    /// within a few tens of milliseconds even on a slow scene; then 1 in 16, then every pixel.
    /// Each pass costs more per pixel than the next (its pixels are far apart: less coherent
    /// memory access), so few passes reach the full image sooner: on balls4 at 1280x720 on 2
    /// cores, 16, 4, 1 was 6% faster to the full image than 16, 8, 4, 2, 1 (medians of 9).
    static constexpr std::array<int, 3> kDefaultStrides = {16, 4, 1};
    /// Passes from coarse to fine; the last must be 1.
    explicit ProgressiveRenderer(std::vector<int> strides = {kDefaultStrides.begin(),
                                                             kDefaultStrides.end()});
    /// Bands the passes of stride 2 and 1 are cut into (each band becomes visible when done).
    static constexpr int kBands = 8;
    /// Cancels the job in flight and joins the worker.
    ~ProgressiveRenderer();
    ProgressiveRenderer(const ProgressiveRenderer&) = delete;
    ProgressiveRenderer& operator=(const ProgressiveRenderer&) = delete;

    /// Cancel the job in flight and render `job` from the coarsest pass. Returns at once.
    /// `requested` is when the change that caused the job happened (for the latencies).
    void start(ProgressiveJob job, Clock::time_point requested = Clock::now());
    /// Cancel the job in flight without starting another.
    void cancel();
    /// Called on the worker thread after each band or pass becomes available (e.g. to wake a UI
    /// loop waiting for events). Set it before the first start().
    void setOnPass(std::function<void()> f) { onPass_ = std::move(f); }

    /// What a snapshot shows: rows [0, rows) the pass of `stride`, the rows below it the pass
    /// before, of `previousStride` (0: none); rows [changedBegin, changedEnd) are the ones this
    /// snapshot wrote; `job` is the number of the job it comes from (see job()). `behind`: a
    /// snapshot limited to `maxRows` left changed rows below changedEnd to the next one (they
    /// still hold what earlier snapshots copied, so previousStride may not name them).
    struct Shown {
        int stride = 0;
        int rows = 0;
        int previousStride = 0;
        int changedBegin = 0, changedEnd = 0;
        uint64_t job = 0;
        bool behind = false;
        /// The snapshot finished a job that a newer one replaced while it came in parts (see
        /// snapshot()): the newer job's rows wait for the next snapshots.
        bool stale = false;
    };
    /// The number of the last job started (1 for the first; 0: none yet). A caller whose last
    /// snapshot has another number has not yet seen anything of the current job.
    uint64_t job() const;
    /// If a band or pass finished since `version`, bring `out` up to date with the displayable
    /// image, update `version` and return true; `shown` (if given) tells what the image holds
    /// and which rows changed. Only the rows written since the last snapshot are copied, so
    /// `out` must be the image the previous snapshots were taken into (any other is made a
    /// whole copy when its size differs; keep one `out` per caller). `maxRows` > 0 copies at
    /// most that many of them: the next snapshot copies the next ones, and `version` is updated
    /// only by the snapshot that catches up (Shown::behind false). The rows of a new job's
    /// first snapshots then lie beside the previous job's: a caller that must not show two
    /// views at once waits for the catch-up. A job whose rows a caller has begun to take in
    /// parts is kept for it when a newer job starts (the newer one renders into a second
    /// image): the next snapshots finish it in parts, the last one Shown::stale, and only then
    /// take the newer job's, so a caller given a new view every frame (a drag) still finishes
    /// each view it began, never taking one whole. With `maxRows` 0, or into an image of
    /// another size, the kept job is dropped for the newest. A replaced job's image of another
    /// size than a non-empty `out` is not taken (`out` was made for the newer job's size).
    bool snapshot(uint64_t& version, Image& out, Shown* shown = nullptr, int maxRows = 0);
    /// What a snapshot taken now would show (its changed rows left at 0): a caller that has
    /// shown another job or stride is behind by a pass.
    Shown latest() const;
    /// Passes of the current job finished so far.
    std::vector<PassRecord> passes() const;
    /// The current job has rendered every pass.
    bool finished() const;
    /// No job is queued or running.
    bool idle() const;
    /// Pixels finished by the pass in flight (for a progress bar), and that pass's pixel count.
    void progress(size_t& done, size_t& total) const;

  private:
    void run();

    std::vector<int> strides_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::unique_ptr<ProgressiveJob> pending_;
    uint64_t jobs_ = 0;  ///< jobs started
    Clock::time_point pendingRequested_;
    bool quit_ = false;
    bool running_ = false;
    bool finished_ = false;
    std::atomic<bool> cancel_{false};
    std::atomic<size_t> progressDone_{0};
    std::atomic<size_t> progressTotal_{0};
    Image display_;     ///< what snapshot() copies from: the passes' blocks, band by band
    RowRange changed_;  ///< rows of display_ written since the last snapshot
    uint64_t displayVersion_ = 0;
    Shown displayShown_;
    /// A job the caller began to take in parts when a newer one started (snapshot()): its
    /// image, its rows not taken yet and what it shows. `kept_` false: none (the image is
    /// kept as the next job's spare buffer).
    Image kept_;
    RowRange keptChanged_;
    Shown keptShown_;
    bool keeping_ = false;
    /// The caller took part of display_'s rows of a job it had not caught up with before
    /// (caughtUp_: the job of the last snapshot that caught up).
    bool partTaken_ = false;
    uint64_t caughtUp_ = 0;
    Image work_;  ///< the worker's lattice buffer, kept between jobs of the same size
    std::vector<PassRecord> passes_;
    std::function<void()> onPass_;
    std::thread worker_;
};

}  // namespace lancer
