// The overlays drawn over the image, after it and before the panels: their options and
// panels (Overlays, Selection), their batches cached per structure, camera, image size and
// options, the hover tooltip, picking and the selection (which the inspector reads to
// highlight the same region).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "app/viewer/background_job.h"
#include "app/viewer/gl/batch.h"
#include "app/viewer/image_costs.h"
#include "app/viewer/overlay/overlay_geometry.h"
#include "app/viewer/structure_builder.h"
#include "app/viewer/timing/frame_budget.h"
#include "engine/render/ray_csg.h"

namespace lancer::viewer::overlay {

/// Drawing choices that need no rebuild of the batches.
struct OverlayLook {
    bool operator==(const OverlayLook&) const = default;
    int replayCuts = -1;        ///< cuts drawn, in the order they were made (-1: all)
    float fillOpacity = 0.35f;  ///< zones' fills
    float lineOpacity = 0.9f;   ///< cut lines and wireframes
    bool tooltip = true;        ///< the hover tooltip over the image
    /// Wireframe lines drawn while the camera moves at most (the longest first; cut lines and
    /// fills capped alike), in parts of restLines until movingMs have passed: the whole layer
    /// is drawn again when it rests. 0: none while it moves.
    size_t movingLines = 2000;
    /// With a frame's budget (Overlays::setFrameBudget()) a moving camera's first part holds
    /// as many lines as the budget leaves room for, at their learned cost, but at least this
    /// many, whatever the budget: the longest, the view's outline.
    size_t movingMinLines = 100;
    /// Milliseconds of a frame while the camera moves given to drawing the layer (0: one part).
    /// balls4's 2,000 longest slab lines took llvmpipe 14-20 ms a frame (2026-12-06).
    double movingMs = 6.0;
    /// At rest a layer of more lines than this is drawn in parts of this many, the longest
    /// lines first (cut lines and fills in step), parts added in a frame until restMs have
    /// passed, and completed over the next frames: no frame draws it whole (balls4's 1.2 M
    /// slab lines took one frame 0.43-0.79 s, 2026-12-06). Coarse first: the longest lines
    /// (the largest regions) are in every frame's first part, the detail comes after. Small
    /// parts keep a frame near its budget: a part of 2,000 of balls4's longest slab lines took
    /// 18-31 ms (2026-12-06).
    size_t restLines = 500;
    /// Milliseconds of a frame at rest given to drawing the layer's parts (0: one part a frame),
    /// within what the frame's budget leaves (setFrameBudget()). Each part drawn composites the
    /// image's texels it changed again (ImageView::setOverlay); at 8 ms, when each part
    /// composited the whole image (8-10 ms at 1280x720), a part frame took 33-37 ms of CPU on
    /// balls4's slabs (2026-12-06).
    double restMs = 5.0;
    /// Batches built in the background are copied to GL in parts of uploadBytes, for
    /// uploadMs of each frame (0: one part a frame), the layer drawn from what is copied:
    /// balls4's slab batches (1.2 M lines, 77 MB) took one frame 31 ms (2026-12-06).
    size_t uploadBytes = size_t(2) << 20;
    double uploadMs = 4.0;
};

/// The region picked in the image (or set by --select, or by the inspector).
struct Selection {
    uint32_t region = 0;
    int64_t zone = -1;  ///< irregular: the zone, in `frame`
    ZoneFrameKind frame = ZoneFrameKind::Camera;
};

class Overlays {
  public:
    /// Needs a current OpenGL 3.3 core context from construction to destruction.
    Overlays();
    ~Overlays();
    Overlays(const Overlays&) = delete;
    Overlays& operator=(const Overlays&) = delete;

    OverlayOptions options;  ///< the layers (a change rebuilds the batches at the next update)
    OverlayLook look;

