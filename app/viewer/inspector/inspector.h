// The 3D inspector: a view of its own, with its own orbit camera, drawn beside the image where
// the window's layout puts it. It shows the structure's regions (regular leaves coloured by
// primitive count or level, with a level range and a slice slab; irregular zones and slabs), the
// directory's blocks, the minimized boxes, the camera's frustum and image plane, and the scene's
// surfaces traced from its camera (surface_tracer.h), the lines hidden behind them by the traced
// depth. A click picks the nearest drawn region. No window needed: a test drives it in OSMesa.
#pragma once

#include <cstdint>
#include <functional>
#include <glm/mat4x4.hpp>
#include <memory>
#include <optional>
#include <string>
#include <utility>

#include "app/viewer/background_job.h"
#include "app/viewer/image_view.h"  // PixelRect
#include "app/viewer/inspector/inspector_model.h"
#include "app/viewer/inspector/surface_tracer.h"
#include "app/viewer/timing/frame_budget.h"

namespace lancer::viewer::gl {
class BatchRenderer;
class GpuBatch;
class Program;
}  // namespace lancer::viewer::gl

namespace lancer::viewer::inspector {

class Inspector {
  public:
    /// Needs a current OpenGL 3.3 core context (as do draw() and the destructor). `wake` (may
    /// be empty) is called from the tracer's thread when the surfaces are ready.
    explicit Inspector(std::function<void()> wake = {});
    ~Inspector();
    Inspector(const Inspector&) = delete;
    Inspector& operator=(const Inspector&) = delete;

    /// The switches and filters; call changed() after editing them.
    InspectorOptions& options() { return opt_; }
    const InspectorOptions& options() const { return opt_; }
    void changed() { dirtyModel_ = true; }
    /// Show or hide the inspector (the I key, the View panel, `--show inspector`).
    void setShown(bool on);
    bool shown() const { return opt_.show; }

    /// Where the inspector draws in a fbWidth x fbHeight framebuffer by default: its right half.
    static PixelRect viewport(int fbWidth, int fbHeight);
    /// Where it draws (framebuffer pixels, row 0 on top): the window's layout sets it; an empty
    /// rectangle (the default) means viewport().
    void setArea(const PixelRect& r) { area_ = r; }
    PixelRect area(int fbWidth, int fbHeight) const;
    /// Its camera (framed on the structure when the scene changes), and setting it.
    const Camera& camera() const { return camera_; }
    void setCamera(const Camera& c);
    /// Move its camera to frame `box` (framedOn(), its viewport's aspect) at the next update(),
    /// once its viewport and structure are known: the F key.
    void frame(const Box3& box) { pendingFrame_ = box; }
    /// The scene (its spec) the camera was framed for or moved over; empty before the first.
    const std::string& cameraScene() const { return cameraScene_; }
    /// Use `c` instead of framing the first structure, if it is of scene `sceneSpec` (a camera
    /// saved in the ini for that scene).
    void restoreCamera(const Camera& c, const std::string& sceneSpec) { restore_ = {c, sceneSpec}; }

    /// Once a frame, before input and drawing: the structure on screen, the main view, the
    /// selected region (-1: none). Rebuilds what changed.
    void update(const std::shared_ptr<const SceneBuild>& structure, const MainView& main,
                int fbWidth, int fbHeight, int64_t selected);
    /// Mouse input over the inspector (ImGui's io, framebuffer pixels): orbit (left drag), pan
    /// (middle drag), zoom (wheel, right drag), pick (left click). True when the inspector took
    /// the mouse this frame (the main camera must not move). A click sets `picked` to the
    /// region under the cursor, or -1 on empty space.
    bool handleMouse(int fbWidth, int fbHeight, std::optional<int64_t>& picked);
    /// The region the ray through viewport pixel (x, y) (top-left origin) meets first among
    /// those drawn, or -1.
    int64_t pick(double x, double y) const;
    /// Draw into framebuffer 0 of fbWidth x fbHeight, in viewport(). Only re-rendered when
    /// something changed; otherwise the last picture is copied.
    void draw(int fbWidth, int fbHeight);
    /// World-space lines drawn over the picture, in front of everything (the ray playback's
    /// region and ray); an empty batch draws nothing. Re-renders the picture.
    void setExtraLines(gl::Batch batch);
    /// The Inspector panel: its layers, colours, level range, slice slab, cap and counts.
    void panel(bool* open);

