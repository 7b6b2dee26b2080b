// What the viewer is building, rendering and showing: the scene and its accelerator, the
// progressive render of the current view, the image on screen, the camera, errors, and the
// speedup measurement. The panels read it and act on it through its methods; it makes no GL
// call (the frame in viewer_app.cpp uploads and draws what it holds).
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/bench/speedup.h"
#include "app/viewer/colormap.h"
#include "app/viewer/compare/rebuild_diff.h"
#include "app/viewer/image_costs.h"
#include "app/viewer/image_view.h"
#include "app/viewer/playback/worst_rays.h"
#include "app/viewer/structure_builder.h"
#include "app/viewer/viewer_settings.h"
#include "engine/render/progressive.h"

namespace lancer::viewer {

/// Text fields and notes the panels keep from frame to frame.
struct PanelNotes {
    std::string pathInput;          ///< the Parameters panel's file field
    int builtinSize = -1;           ///< its size slider (-1: the scene's own size)
    std::string cameraJson;         ///< the last camera pasted
    std::string cameraError;        ///< why that paste was refused
    std::string screenshotNote;     ///< "saved FILE", or why it was not
    std::string pendingScreenshot;  ///< taken once the frame is drawn
    int screenshotCount = 0;
    int speedupStride = 4;  ///< the Statistics panel's sample: 1 pixel in stride x stride
    /// The Ray panel's "Worst rays": open, ranked by what (playback::RayCost), the list of the
    /// complete image of job `worstJob`, and where its first row was drawn (screen pixels).
    bool worstOpen = false;
    int worstBy = 0;
    uint64_t worstJob = 0;
    int worstListedBy = -1;
    std::vector<playback::CostlyPixel> worst;
    float worstFirstRow[2] = {-1.0f, -1.0f};
};

/// The totals of an A/B over the rows it compares (ViewerState::abTotals()).
struct AbTotals {
    compare::CounterSums a, b;  ///< old and new, over the same rows
    /// The whole new image compares: its passes' counters and render time are final.
    bool complete = false;
    RayCounters aCounters, bCounters;  ///< every ray of each image (when complete)
    double aRenderMs = 0.0, bRenderMs = 0.0;
};

/// The speedup over brute force on the current view, as the Statistics panel shows it.
struct SpeedupResult {
    std::string scheme;      ///< the scheme measured
    std::string error;       ///< why there is no measurement (the view changed, a build failed)
    bench::Speedup speedup;  ///< both renders, as `lancer bench` measures them
};

/// The pixels of a finer pass that one frame takes from the renderer at most (a third of a
/// 1280x720 image): the rest comes in the next frames (ViewerState::takeSnapshot).
inline constexpr int kSnapshotPixels = 1280 * 720 / 3;

class ViewerState {
  public:
    using Clock = std::chrono::steady_clock;

    /// Starts loading `settings.scene` at once. `settings` is the object the ini handler reads
    /// and writes; it must outlive the state. `wake` (optional) is called from worker threads
    /// when there is something new to show.
    ViewerState(ViewerSettings& settings, bool logTimings, std::function<void()> wake);
    ~ViewerState();
    ViewerState(const ViewerState&) = delete;
    ViewerState& operator=(const ViewerState&) = delete;

    // Frame steps (viewer_app.cpp calls them in order).
    /// Take what the workers finished before this frame: a new structure (or its failure) and
    /// the newest image.
    void poll();
    /// Whether the image must be uploaded again since the last call, and its rows that changed
    /// (all of them after a change of view mode).
    bool takeUpload(RowRange& rows);
    /// After the panels: follow the framebuffer's size, rebuild for a camera the irregular
    /// scheme was built for once the drag ends, and start the render a change asked for.
    void startWork(int fbWidth, int fbHeight);
    /// Everything asked for is built and rendered (as of the frame's start and now).
    bool settledSince() const;