    /// Take the structure on screen (null: none yet) and rebuild the batches if the structure,
    /// the camera they depend on, the size or the options changed. Until a new structure
    /// arrives the previous one's overlays stay. While the camera is `moving` (a drag), batches
    /// culled for an earlier view are kept: they are culled again once it rests. Without
    /// `copy` no part of the batches is copied to GL (the frame's first update, before the
    /// steps after the layer have said what they take: a later update with `copy` in the same
    /// frame copies within the budget then).
    void update(const std::shared_ptr<const SceneBuild>& structure, const Camera& view, int width,
                int height, bool moving = false, bool copy = true);
    /// Draw the layers and the selection into the current framebuffer (width x height, the
    /// image filling it), as seen by `view`.
    void draw(const Camera& view, int width, int height) {
        drawLayers(view, width, height);
        drawSelection(view, width, height);
    }
    /// The last complete image's counts (null: none yet). A cost colouring uses them when they
    /// are of the structure on screen and of options.costRays; the batches are rebuilt when
    /// they change.
    void setCosts(std::shared_ptr<const ImageCosts> costs) { costs_ = std::move(costs); }
    /// The counts the batches were last built with (null: none).
    const ImageCosts* builtCosts() const { return builtCosts_.get(); }
    /// The layers alone (cut lines, fills, wireframes), blended into the current framebuffer.
    void drawLayers(const Camera& view, int width, int height) {
        drawLayers(view, width, height, SIZE_MAX);
    }
    /// The layers with at most `lines` wireframe lines (the longest), cut lines and fills.
    void drawLayers(const Camera& view, int width, int height, size_t lines);
    /// The selection's highlight alone (a few lines and faces: cheap to draw every frame), in
    /// a width x height viewport whose lower-left corner is framebuffer pixel (x0, y0) (GL's
    /// rows: the image viewport).
    void drawSelection(const Camera& view, int width, int height, int x0 = 0, int y0 = 0);
    /// The layers drawn into a texture of their own (premultiplied RGBA, framebuffer rows),
    /// again only when the batches, the camera, the size or the look changed: the image view
    /// composites it when it shades the image (ImageView::setOverlay), so layers of a million
    /// lines cost nothing in a frame where nothing changed. 0 when no layer is on.
    /// With `moving` (the camera is being moved), the texture holds only the first lines
    /// (OverlayGeometry::wiresLongestFirst): parts of look.restLines until look.movingMs have
    /// passed, at most look.movingLines; it goes on at the first call without (below); 0 while
    /// moving when look.movingLines is 0. At rest a layer
    /// of more than look.restLines lines is drawn in parts of look.restLines, longest first,
    /// for look.restMs at each call, until it is whole (layerPending()).
    unsigned layerTexture(const Camera& view, int width, int height, bool moving = false);
    /// layerTexture() would draw the texture again (or has none to give); a texture drawn
    /// while moving is stale once the camera rests.
    bool layerStale(const Camera& view, int width, int height) const;
    /// The texture holds a moving camera's capped layer, or a layer not yet drawn whole.
    bool layerPartial() const { return layerPartial_; }
    /// At rest, the layer is being drawn over several frames: more calls to layerTexture()
    /// complete it (also when the frame's budget deferred it).
    bool layerPending() const {
        return (layerDeferred_ || (layerPartial_ && !layerMoving_)) && options.any() && view_;
    }
    /// Share a frame's budget from now on (null: none, each step only its own share): each
    /// part of the batches' copy to GL (once a frame) and of the layer starts only when its
    /// learned cost fits in the frame's budget less `reserveMs` (kept for the steps after
    /// them); the rest goes on in the next frames. At rest no part is drawn then; a moving
    /// camera's layer draws a first part in any case, of as many lines as fit
    /// (OverlayLook::movingMinLines at least). At rest the texture of a new size is made only
    /// when its learned cost fits, and the layer is drawn into it from the next call. None of
    /// these waits for ever: after kPatienceFrames frames deferred in a row, the first part of
    /// the next starts whatever the budget (FrameBudget::fits() with a Patience). The budget
    /// must outlive the overlays or be unset.
    void setFrameBudget(FrameBudget* budget, double reserveMs) {
        budget_ = budget;
        budgetReserveMs_ = reserveMs;
    }
    /// Lines of the layer drawn into the texture so far, of layerLines().
    size_t layerDrawn() const { return layerDrawn_; }
    /// The layer's lines (the wireframe's, or the cuts' or zones' when they are more).
    size_t layerLines() const;
    /// Milliseconds the last drawing of the layers' texture took (to the end of GL's work).
    double lastLayerMs() const { return lastLayerMs_; }
    /// Incremented each time layerTexture() draws the texture again.
    uint64_t layerVersion() const { return layerVersion_; }