    /// Hidden, or showing everything asked for: the surfaces of its camera (when on) are traced
    /// and the model is up to date.
    bool settled() const;
    /// What is drawn (for the panel and tests): the model (without the frustum) and the main
    /// camera's frustum, apart, so a turn of the main camera builds only the frustum again.
    const InspectorModel& model() const { return model_; }
    const gl::Batch& frustum() const { return frustum_; }
    /// Build the model on a worker thread from now on, `wake` (may be empty) called from it
    /// when it is ready; until then the last model is drawn. Otherwise (tests) update() builds
    /// it itself. balls4's irregular slabs took the UI thread 57-111 ms a structure (2026-12-06).
    void buildInBackground(std::function<void()> wake);
    /// Times the model was built (tests: what changes it and what does not).
    uint64_t modelBuilds() const { return modelBuilds_; }
    /// Draw the picture's lines in parts of `lines` (copied to GL in parts too) until `ms` of
    /// a draw() have passed (0: one part a draw), the rest at the next draws; 0 lines: whole
    /// (the default). balls4's inspector picture (20,000 regions, 240,000 lines) took
    /// llvmpipe 50-75 ms in one frame (2026-12-06).
    void drawInParts(size_t lines, double ms);
    /// Share a frame's budget from now on (null: none): draw() starts each piece of the
    /// picture (a band of its surfaces' rows, a part of its lines) only when the piece's
    /// learned cost fits in the frame's budget less `reserveMs` and the learned cost of
    /// copying the picture to the window after it, and leaves the rest to later
    /// draws; the picture on screen stays until then (a draw's first piece waits
    /// kPatienceFrames draws at most). The budget must outlive the inspector or
    /// be unset.
    void setFrameBudget(FrameBudget* budget, double reserveMs) {
        budget_ = budget;
        budgetReserveMs_ = reserveMs;
    }
    /// The learned cost of the picture's copy to the window that each draw() makes while it is
    /// shown (0 when hidden), in ms: the steps before it keep it back.
    double showEstimateMs() const { return opt_.show ? showCost_.estimateMs(1) : 0.0; }
    /// A picture is to be drawn (a change since the last draw), completed or drawn again (the
    /// budget) by later draws.
    bool picturePending() const {
        return opt_.show && (dirtyPicture_ || picturePending_ || pictureDeferred_);
    }
    /// The size of the picture's framebuffer (the view's once made: makeFramebuffer()).
    std::pair<int, int> framebufferSize() const { return {fboW_, fboH_}; }
    /// Lines of the model in the picture so far (all of them once it is whole).
    size_t picturedLines() const { return picturedLines_; }
    /// Surfaces of the current camera are on screen (the trace arrived).
    bool surfacesShown() const;
    /// Wait (tests) until the surfaces of the current camera are traced, up to `ms`.
    bool waitSurfaces(int ms);

  private:
    void rebuildModel();
    /// Draw nothing visible into the picture's framebuffer (bound, of vw_ x vh_) with each of
    /// its states: readies the driver for them (the constructor, before any frame).
    void warmUp();
    /// The main camera's frustum again (frustum_), for the picture.
    void rebuildFrustum();
    void requestSurfaces();
    void takeSurfaces();
    /// Start the picture again: the surfaces, then the lines (renderMore()).
    void render();
    /// The next surface rows or lines of the picture, for the part's time, and the lines over
    /// them.
    void renderMore();
    /// Rows [rowBegin, rowEnd) of the traced surfaces into the picture (GL's rows).
    void drawSurfaceRows(int rowBegin, int rowEnd);
    /// Near and far depths of everything drawn, for the inspector's camera.
    void depthBounds(double& near, double& far) const;

    InspectorOptions opt_;
    Camera camera_;
    bool cameraFramed_ = false;
    std::string cameraScene_;
    struct Restore {
        Camera camera;
        std::string scene;
    };
    std::optional<Restore> restore_;
    std::optional<Box3> pendingFrame_;  ///< frame()
    std::shared_ptr<const SceneBuild> structure_;
    std::shared_ptr<const StructureView> view_;
    MainView main_;
    int64_t selected_ = -1;
    PixelRect area_;       ///< setArea()
    int vw_ = 0, vh_ = 0;  ///< viewport size
    InspectorModel model_;
    gl::Batch frustum_;  ///< frustumLines() of main_ (empty without InspectorOptions::frustum)
    bool dirtyModel_ = true, dirtyPicture_ = true, dirtyBatch_ = true;
    uint64_t modelBuilds_ = 0;
    bool background_ = false;
    std::function<void()> wake_;
    bool dragging_ = false;  ///< a drag that began in the inspector is under way
    int dragButton_ = -1;

