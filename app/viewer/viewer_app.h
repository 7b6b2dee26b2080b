// The viewer's frame, independent of the window: it sequences the steps of one frame (poll the
// workers, input, panels, the image, overlays, the panel layer). What is built, rendered and
// shown lives in ViewerState (viewer_state.h), the panels in panels/, the camera controls in
// input.h. A GLFW shell (window.cpp) or a test (an OSMesa context) calls frame() once per frame.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/gl/batch.h"
#include "app/viewer/image_view.h"
#include "app/viewer/inspector/inspector.h"
#include "app/viewer/overlay/overlays.h"
#include "app/viewer/panel_cache.h"
#include "app/viewer/panels/keys.h"
#include "app/viewer/panels/panels.h"
#include "app/viewer/panels/tree_panel.h"
#include "app/viewer/playback/ray_player.h"
#include "app/viewer/timing/frame_budget.h"
#include "app/viewer/timing/frame_times.h"
#include "app/viewer/viewer_state.h"

namespace lancer::viewer {

namespace gl {
class BatchRenderer;
}

class ViewerApp {
  public:
    using Clock = ViewerState::Clock;

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
    void openScene(const std::string& spec) { state_.openScene(spec); }
    /// Rebuild the structure with the current parameters, as a parameter change does.
    void rebuild(const char* why) { state_.requestBuild(false, why); }
    /// Everything asked for is built and the last frame drew the complete image.
    bool settled() const { return settled_; }
    /// What the workers produce next should be drawn at once: a build is under way or ready,
    /// the render of the latest change has shown nothing yet, a pass finer than the one on
    /// screen has begun to show, or the render is complete. Otherwise the render is only
    /// refining the pass on screen band by band, and a window may show its bands at a lower
    /// rate. Also while the overlays' layer is drawn over several frames, or image rows or the
    /// layer's read-back wait for the frame's budget.
    bool eager() const {
        return state_.eager(settled_) || overlays_->layerPending() ||
               inspector_->picturePending() || panels_.deferred() > 0 || view_->pendingRows() > 0 ||
               !layerRead_;
    }
    /// The frame drawn by the last frame() is on screen (after the window's swap): logs, with
    /// --log-timings, the passes it shows for the first time, with their latency.
    void presented() { state_.presented(); }
    /// A scripted turn (`lancer view --orbit`) moves the camera in this frame: the overlays are
    /// drawn as while a drag moves it (capped to the longest lines), and whole once it stops.
    void setCameraTurning(bool turning) { cameraTurning_ = turning; }
    /// A drag over the image or a scripted turn may move the camera in this frame.
    bool cameraMoving() const;
    /// Write the framebuffer as drawn by the last frame() to a PNG or JPEG (by the path's
    /// extension). Throws std::runtime_error.
    void saveScreenshot(const std::string& path, int fbWidth, int fbHeight) const;

    /// What the image area shows, and its heat scale (turns automatic scaling off).
    void setViewMode(ViewMode mode) { state_.setViewMode(mode); }
    void setHeatScale(float scale) { state_.setHeatScale(scale); }
    /// What the heat map shows of the last rebuild's A/B: the new image, the old one, or old
    /// minus new (compare/rebuild_diff.h).
    void setAbView(compare::AbView v) { state_.setAbView(v); }
    /// The image on screen (the last snapshot taken), the current error, the camera.
    const Image& displayed() const { return state_.shown(); }
    const std::string& error() const { return state_.error(); }
    const Camera& camera() const { return state_.camera(); }
    void setCamera(const Camera& c) { state_.setCamera(c); }
    /// The Camera panel's buttons: the camera as JSON to the clipboard (ImGui's, which the GLFW
    /// backend makes the desktop's), and back. A paste that is not a valid camera leaves the
    /// camera as it is and returns false; cameraError() says why.
    void copyCameraJson() { state_.copyCameraJson(); }
    bool pasteCameraJson() { return state_.pasteCameraJson(); }
    const std::string& cameraError() const { return state_.notes().cameraError; }
    /// The scene and accelerator on screen (null until the first build succeeds).
    const std::shared_ptr<const SceneBuild>& sceneBuild() const { return state_.sceneBuild(); }
    /// The heat scale in use this frame.
    float heatScale() const { return state_.heatScale(); }
    /// The speedup over brute force on the current view (the Statistics panel's button), on
    /// one pixel in `stride` x `stride`, on a worker thread; and its result once done.
    void measureSpeedup(int stride) { state_.measureSpeedup(stride); }
    std::optional<SpeedupResult> speedupResult() const { return state_.speedupResult(); }

