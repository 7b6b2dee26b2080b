// The scene's surfaces as the inspector's camera sees them, traced by the engine's tracer on a
// worker thread: exact CSG (no mesh to build), at a small size, primary rays only (no bounce,
// no shadow), with the depth of each pixel so the inspector's lines can be hidden behind them.
// The newest request wins; one in progress is cancelled.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "app/viewer/structure_builder.h"
#include "engine/render/image.h"

namespace lancer::viewer::inspector {

struct SurfaceImage {
    Camera camera;  ///< the camera it was traced for
    std::shared_ptr<const SceneBuild> structure;
    Image image;  ///< colour and depth (hit distance along the unit ray; +inf: miss)
};

class SurfaceTracer {
  public:
    SurfaceTracer();
    ~SurfaceTracer();
    SurfaceTracer(const SurfaceTracer&) = delete;
    SurfaceTracer& operator=(const SurfaceTracer&) = delete;

    /// Trace `structure`'s scene from `camera` at w x h, replacing any request not done.
    void request(std::shared_ptr<const SceneBuild> structure, const Camera& camera, int w, int h);
    /// The newest finished image, once.
    std::optional<SurfaceImage> poll();
    /// Called on the worker thread when an image is ready. Set it before the first request.
    void setOnReady(std::function<void()> f) { onReady_ = std::move(f); }
    bool busy() const;

  private:
    void run();

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<SurfaceImage> pending_, ready_;
    std::atomic<bool> cancel_{false};
    bool running_ = false, quit_ = false;
    std::function<void()> onReady_;
    std::thread worker_;
};

}  // namespace lancer::viewer::inspector