    // What the panels read.
    ViewerSettings& settings() { return s_; }
    const ViewerSettings& settings() const { return s_; }
    /// The scene and accelerator on screen (null until the first build succeeds).
    const std::shared_ptr<const SceneBuild>& sceneBuild() const { return sceneBuild_; }
    bool building() const { return builder_.busy(); }
    /// A render of the current view is under way (false before the first scene is shown).
    bool rendering() const { return renderer_.job() != 0 && !renderer_.finished(); }
    const ProgressiveRenderer& renderer() const { return renderer_; }
    const std::string& error() const { return error_; }
    /// Why the run's first structure was refused (its options, its memory budget); "" while it
    /// was not. A refusal at start ends the run (window.cpp); later ones keep what is shown.
    const std::string& startRefusal() const { return startRefusal_; }
    const Camera& camera() const { return camera_; }
    const Camera& home() const { return home_; }
    /// The image on screen (the last snapshot taken).
    const Image& shown() const { return shown_; }
    /// A new view's image is coming in parts (takeSnapshot): the screen keeps the previous
    /// view's until the last part is in, so two views never share it.
    bool holdImage() const { return holding_; }
    /// The shown image has every row at full resolution: its counters are the render's.
    bool shownComplete() const { return shownComplete_; }
    /// The render job the shown image comes from (a new one for each change).
    uint64_t shownJob() const { return shownJob_; }
    /// Size of the render: the image viewport's (panels/layout.h), in pixels.
    int width() const { return jobWidth_; }
    int height() const { return jobHeight_; }
    /// Where the image viewport lies in the framebuffer this frame (pixels, row 0 at the top):
    /// every mapping between the mouse and an image pixel goes through it.
    const PixelRect& imageArea() const { return imageArea_; }
    /// Set by the frame from the layout, before the panels and the input read it.
    void setImageArea(const PixelRect& r) { imageArea_ = r; }
    /// The image pixel under the mouse, if the mouse is over the image viewport.
    std::optional<std::pair<int, int>> pixelUnderMouse() const;
    /// The heat scale in use this frame.
    float heatScale() const { return scale_; }
    PanelNotes& notes() { return notes_; }
    const PanelNotes& notes() const { return notes_; }
    /// Every panel and the menu bar hidden (Tab, --hide-panels): the image alone.
    bool panelsHidden() const { return panelsHidden_; }
    void setPanelsHidden(bool hidden) { panelsHidden_ = hidden; }

    // What the panels do.
    /// Open a scene: loaded in the background; on failure the error shows and the previous
    /// scene stays.
    void openScene(const std::string& spec);
    /// Rebuild with the current parameters (or reload the scene too).
    void requestBuild(bool reloadScene, const char* why);
    /// Render again (a shading parameter changed); the change is timed from now.
    void markRender(const char* why);
    void setCamera(const Camera& c);
    /// The camera as JSON to ImGui's clipboard, and back (false, with notes().cameraError, for
    /// a paste that is not a camera: the camera stays).
    void copyCameraJson();
    bool pasteCameraJson();
    /// What the image area shows; heat maps are uploaded again whole.
    void setViewMode(ViewMode mode);
    /// A fixed heat scale (turns automatic scaling off).
    void setHeatScale(float scale);

    // The A/B of the last rebuild (compare/rebuild_diff.h): the old structure's complete image
    // against the new one's, in the heat maps.
    /// What the heat map shows: the new image's counter, the old one's, or old minus new.
    compare::AbView abView() const { return ab_; }
    void setAbView(compare::AbView v);
    /// Show the old image's counter if the new one's is shown, else the new one's (the B key).
    void flipAb() {
        setAbView(ab_ == compare::AbView::Old ? compare::AbView::New : compare::AbView::Old);
    }
    /// The old image kept (null: none) and how it compares with the image on screen.
    const compare::CounterImage* abOld() const { return diff_.old(); }
    const compare::AbStatus& abStatus() const { return abStatus_; }
    /// Totals of the rows compared (meaningful when abStatus().comparable).
    const AbTotals& abTotals() const { return abTotals_; }
    /// The structure's parameters of the render on screen (B).
    const BuildParams& shownParams() const { return jobParams_; }
    /// The heat map's values of rows [rowBegin, rowEnd) (-1: to the last) as the image view
    /// uploads them: the shown counter, A's, or A minus B (kNoDiff where nothing compares);
    /// empty in colour mode.
    std::vector<float> heatRows(int rowBegin, int rowEnd) const;
    /// The heat map is a signed difference, drawn on the diverging map.
    bool heatDiverging() const;
    /// Ask, for this frame, for the counts per region of the last complete image (`rays`' visits
    /// and tests: the overlays' cost colourings and the tree browser call it each frame they
    /// show them). Once the image on screen is complete they are counted by an observer of the
    /// render's walk (countRegionCosts) on a worker thread at low priority, once per image; a
    /// new render cancels a count under way. Until the count is done the run is not settled.
    void requestCosts(CostRays rays) { costsWanted_ = rays; }
    /// The last counts done (null: none yet); they may be of a structure no longer on screen
    /// (costsFit() tells).
    const std::shared_ptr<const ImageCosts>& costs() const { return costs_; }
    /// Why the last count failed ("" when it did not).
    const std::string& costsError() const { return costsError_; }
    /// Measure the speedup over brute force on the current view, on a worker thread, with one
    /// pixel in `stride` x `stride`. Nothing happens before the first structure.
    void measureSpeedup(int stride);
    bool measuringSpeedup() const { return speedup_ && !speedup_->done; }
    /// The last measurement, once it is done.
    std::optional<SpeedupResult> speedupResult() const;

