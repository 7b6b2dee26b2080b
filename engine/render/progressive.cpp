#include "engine/render/progressive.h"

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace lancer {

void lowerThreadPriority() {
#ifdef __linux__
    // On Linux the nice value is per thread: this leaves the caller's other threads alone.
    setpriority(PRIO_PROCESS, id_t(syscall(SYS_gettid)), 5);
#endif
}

void fillBlocks(const Image& src, int stride, Image& dst) {
    if (dst.width != src.width || dst.height != src.height) dst.resize(src.width, src.height);
    for (int y = 0; y < src.height; ++y) {
        const int sy = y - y % stride;
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

bool ProgressiveRenderer::snapshot(uint64_t& version, Image& out, int* stride) const {
    std::lock_guard lock(mutex_);
    if (version == displayVersion_) return false;
    out = display_;
    if (stride) *stride = displayStride_;
    version = displayVersion_;
    return true;
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
        Clock::time_point requested;
        {
            std::unique_lock lock(mutex_);
            running_ = false;
            wake_.wait(lock, [&] { return quit_ || pending_; });
            if (quit_) return;
            job = std::move(*pending_);
            pending_.reset();
            requested = pendingRequested_;
            cancel_ = false;
            running_ = true;
        }
        const int w = job.options.width, h = job.options.height;
        Image work(w, h), shown;
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
            RenderStats rs = render(*job.scene, *job.accel, job.options, work, lattice, &cancel_,
                                    &progressDone_);
            if (rs.cancelled) {
                complete = false;
                break;
            }
            fillBlocks(work, stride, shown);
            std::unique_lock lock(mutex_);
            if (cancel_) {  // a newer job arrived while the pass finished: do not show this one
                complete = false;
                break;
            }
            std::swap(display_, shown);
            ++displayVersion_;
            displayStride_ = stride;
            PassRecord rec;
            rec.stride = stride;
            rec.renderMs = rs.renderMs;
            rec.sinceStartMs =
                std::chrono::duration<double, std::milli>(Clock::now() - requested).count();
            rec.counters = rs.counters;
            passes_.push_back(rec);
            previous = stride;
            lock.unlock();
            if (onPass_) onPass_();
        }
        std::lock_guard lock(mutex_);
        if (complete && !pending_) finished_ = true;
    }
}

}  // namespace lancer
