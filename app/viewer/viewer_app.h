// The viewer's body, independent of the window: state, ImGui panels, camera input, the
// progressive render and structure builds in the background, and the GL drawing of each frame.
// A GLFW shell (window.cpp) or a test (an OSMesa context) calls frame() once per frame.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "app/viewer/image_view.h"
#include "app/viewer/inspector/inspector.h"
#include "app/viewer/panel_cache.h"
#include "app/viewer/structure_builder.h"
#include "app/viewer/viewer_settings.h"
#include "engine/render/progressive.h"

namespace lancer::viewer {

class ViewerApp {
  public:
    using Clock = std::chrono::steady_clock;

    /// Needs a current OpenGL 3.3 core context and an ImGui context whose OpenGL3 renderer
    /// backend is initialised. Starts loading `settings.scene` at once. `settings` is the
    /// object the ini handler reads and writes; it must outlive the app.
    /// `wake` (optional) is called from worker threads when there is something new to show.
    ViewerApp(ViewerSettings& settings, bool logTimings, std::function<void()> wake = {});
    ~ViewerApp();

    /// One frame: ImGui::NewFrame (the platform backend, if any, has set io.DisplaySize and the
    /// input), panels and camera input, then draws the image and the UI into the current
    /// framebuffer of fbWidth x fbHeight pixels.
    void frame(int fbWidth, int fbHeight);
    /// Open a scene (file dropped on the window, or typed): loaded in the background; on failure
    /// the error shows in the panel and the previous scene stays.
    void openScene(const std::string& spec);
    /// Rebuild the structure with the current parameters, as a parameter change does.
    void rebuild(const char* why) { requestBuild(false, why); }
    /// Everything asked for is built and the last frame drew the complete image.
    bool settled() const { return settled_; }
    /// What the workers produce next should be drawn at once: a build is under way or ready,
    /// the render of the latest change has shown nothing yet, a pass finer than the one on
    /// screen has begun to show, or the render is complete. Otherwise the render is only
    /// refining the pass on screen band by band, and a window may show its bands at a lower
    /// rate.
    bool eager() const;
    /// The frame drawn by the last frame() is on screen (after the window's swap): logs, with
    /// --log-timings, the passes it shows for the first time, with their latency.
    void presented();
    /// Write the framebuffer as drawn by the last frame() to a PNG. Throws std::runtime_error.
    void saveScreenshot(const std::string& path, int fbWidth, int fbHeight) const;

    /// What the image area shows, and its heat scale (turns automatic scaling off).
    void setViewMode(ViewMode mode);
    void setHeatScale(float scale);
    /// The image on screen (the last snapshot uploaded), the current error, the camera.
    const Image& displayed() const { return shown_; }
    const std::string& error() const { return error_; }
    const Camera& camera() const { return camera_; }
    void setCamera(const Camera& c);
    /// The Camera panel's buttons: the camera as JSON to the clipboard (ImGui's, which the GLFW
    /// backend makes the desktop's), and back. A paste that is not a valid camera leaves the
    /// camera as it is and returns false; cameraError() says why.
    void copyCameraJson();
    bool pasteCameraJson();
    const std::string& cameraError() const { return cameraError_; }
    /// The scene and structure on screen (null until the first build succeeds).
    const std::shared_ptr<const Structure>& structure() const { return structure_; }
    /// The 3D inspector (its options, camera and what it draws).
    inspector::Inspector& inspector() { return *inspector_; }
    /// Show or hide the inspector (the I key, the View panel's checkbox, `--show inspector`).
    void showInspector(bool on) { inspector_->setShown(on); }
    /// The selected region (-1: none), which the inspector highlights; a click in the inspector
    /// sets it.
    int64_t selectedRegion() const { return selected_; }
    void selectRegion(int64_t id) { selected_ = id; }
    /// The heat scale in use this frame.
    float heatScale() const { return scale_; }

    /// The speedup over brute force on the current view (the Statistics panel's button): the
    /// pixels of one in `stride` x `stride` traced with the scheme, then with brute force, on
    /// a worker thread. Nothing happens before the first structure.
    void measureSpeedup(int stride);
    struct SpeedupResult {
        std::string scheme, error;
        size_t pixels = 0;
        double schemeMs = 0.0, bruteMs = 0.0;
        uint64_t schemeRays = 0, bruteRays = 0, schemeTests = 0, bruteTests = 0;
    };
    /// The last measurement, once it is done.
    std::optional<SpeedupResult> speedupResult() const;

  private:
    void pollBackground();
    /// Upload what the renderer has new, if anything, and log the passes that became visible.
    void takeSnapshot();
    void handleInput(int fbWidth, int fbHeight);
    void handleKeys();
    void panels();
    void parametersPanel();
    void cameraPanel();
    void statisticsPanel();
    void viewPanel();
    void requestBuild(bool reloadScene, const char* why);
    void restartRender(const char* why);
    void markRender(const char* why);
    void startSpeedup();
    void logTiming(const std::string& line) const;
    void updateAutoScale();
    /// The heat scale this frame draws with: the automatic one or the user's.
    void updateScale();

    ViewerSettings& s_;
    bool logTimings_;
    std::unique_ptr<ImageView> view_;
    std::unique_ptr<inspector::Inspector> inspector_;
    int64_t selected_ = -1;
    PanelCache panels_;  ///< ImGui's panels, each redrawn only when it changed
    StructureBuilder builder_;
    ProgressiveRenderer renderer_;
    std::shared_ptr<const Structure> structure_;
    Camera camera_, home_;
    bool cameraSet_ = false;  ///< camera_ chosen (else it follows the next scene)
    std::string error_;
    Image shown_;
    uint64_t shownVersion_ = 0;
    uint64_t shownJob_ = 0;  ///< the render job the image on screen comes from
    int shownStride_ = 0;    ///< and the pass it shows (some of its rows, at least)
    int jobWidth_ = 0, jobHeight_ = 0;
    bool renderDirty_ = false, buildDirty_ = false, cameraMovedForBuild_ = false;
    std::string renderWhy_;
    float scale_ = 1.0f;
    float autoScale_ = 1.0f;  ///< largest value of the shown counter
    bool settled_ = false;

    // Latency of the last change: when it happened, what it was, what was logged.
    Clock::time_point changeAt_ = Clock::now(), buildChangeAt_ = Clock::now();
    std::string changeWhy_, buildWhy_;
    size_t passesLogged_ = 0;
    /// Timing lines of passes in the image drawn but not yet on screen: text before the latency,
    /// after it, and the change it counts from.
    struct PendingLog {
        std::string before, after;
        Clock::time_point since;
    };
    std::vector<PendingLog> pendingLogs_;

    // UI scratch.
    std::string pathInput_, cameraJson_, cameraError_, screenshotNote_, pendingScreenshot_;
    int builtinSize_ = -1;
    int screenshotCount_ = 0;

    // Speedup over brute force, measured on demand on a worker thread.
    struct Speedup;
    std::shared_ptr<Speedup> speedup_;
    std::thread speedupThread_;
    int speedupStride_ = 4;
};

}  // namespace lancer::viewer