    // Timings (--log-timings).
    /// Whether what the workers produce next should be drawn at once (ViewerApp::eager()).
    bool eager(bool settled) const;
    /// The frame drawn is on screen: log the passes it shows for the first time.
    void presented();

  private:
    PixelRect imageArea_;  ///< the image viewport this frame (framebuffer pixels)
    struct SpeedupJob {
        std::atomic<bool> cancel{false}, done{false};
        SpeedupResult result;
        int stride = 4;
    };

    void pollBuilder();
    /// Take the renderer's newest image, if any (true then): at most kSnapshotPixels' worth of
    /// rows a frame, unless `whole` (a new view's held off the screen until complete).
    bool takeSnapshot(bool whole = false);
    void restartRender(const char* why);
    void updateAutoScale();
    /// After the snapshot: the A/B's status and totals, and a whole upload when what the heat
    /// map compares changed.
    /// Returns whether what is compared changed.
    bool updateAb();
    void logTiming(const std::string& line) const;

    ViewerSettings& s_;
    bool logTimings_;
    StructureBuilder builder_;
    ProgressiveRenderer renderer_;
    std::shared_ptr<const SceneBuild> sceneBuild_;
    Camera camera_, home_;
    std::string error_;
    std::string startRefusal_;
    bool started_ = false;  ///< a first build result (a structure or a failure) came
    PanelNotes notes_;
    bool panelsHidden_ = false;

    // The image on screen.
    Image shown_;
    uint64_t shownVersion_ = 0;
    uint64_t shownJob_ = 0;        ///< the render job the image on screen comes from
    int shownStride_ = 0;          ///< and the pass it shows (some of its rows, at least)
    RowRange changed_;             ///< rows not uploaded yet
    bool snapshotBehind_ = false;  ///< the last snapshot left rows of its pass to the next
    uint64_t screenJob_ = 0;       ///< the job whose rows the screen may show (caught up with)
    bool holding_ = false;         ///< a new job's rows are coming in parts: holdImage()
    bool uploadDue_ = false;
    int jobWidth_ = 0, jobHeight_ = 0;
    bool renderDirty_ = false, cameraMovedForBuild_ = false;
    std::string renderWhy_;
    float scale_ = 1.0f;
    float autoScale_ = 1.0f;
    /// As of the start of the frame: the job finished and the builder idle.
    bool finishedBefore_ = false, builtBefore_ = false;

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

    // The A/B of the last rebuild.
    compare::RebuildDiff diff_;
    compare::AbView ab_ = compare::AbView::New;
    compare::AbStatus abStatus_;
    AbTotals abTotals_;
    compare::RenderKey jobKey_;   ///< what the latest job renders
    BuildParams jobParams_;       ///< with the structure of these parameters
    uint64_t startedJob_ = 0;     ///< its number (ProgressiveRenderer::job())
    int shownRows_ = 0;           ///< rows of the shown pass done (Shown::rows)
    bool shownComplete_ = false;  ///< the shown image has every row at full resolution
    bool snapped_ = false;        ///< a snapshot was taken in this frame's poll
    uint64_t abSignature_ = 0;    ///< what the heat map compared at the last upload
    /// A's automatic scale for a counter, cached per A (a percentile of a million pixels).
    mutable uint64_t oldScaleGeneration_ = ~uint64_t(0);
    mutable float oldScale_[kViewModeCount] = {};

    std::shared_ptr<SpeedupJob> speedup_;
    std::thread speedupThread_;

    // The counts per region of the last complete image (requestCosts).
    struct CostJob {
        std::atomic<bool> cancel{false}, done{false};
        uint64_t job = 0;
        CostRays rays = CostRays::All;
        std::shared_ptr<const ImageCosts> result;  ///< null when cancelled or failed
        std::string error;
    };
    /// Take a finished count (poll: the frame's overlays and keys see it at once).
    void takeCosts();
    /// Start counting the shown image's costs when asked and not yet done for it.
    void updateCosts();
    std::function<void()> wake_;
    RenderOptions jobOptions_;                    ///< what the latest job renders
    std::shared_ptr<const SceneBuild> jobBuild_;  ///< with this structure
    std::optional<CostRays> costsWanted_;         ///< asked for in this frame
    bool costsDue_ = false;                       ///< asked for, and not done for the image
    std::shared_ptr<const ImageCosts> costs_;
    std::string costsError_;
    uint64_t costsTriedJob_ = 0;               ///< the job and rays of the last count
    CostRays costsTriedRays_ = CostRays::All;  ///< finished (done, failed)
    std::shared_ptr<CostJob> costJob_;
    std::thread costThread_;
};

}  // namespace lancer::viewer
