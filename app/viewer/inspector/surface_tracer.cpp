#include "app/viewer/inspector/surface_tracer.h"

#include "engine/render/progressive.h"  // lowerThreadPriority
#include "engine/render/renderer.h"

namespace lancer::viewer::inspector {

SurfaceTracer::SurfaceTracer() : worker_([this] { run(); }) {}

SurfaceTracer::~SurfaceTracer() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        quit_ = true;
        cancel_ = true;
    }
    wake_.notify_all();
    worker_.join();
}

void SurfaceTracer::request(std::shared_ptr<const SceneBuild> structure, const Camera& camera,
                            int w, int h) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        SurfaceImage s;
        s.camera = camera;
        s.structure = std::move(structure);
        s.image.width = w;  // sized on the worker
        s.image.height = h;
        pending_ = std::move(s);
        if (running_) cancel_ = true;
    }
    wake_.notify_all();
}

std::optional<SurfaceImage> SurfaceTracer::poll() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::optional<SurfaceImage> out = std::move(ready_);
    ready_.reset();
    return out;
}

bool SurfaceTracer::busy() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return running_ || pending_.has_value();
}

void SurfaceTracer::run() {
    lowerThreadPriority();  // the main render comes first
    for (;;) {
        SurfaceImage job;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return quit_ || pending_.has_value(); });
            if (quit_) return;
            job = std::move(*pending_);
            pending_.reset();
            running_ = true;
            cancel_ = false;
        }
        const int w = job.image.width, h = job.image.height;
        job.image.resize(w, h);
        RenderOptions opt;
        opt.width = w;
        opt.height = h;
        opt.threads = 1;
        opt.camera = job.camera;
        opt.shading.bounces = 0;
        opt.shading.shadows = false;
        opt.shading.reflections = false;
        opt.shading.refractions = false;
        RenderStats st;
        try {
            st = render(*job.structure->scene, *job.structure->accel, opt, job.image, {}, &cancel_);
        } catch (const std::exception&) {
            st.cancelled = true;  // nothing to show: the lines are drawn alone
        }
        bool notify = false;
        {
            std::lock_guard<std::mutex> lock(mutex_);
            running_ = false;
            if (!st.cancelled && !pending_) {
                ready_ = std::move(job);
                notify = true;
            }
        }
        if (notify && onReady_) onReady_();
    }
}

}  // namespace lancer::viewer::inspector