    /// The overlays over the image (layers, selection); the inspector reads the selection.
    overlay::Overlays& overlays() { return *overlays_; }
    const overlay::Overlays& overlays() const { return *overlays_; }
    /// Apply a --show list (DESIGN.md section 6) to the overlays. Returns the items nothing in
    /// the viewer draws yet (to be refused by the caller); throws std::invalid_argument naming an
    /// unknown item. Views other than the overlays (the inspector's boxes, frustum and view, the
    /// ray) take their items here, from what the overlays leave.
    std::vector<std::string> applyShow(const std::string& list);
    /// The 3D inspector (its options, camera and what it draws); shown while
    /// settings().showInspector is set (the I key, the View panel, `--show inspector`).
    inspector::Inspector& inspector() { return *inspector_; }
    /// Show or hide the inspector.
    void showInspector(bool on) { state_.settings().showInspector = on; }
    /// The inspector's part of a --show list (DESIGN.md section 6): given the items the overlays
    /// do not draw, shows the inspector when "inspector" is among them and turns its boxes and
    /// frustum on or off as "boxes" and "frustum" are listed or not. Returns the items left
    /// (nothing draws them yet).
    std::vector<std::string> applyInspectorShow(const std::vector<std::string>& items);
    /// The selected region (-1: none): the overlays' selection, which the inspector highlights
    /// and a click in the inspector sets.
    int64_t selectedRegion() const {
        return overlays_->selection() ? int64_t(overlays_->selection()->region) : -1;
    }
    /// Select region `id` (-1: clear); the Selection panel opens on it.
    void selectRegion(int64_t id);
    /// The F key: frame the selected region (the played step's while a ray plays) in the
    /// inspector when `inInspector` or when the scheme's regions belong to the main camera
    /// (irregular; the inspector opens), else in the main view. False with no selection.
    bool frameSelection(bool inInspector);

    /// The ray playback: the picked pixel's tree and the ray played (Shift+click, the Ray
    /// panel, `--pick`). The current region is the selected region while a ray is played.
    playback::RayPlayer& rayPlayer() { return player_; }
    /// Pick pixel (x, y) of the image, select ray `ray` of its tree and stop at step `step`, as
    /// soon as a structure is on screen (`--pick X Y --ray K --step N`); shows the Ray panel.
    void pickPixel(int x, int y, int ray = 0, int step = 0);

    /// The structure tree panel's browser (its open nodes, where it drew the regions' rows).
    const TreeBrowser& treeBrowser() const { return tree_; }
    TreeBrowser& treeBrowser() { return tree_; }

    /// What is built, rendered and shown (what the panels read).
    ViewerState& state() { return state_; }
    const ViewerState& state() const { return state_; }
    /// Where the last frame put the panels, the image and the inspector (display units).
    const PanelLayout& layout() const { return layout_; }
    /// The colour keys the last frame drew over the image viewport's corner, and where.
    const KeyReport& keys() const { return keys_; }
    /// Where the last frame()'s UI CPU time went, by step (--log-timings' slow frames).
    const FramePhases& phases() const { return phases_; }
    /// The frame's budget shared by the steps that may leave work for the next frame (the
    /// overlays' copy and layer parts, the inspector's picture, the panel redraws).
    FrameBudget& frameBudget() { return budget_; }
    /// Panels the last frame rasterized again (the rest were copied from the panel layer).
    int panelsRedrawn() const { return panels_.redrawn(); }
    /// What the last frame's image step composited and copied (--log-timings' slow frames).
    const ImageView::ShadeCount& imageShade() const { return view_->lastShade(); }
    const FrameBudget& frameBudget() const { return budget_; }
    /// What the steps before the image's copy (the layer, a held view's and a finer pass's
    /// composites) keep back of the frame's budget beside the learned costs of the steps
    /// after them, in ms: 9 (the flush of the frame's GL work after the image step, about 6
    /// ms, and room for the inspector's pieces), or, when more, that flush's learned cost
    /// (`flushMs`) and that room.
    static double layerReserveMs(double flushMs);
    /// The learned cost of that flush, in ms (6 until measured).
    double imageFlushEstimateMs() const { return imageFlushCost_.estimateMs(1); }