    /// The Overlays panel (layers, replay, opacity, level range, cap, counts).
    void panel(bool* open);
    /// The Selection panel: the selected region's box, primitives, restricted tree, neighbours.
    void selectionPanel(bool* open);
    /// The played ray's evaluation of region `region`'s tree (rayCsg's nodes of the current
    /// step) in `pool`: while that region of the same structure is selected the Selection panel
    /// lights the nodes evaluated, with their spans, and dims the others. `region` -1: no ray
    /// played.
    void setEvaluatedNodes(int64_t region, const CsgTree* pool,
                           const std::vector<NodeSpans>& nodes) {
        evalRegion_ = region;
        evalPool_ = pool;
        evalNodes_ = nodes;
    }
    /// The tooltip for the image point (x, y) under the mouse (continuous image coordinates);
    /// `depth` is the primary hit distance there.
    void tooltip(const Camera& view, int width, int height, double x, double y, float depth);
    /// Select the region under image point (x, y); false (selection unchanged) when none.
    bool pickAt(const Camera& view, int width, int height, double x, double y, float depth);

    /// The selection, if any.
    const std::optional<Selection>& selection() const { return selection_; }
    /// Select region `id` of the structure on screen; false (nothing selected) when there is no
    /// such region.
    bool select(uint32_t id);
    void clearSelection() { selection_.reset(); }
    /// The description of the structure on screen (null before the first).
    const StructureView* view() const { return view_.get(); }
    /// The structure it describes (null before the first).
    const SceneBuild* structure() const { return structure_.get(); }
    /// Build the batches on a worker thread from now on, `wake` (may be empty) called from it
    /// when they are ready (the viewer: a frame never waits for them; until they come the
    /// previous ones are drawn). Otherwise (tests) update() builds them itself.
    void buildInBackground(std::function<void()> wake);
    /// A build of the batches is under way on the worker, or its batches are being copied to
    /// GL (OverlayLook::uploadMs).
    bool building() const { return job_.pending() || !uploaded(); }
    /// The batches built are all copied to GL.
    bool uploaded() const;
    /// Bytes of the batches taken that are copied to GL so far (in parts: uploadMore()).
    size_t copiedBytes() const;
    /// The layer's first lines (in longest-first order) whose wires, cut lines and fills are
    /// all copied to GL: what its parts may draw.
    size_t layerReady() const;
    /// The cached geometry (what the last update built).
    const OverlayGeometry& geometry() const { return geometry_; }
    /// Times the batches were rebuilt (tests: a change rebuilds, nothing else does).
    uint64_t rebuilds() const { return rebuilds_; }
    /// Milliseconds the last rebuild took (building and uploading the batches).
    double lastBuildMs() const { return lastBuildMs_; }

  private:
    /// The Overlays panel's colour choice of leaves or BVH nodes, and its cost line (which
    /// rays, whether the counts are there).
    void leafColorCombo(const char* label);
    void costLine();

    /// The layers' lines [first, first + count): `longestFirst`, of
    /// OverlayGeometry::wiresLongestFirst, with the cut lines in cut order and the zones' fills
    /// of the same indices (the parts [0, a) then [a, b) draw what [0, b) draws); otherwise the
    /// wireframe in its own order and every fill.
    void drawLayerRange(const Camera& view, int width, int height, size_t first, size_t count,
                        bool longestFirst);

    /// What a build of the batches reads: taken whole, so a worker reads nothing that changes.
    struct BuildInputs {
        std::shared_ptr<const SceneBuild> structure;  ///< what `view` reads, kept alive
        std::shared_ptr<const StructureView> view;
        Camera camera;
        int width = 0, height = 0;
        OverlayOptions options;
        std::shared_ptr<const ImageCosts> costs;
    };
    static OverlayGeometry build(const BuildInputs& in);
    /// The built geometry into the GL batches (in parts, from a worker's build), and what it
    /// was built for.
    void take(OverlayGeometry geometry, const BuildInputs& in, double ms, bool copy);
    /// Copy more of the batches taken, for look.uploadMs: cut lines, fills and the longest-
    /// first wireframe first (what the layer's parts draw), the wireframe in its own order last.
    void uploadMore();