    gl::Batch extra_;  ///< setExtraLines()
    SurfaceTracer tracer_;
    std::optional<SurfaceImage> surfaces_;  ///< the last traced surfaces
    bool surfacesRequested_ = false;
    Camera requestedCamera_;
    int requestedW_ = 0, requestedH_ = 0;

    // GL.
    std::unique_ptr<gl::BatchRenderer> batches_;
    std::unique_ptr<gl::GpuBatch> lines_, selection_, frustumGpu_;
    std::unique_ptr<gl::Program> surfaceProgram_;
    unsigned fbo_ = 0, colorTex_ = 0, depthRb_ = 0, surfColorTex_ = 0, surfDepthTex_ = 0, vao_ = 0;
    int fboW_ = 0, fboH_ = 0, surfW_ = 0, surfH_ = 0;
    /// The picture's storage at a new size (nextW_ x nextH_), made beside the one on screen,
    /// colour and depth each in a draw of its own (makeFramebuffer()).
    unsigned nextColorTex_ = 0, nextDepthRb_ = 0;
    int nextW_ = 0, nextH_ = 0;
    bool nextColorMade_ = false, nextDepthMade_ = false;
    /// Give the picture's framebuffer the view's size: -1 while a storage waits for the budget
    /// (the picture on screen stays), 0 if it had it, 1 once made now (its picture is to draw).
    int makeFramebuffer();
    bool surfUploaded_ = false;
    // The picture in parts (drawInParts()).
    static constexpr size_t kPartBytes = size_t(2) << 20;  ///< copied to GL per part
    size_t partLines_ = 0;
    double partMs_ = 0.0;
    size_t picturedLines_ = 0;
    bool picturePending_ = false;
    bool pictureSurfaces_ = false;
    double pictureNear_ = 0.0, pictureFar_ = 1.0;
    int surfaceRows_ = 0;  ///< rows of the surfaces in the picture so far
    /// The traced surfaces are drawn in bands of a 24th of the rows when in parts: a band of a
    /// sixth of balls4's rows took llvmpipe 4-7 ms (2026-12-06), too much to start late in a
    /// frame.
    static constexpr int kSurfaceBands = 24;
    /// The next piece of the picture: rows of the surfaces' next band (0: the lines are next).
    int nextBandRows() const;
    /// The next piece's estimated cost, in ms (the budget asks it before the piece starts).
    double nextPieceMs() const;
    /// Learned costs (FrameBudget's clock): a row of surfaces, a part of lines (its copy to GL
    /// and its drawing, with the frustum and selection drawn over it); about 4 ms a band of
    /// 120 rows and 4 ms a part to begin with (balls4, 2026-12-06).
    StepCost rowCost_{4.0 / 120.0};
    StepCost partCost_{4.0};
    /// A new picture's start (its clear, about 2 ms) and new surfaces' conversion and copy to
    /// GL (1-5 ms), also learned.
    StepCost startCost_{2.0};
    StepCost surfaceCopyCost_{3.0};
    /// The picture's copy to the window, which draw() makes after its pieces in every frame
    /// (4-5 ms of llvmpipe's time for balls4's inspector at 1280x720, 2026-12-07): learned,
    /// and kept back beside the reserve, so that the last piece does not push it over the
    /// frame's budget.
    StepCost showCost_{5.0};
    /// A storage of the picture's framebuffer (its colour texture, its depth buffer) per
    /// texel: llvmpipe clears what it allocates, about 10 ms each at 1280x720 (2026-12-07).
    StepCost storageCost_{10.0 / (1280.0 * 720.0)};
    /// The draws in a row a storage of a new size waited for the budget (never starved).
    Patience storagePatience_{"the inspector's framebuffer of a new size"};
    /// What a piece leaves of the frame's budget: the reserve given and the picture's copy.
    double reserveMs() const;
    FrameBudget* budget_ = nullptr;  ///< setFrameBudget()
    double budgetReserveMs_ = 0.0;
    bool pictureDeferred_ = false;  ///< the last draw() left the picture for the budget
    /// The draws in a row the picture's first piece waited for the budget: it starts whatever
    /// the budget after kPatienceFrames (never starved).
    Patience piecePatience_{"the inspector's first piece"};
    glm::mat4 pictureToClip_{1.0f};
    BackgroundJob<InspectorModel> job_;  ///< last: its worker joined before the rest is destroyed
};

}  // namespace lancer::viewer::inspector