  private:
    /// Upload rows [rowBegin, rowEnd) (-1: to the last) of the image on screen, with the heat
    /// values the state gives (a counter, or an A/B's).
    void uploadImage(int rowBegin, int rowEnd);
    /// The hover tooltip and Ctrl+click picking over the image viewport (mouse not taken by
    /// ImGui).
    void overlayInput();
    /// Steps 5 of frame(): the overlays' layer (imageW x imageH, the image's size) handed to
    /// the image view within the frame's budget less `reserveMs`, and its timing.
    void prepareOverlays(int imageW, int imageH, double reserveMs);
    /// The overlays' and the inspector's options and camera into the settings the ini is
    /// written from (marked to be saved when they changed).
    void keepSettings();
    /// The overlays' and the inspector's region filter: the played ray's regions while
    /// settings().rayRegionsOnly, else all.
    void syncRegionFilter();
    /// The structure tree panel (panels/tree_panel.h), its window Begin to End.
    void treePanel(bool* open);
    /// --log-timings: the overlays' work in this frame (`layerDrawn`: it drew the layers).
    void logOverlayTiming(double ms, bool layerDrawn);

    ViewerState state_;
    std::unique_ptr<ImageView> view_;
    std::unique_ptr<overlay::Overlays> overlays_;
    bool logTimings_ = false;
    bool cameraTurning_ = false;  ///< setCameraTurning: a scripted turn moves the camera
    struct OverlayStat {
        double ms = 0.0;
        int frames = 0;
        Clock::time_point since = Clock::now();
    } overlayStat_;
    std::unique_ptr<inspector::Inspector> inspector_;
    playback::RayPlayer player_;
    TreeBrowser tree_;
    std::unique_ptr<gl::BatchRenderer> rayRenderer_;
    Clock::time_point lastFrame_ = Clock::now();
    FramePhases phases_;                  ///< the last frame's CPU time by step
    FrameBudget budget_{kFrameBudgetMs};  ///< begun at each frame()
    /// The flush of the frame's GL work after the image step (its copy to the window, the
    /// clears around it), learned: 6 ms to begin with (balls4's slabs, 2026-12-07).
    StepCost imageFlushCost_{6.0};
    /// The image step's cost when the layer changed (its changed texels composited again), at
    /// rest [0] and while the camera moves [1]: kept back from the layer's budget. 8.6 ms (a
    /// whole 1280x720 composite) to begin with.
    StepCost layerCompositeCost_[2] = {StepCost(8.6), StepCost(8.6)};
    /// The region the playback selected last (-1: none), so a click elsewhere is not undone.
    int64_t playedRegion_ = -1;
    gl::Batch inspectorRay_;     ///< the lines last handed to the inspector
    PanelCache panels_;          ///< ImGui's panels, each redrawn only when it changed
    PanelHeights panelHeights_;  ///< what each panel asked for last frame
    PanelLayout layout_;         ///< where this frame's panels, image and inspector go
    KeyReport keys_;             ///< the colour keys drawn this frame
    bool settled_ = false;
    /// The image view holds the overlays' latest layer (its read-back waits for the budget).
    bool layerRead_ = true;
};

}  // namespace lancer::viewer
