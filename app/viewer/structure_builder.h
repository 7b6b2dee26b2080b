// Loads scenes and builds acceleration structures on a background thread, so the window keeps
// drawing (with the previous structure) while a new one is made. The newest request wins: it
// cancels a build in progress (within 100 ms, build_guard.h).
#pragma once

#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stop_token>
#include <string>
#include <thread>

#include "engine/accel/accelerator.h"

namespace lancer::viewer {

/// A scene and the acceleration structure built over it (not the structure description the
/// overlays draw); the accelerator refers to the scene, so they travel together (members are
/// destroyed in reverse order: the accelerator first).
struct SceneBuild {
    std::string spec;  ///< the SCENE argument it was loaded from
    std::shared_ptr<const Scene> scene;
    std::shared_ptr<const Accelerator> accel;
    double loadMs = 0.0;  ///< reading and preparing the scene
};

struct BuildRequest {
    std::string spec;
    std::shared_ptr<const Scene>
        loaded;  ///< the scene of `spec` when already loaded; else it is read
    BuildParams params;
    std::optional<Camera> camera;  ///< the view the structure is built for (irregular scheme)
    /// --camera: a .camera.json replacing the camera of the scene read (its home view).
    std::string cameraFile;
    ReadOptions read;  ///< --facets: how the scene is read
    /// The structure built over `loaded` for an earlier view: it lends what does not depend on
    /// the camera (BuildControl::previous). Null: none.
    std::shared_ptr<const Accelerator> previous;
};

struct BuildResult {
    std::shared_ptr<const SceneBuild> sceneBuild;  ///< null on failure
    std::string error;                             ///< why it failed
    bool sceneFailed = false;  ///< the scene could not be loaded (else: the build)
    uint64_t request = 0;
};

class StructureBuilder {
  public:
    StructureBuilder();
    ~StructureBuilder();  ///< cancels a build in progress and waits for it to return
    StructureBuilder(const StructureBuilder&) = delete;
    StructureBuilder& operator=(const StructureBuilder&) = delete;

    /// Queue a load/build, replacing any request not yet started and cancelling the one
    /// running. Returns its number.
    uint64_t request(BuildRequest r);
    /// The result of the newest request, once, when it is ready (older results are dropped).
    std::optional<BuildResult> poll();
    /// A request is queued or running.
    bool busy() const;
    /// A result is waiting for poll().
    bool ready() const;
    /// Called on the builder's thread when a result is ready. Set it before the first request.
    void setOnReady(std::function<void()> f) { onReady_ = std::move(f); }

  private:
    void run();

    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::optional<BuildRequest> pending_;
    std::optional<BuildResult> ready_;
    uint64_t requested_ = 0;
    bool running_ = false;
    std::stop_source stop_;  ///< the running build's
    bool quit_ = false;
    std::function<void()> onReady_;
    std::thread worker_;
};

/// Load (unless already loaded) and build, synchronously; a requested `stop` ends the build
/// early (the result then holds an error). Never throws: errors are in the result.
BuildResult buildStructure(const BuildRequest& r, std::stop_token stop = {});

}  // namespace lancer::viewer
