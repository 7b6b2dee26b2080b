#include "engine/render/progressive.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace lancer {

void lowerThreadPriority() {
#ifdef __linux__
    // On Linux the nice value is per thread: this leaves the caller's other threads alone.
    setpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)), 19);
#endif
}

void fillBlocks(const Image& src, int stride, Image& dst, int rowBegin, int rowEnd) {
    if (dst.width != src.width || dst.height != src.height) {
        dst.resize(src.width, src.height);
        rowBegin = 0;
        rowEnd = -1;
    }
    const int begin = std::max(rowBegin, 0);
    const int end = rowEnd < 0 ? src.height : std::min(rowEnd, src.height);
    const size_t w = size_t(src.width);
    for (int y = begin; y < end; ++y) {
        const int sy = y - y % stride;
        if (y > begin && y != sy) {  // the same blocks as the row above, just written: copy it
            const size_t d = dst.index(0, y), a = d - w;
            auto row = [&](auto& v) {
                std::copy_n(v.begin() + ptrdiff_t(a), w, v.begin() + ptrdiff_t(d));
            };
            row(dst.color);
            row(dst.depth);
            row(dst.hitPrim);
            row(dst.primTests);
            row(dst.regionVisits);
            row(dst.timeUs);
            continue;
        }
        for (int x = 0; x < src.width; ++x) {
            const size_t s = src.index(x - x % stride, sy), d = dst.index(x, y);
            dst.color[d] = src.color[s];
            dst.depth[d] = src.depth[s];
            dst.hitPrim[d] = src.hitPrim[s];
            dst.primTests[d] = src.primTests[s];
            dst.regionVisits[d] = src.regionVisits[s];
            dst.timeUs[d] = src.timeUs[s];
        }
    }
}

ProgressiveRenderer::ProgressiveRenderer(std::vector<int> strides) : strides_(std::move(strides)) {
    if (strides_.empty() || strides_.back() != 1) strides_.push_back(1);
    worker_ = std::thread([this] {
        lowerThreadPriority();
        run();
    });
}

ProgressiveRenderer::~ProgressiveRenderer() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
        cancel_ = true;
    }
    wake_.notify_all();
    worker_.join();
}

void ProgressiveRenderer::start(ProgressiveJob job, Clock::time_point requested) {
    {
        std::lock_guard lock(mutex_);
        pending_ = std::make_unique<ProgressiveJob>(std::move(job));
        ++jobs_;
        pendingRequested_ = requested;
        cancel_ = true;
        finished_ = false;
        passes_.clear();
    }
    wake_.notify_all();
}

void ProgressiveRenderer::cancel() {
    std::lock_guard lock(mutex_);
    pending_.reset();
    cancel_ = true;
}

bool ProgressiveRenderer::snapshot(uint64_t& version, Image& out, Shown* shown, int maxRows) {
    std::lock_guard lock(mutex_);
    if (keeping_) {
        // The job the caller began in parts, replaced since: its next rows, until it is whole.
        const bool fits = out.width == kept_.width && out.height == kept_.height;
        keeping_ = maxRows > 0 && fits && !keptChanged_.empty();
        if (keeping_) {
            const int end = std::min(keptChanged_.end, keptChanged_.begin + maxRows);
            copyRows(kept_, out, keptChanged_.begin, end);
            Shown s = keptShown_;
            s.changedBegin = keptChanged_.begin;
            s.changedEnd = end;
            keptChanged_.begin = end;
            s.behind = end < keptChanged_.end;
            if (s.behind) {
                s.rows = std::min(s.rows, end);
            } else {
                keeping_ = false;
                caughtUp_ = s.job;
                s.stale = true;  // the newer job's rows are next
            }
            if (shown) *shown = s;
            return true;
        }
    }
    if (version == displayVersion_) return false;
    // Only the rows written since the last snapshot, unless `out` is new or of another size.
    Shown s = displayShown_;
    const bool whole = out.width != display_.width || out.height != display_.height;
    // A replaced job's image of another size: the caller made `out` for the newer job.
    if (whole && out.width > 0 && displayShown_.job != jobs_) return false;
    int end = changed_.end;
    if (!whole && maxRows > 0 && end - changed_.begin > maxRows) end = changed_.begin + maxRows;
    copyRows(display_, out, changed_.begin, end);  // whole when the size differs
    s.changedBegin = whole ? 0 : changed_.begin;
    s.changedEnd = whole ? display_.height : end;
    if (!whole && end < changed_.end) {
        changed_.begin = end;
        s.rows = std::min(s.rows, end);  // the pass's rows that `out` holds
        s.behind = true;
        partTaken_ = partTaken_ || s.job != caughtUp_;
    } else {
        changed_.clear();
        version = displayVersion_;
        partTaken_ = false;
        caughtUp_ = s.job;
    }
    if (shown) *shown = s;
    return true;
}