    std::shared_ptr<const SceneBuild> structure_;
    std::shared_ptr<const StructureView> view_;
    std::unique_ptr<gl::BatchRenderer> renderer_;
    std::unique_ptr<gl::GpuBatch> cuts_, fills_, wires_, wiresLongestFirst_;
    OverlayGeometry geometry_;
    std::shared_ptr<const ImageCosts> costs_;
    // What the batches were built for.
    OverlayOptions builtOptions_;
    std::shared_ptr<const ImageCosts> builtCosts_;  ///< the counts used (null: none)
    Camera builtCamera_;
    int builtWidth_ = 0, builtHeight_ = 0;
    /// The structure's description they show (null: none built yet).
    const StructureView* builtView_ = nullptr;
    uint64_t rebuilds_ = 0;
    double lastBuildMs_ = 0.0;
    // The layers' texture and what it was drawn for.
    unsigned layerFbo_ = 0, layerTex_ = 0;
    int layerWidth_ = 0, layerHeight_ = 0;
    uint64_t layerVersion_ = 0, layerRebuild_ = ~uint64_t(0);
    double lastLayerMs_ = 0.0;
    bool layerPartial_ = false;
    bool layerMoving_ = false;       ///< the partial texture is a moving camera's cap
    size_t layerDrawn_ = 0;          ///< layerDrawn()
    bool layerDeferred_ = false;     ///< the last layerTexture() drew nothing for the budget
    FrameBudget* budget_ = nullptr;  ///< setFrameBudget()
    double budgetReserveMs_ = 0.0;
    unsigned long uploadFrame_ = 0;  ///< the budget's frame the batches were last copied in
    /// Learned costs (the budget's clock): a byte of the batches' copy, a line of a moving
    /// camera's layer and of a layer at rest (the longest lines, drawn while moving, cost more
    /// each). To begin with: 4 ms per 2 MiB, 7 ms per 1,000 moving lines, 5 ms per 500 lines at
    /// rest (balls4's slabs, 2026-12-06).
    StepCost uploadCost_{4.0 / double(size_t(2) << 20)};
    StepCost movingLineCost_{7.0 / 1000.0};
    StepCost restLineCost_{5.0 / 500.0};
    /// A texel of the layer's texture made at a new size (llvmpipe zeroes its storage): 10 ms
    /// at 1280x720 to begin with (balls4's first structure, 2026-12-07).
    StepCost textureCost_{10.0 / (1280.0 * 720.0)};
    /// The frames in a row the batches' copy, the texture of a new size and the layer's first
    /// part at rest waited for the budget: each starts whatever the budget after
    /// kPatienceFrames (never starved).
    Patience uploadPatience_{"the layer's batches copied to GL"};
    Patience texturePatience_{"the layer's texture of a new size"};
    Patience partPatience_{"the layer's first part at rest"};
    Camera layerCamera_;
    OverlayLook layerLook_;
    std::optional<Selection> selection_;
    int64_t evalRegion_ = -1;
    const CsgTree* evalPool_ = nullptr;  ///< the tree's pool (compared, never read)
    std::vector<NodeSpans> evalNodes_;
    uint32_t pendingSelect_ = 0;
    bool hasPendingSelect_ = false;
    // buildInBackground(): the build under way, what it reads and when it began.
    bool background_ = false;
    std::function<void()> wake_;
    BuildInputs jobInputs_;
    std::chrono::steady_clock::time_point jobStart_;
    BackgroundJob<OverlayGeometry> job_;  ///< last: its worker joined before the rest is destroyed
};

/// The names --show accepts (DESIGN.md section 6), and which of them the overlays draw.
/// Parse a --show list into `options`; returns the items the overlays do not draw (an empty
/// list when all were taken) and throws std::invalid_argument naming an unknown item.
std::vector<std::string> applyShowList(const std::string& list, OverlayOptions& options);
/// Why a --show list does not fit `scheme`: "--show leaves: the irregular scheme has no leaves
/// (the regular scheme's layer)" for the first item that names another scheme's layer (bsp,
/// zones, slabs: irregular; leaves, grid: regular); "" when every item fits.
std::string showListMismatch(const std::string& list, SchemeKind scheme);

}  // namespace lancer::viewer::overlay
