#include "app/viewer/structure_builder.h"

#include <chrono>

#include "engine/render/progressive.h"
#include "engine/scene/loader.h"

namespace lancer::viewer {

BuildResult buildStructure(const BuildRequest& r, std::stop_token stop) {
    BuildResult out;
    auto s = std::make_shared<SceneBuild>();
    s->spec = r.spec;
    std::shared_ptr<const Scene> scene = r.loaded;
    if (!scene) {
        auto start = std::chrono::steady_clock::now();
        try {
            Scene loaded = loadScene(r.spec, r.read);
            if (!r.cameraFile.empty()) applyCameraFile(loaded, r.cameraFile);
            scene = std::make_shared<const Scene>(std::move(loaded));
        } catch (const std::exception& e) {
            out.error = e.what();
            out.sceneFailed = true;
            return out;
        }
        s->loadMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
    }
    if (r.camera) {  // the structure is built for this view; the scene's own camera stays the home
                     // view
        auto viewed = std::make_shared<Scene>(*scene);
        viewed->camera = *r.camera;
        scene = viewed;
    }
    try {
        s->accel = buildAccelerator(*scene, r.params, {std::move(stop), {}, r.previous.get()});
    } catch (const std::exception& e) {
        out.error = e.what();
        return out;
    }
    s->scene = std::move(scene);
    out.sceneBuild = std::move(s);
    return out;
}

StructureBuilder::StructureBuilder() {
    worker_ = std::thread([this] {
        lowerThreadPriority();
        run();
    });
}

StructureBuilder::~StructureBuilder() {
    {
        std::lock_guard lock(mutex_);
        quit_ = true;
        pending_.reset();
        stop_.request_stop();
    }
    wake_.notify_all();
    worker_.join();
}

uint64_t StructureBuilder::request(BuildRequest r) {
    std::lock_guard lock(mutex_);
    pending_ = std::move(r);
    ready_.reset();
    stop_.request_stop();  // the running build is superseded
    ++requested_;
    wake_.notify_all();
    return requested_;
}

std::optional<BuildResult> StructureBuilder::poll() {
    std::lock_guard lock(mutex_);
    std::optional<BuildResult> r;
    r.swap(ready_);
    return r;
}

bool StructureBuilder::busy() const {
    std::lock_guard lock(mutex_);
    return pending_.has_value() || running_;
}

bool StructureBuilder::ready() const {
    std::lock_guard lock(mutex_);
    return ready_.has_value();
}

void StructureBuilder::run() {
    for (;;) {
        BuildRequest r;
        uint64_t id;
        std::stop_token stop;
        {
            std::unique_lock lock(mutex_);
            wake_.wait(lock, [&] { return quit_ || pending_; });
            if (quit_) return;
            r = std::move(*pending_);
            pending_.reset();
            id = requested_;
            running_ = true;
            stop_ = std::stop_source();
            stop = stop_.get_token();
        }
        BuildResult result = buildStructure(r, stop);
        result.request = id;
        {
            std::lock_guard lock(mutex_);
            running_ = false;
            if (id == requested_)
                ready_ = std::move(result);  // a newer request supersedes this one
        }
        if (onReady_) onReady_();
    }
}

}  // namespace lancer::viewer