uint64_t ProgressiveRenderer::job() const {
    std::lock_guard lock(mutex_);
    return jobs_;
}

ProgressiveRenderer::Shown ProgressiveRenderer::latest() const {
    std::lock_guard lock(mutex_);
    return displayShown_;
}

std::vector<PassRecord> ProgressiveRenderer::passes() const {
    std::lock_guard lock(mutex_);
    return passes_;
}

bool ProgressiveRenderer::finished() const {
    std::lock_guard lock(mutex_);
    return finished_ && !pending_;
}

bool ProgressiveRenderer::idle() const {
    std::lock_guard lock(mutex_);
    return !pending_ && !running_;
}

void ProgressiveRenderer::progress(size_t& done, size_t& total) const {
    done = progressDone_.load();
    total = progressTotal_.load();
}

void ProgressiveRenderer::run() {
    for (;;) {
        ProgressiveJob job;
        uint64_t jobNumber = 0;
        Clock::time_point requested;
        {
            std::unique_lock lock(mutex_);
            running_ = false;
            wake_.wait(lock, [&] { return quit_ || pending_; });
            if (quit_) return;
            job = std::move(*pending_);
            pending_.reset();
            jobNumber = jobs_;
            requested = pendingRequested_;
            cancel_ = false;
            running_ = true;
        }
        const int w = job.options.width, h = job.options.height;
        // Kept between jobs: no allocation (and page faults) before the first pass. `work` need
        // not be cleared: each pass writes its lattice before any pixel of it is shown.
        Image& work = work_;
        if (work.width != w || work.height != h) work = Image(w, h);
        // Where primary rays can first meet a box: once for all the passes of the view.
        const std::shared_ptr<const LightBuffer> eye = job.accel->eyeBuffer(
            *job.scene, job.options.camera ? *job.options.camera : job.scene->camera);
        int previous = 0;
        bool complete = true;
        for (int stride : strides_) {
            // A pass coarser than the image would render the corner pixel only: skip to finer.
            if (stride > 1 && (stride >= w || stride >= h)) continue;
            PassLattice lattice{stride, previous};
            size_t count = 0;
            for (int y = 0; y < h; y += stride)
                for (int x = 0; x < w; x += stride) count += lattice.contains(x, y);
            progressDone_ = 0;
            progressTotal_ = count;
            // The long passes in bands of rows (a multiple of the coarsest stride, so a band's
            // blocks come from its own rows), each shown when done; the rest of the image keeps
            // the previous pass meanwhile.
            // The first pass is shown whole: nothing older is there to fill the rows below.
            const int bands = stride <= 2 && previous > 0 ? kBands : 1;
            const int bandRows = std::max(8, (h / bands + 7) / 8 * 8);
            PassRecord rec;
            rec.stride = stride;
            for (int y0 = 0; y0 < h && complete; y0 += bandRows) {
                lattice.rowBegin = y0;
                lattice.rowEnd = std::min(h, y0 + bandRows);
                RenderStats rs = render(*job.scene, *job.accel, job.options, work, lattice,
                                        &cancel_, &progressDone_, eye.get());
                if (rs.cancelled) {
                    complete = false;
                    break;
                }
                rec.renderMs += rs.renderMs;
                rec.counters += rs.counters;
                const bool passDone = lattice.rowEnd == h;
                std::unique_lock lock(mutex_);
                if (cancel_) {  // a newer job arrived while the band finished: do not show it
                    complete = false;
                    break;
                }
                if (previous == 0 && y0 == 0) {
                    // A new job's first rows. A job the caller began to take in parts is kept
                    // for it to finish (snapshot()); this one goes into the spare image.
                    if (partTaken_ && !keeping_) {
                        std::swap(display_, kept_);
                        keptChanged_ = changed_;
                        keptShown_ = displayShown_;
                        keeping_ = true;
                    }
                    partTaken_ = false;
                    changed_.clear();
                }
                // The band's rows, as blocks of the pass, straight into the displayed image (the
                // first pass of a job fills it whole; another size is refilled whole).
                const bool whole = display_.width != w || display_.height != h;
                fillBlocks(work, stride, display_, y0, lattice.rowEnd);
                changed_.add(whole ? 0 : y0, whole ? h : lattice.rowEnd);
                ++displayVersion_;
                displayShown_ = {stride, lattice.rowEnd, previous, 0, 0, jobNumber};
                if (passDone) {
                    rec.sinceStartMs =
                        std::chrono::duration<double, std::milli>(Clock::now() - requested).count();
                    passes_.push_back(rec);
                }
                lock.unlock();
                if (onPass_) onPass_();
            }
            if (!complete) break;
            previous = stride;
        }
        std::lock_guard lock(mutex_);
        if (complete && !pending_) finished_ = true;
    }
}

}  // namespace lancer
