// Draws the traced image (or a heat map of its counters) into the current GL context, given
// the framebuffer size: no window involved, so the OSMesa test drives exactly this code.
#pragma once

#include <memory>
#include <vector>

#include "app/viewer/colormap.h"
#include "app/viewer/memory/fresh_memory.h"
#include "app/viewer/timing/frame_budget.h"
#include "engine/render/image.h"

namespace lancer::viewer {

namespace gl {
class Program;
}

/// A rectangle of framebuffer pixels, [x0, x1) x [y0, y1), row 0 at the top (as ImGui has it).
struct PixelRect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// The parts of a width x height framebuffer that none of `covered` overlaps, as rectangles
/// (bands of rows, each cut into the runs between covering rectangles).
std::vector<PixelRect> uncovered(int width, int height, const std::vector<PixelRect>& covered);

/// Zeroed bytes whose pages are mapped only when first written: a buffer of a new image size
/// costs nothing until its rows are written, and then per row, in the parts the rows come in
/// (writing a new 1280x720 RGBA8 buffer whole took 9-11 ms of page faults in one frame on the
/// loaded 2-core machine, 2026-12-07).
class ZeroedBytes {
  public:
    /// `n` zero bytes (the old ones dropped), unless it holds `n` already (kept as they are).
    void resize(size_t n);
    /// `n` zero bytes, whatever it held.
    void assignZeroed(size_t n);
    /// Holds nothing.
    void clear() { data_.reset(); }
    /// The bytes (null when empty).
    uint8_t* data() const { return data_.get(); }
    /// How many bytes it holds.
    size_t size() const { return data_ ? data_.get_deleter().size : 0; }
    /// Holds nothing.
    bool empty() const { return size() == 0; }

  private:
    /// Unmaps the mapping, whose length it keeps.
    struct Unmap {
        size_t size;  ///< the mapping's length (no initialiser: unique_ptr value-initialises it)
        void operator()(uint8_t* p) const;
    };
    std::unique_ptr<uint8_t, Unmap> data_;
};

class ImageView {
  public:
    /// Needs a current OpenGL 3.3 core context. Throws std::runtime_error if a shader fails.
    ImageView();
    ~ImageView();
    ImageView(const ImageView&) = delete;
    ImageView& operator=(const ImageView&) = delete;

    /// Upload rows [rowBegin, rowEnd) (-1: to the last) of the colour and of the counter `mode`
    /// shows. The other rows keep what earlier uploads put there (nothing, after a change of
    /// size: upload every row of a new size before it is drawn unheld), so after a change of
    /// mode upload the whole image.
    /// `heat` (optional) replaces the counter: the values of those rows (the whole image's when
    /// its size differs), e.g. an A/B's difference; it must hold one value per pixel of them.
    void upload(const Image& img, ViewMode mode, int rowBegin = 0, int rowEnd = -1,
                const std::vector<float>* heat = nullptr);
    /// Draw the uploaded image into viewport() of a fbWidth x fbHeight framebuffer
    /// (framebuffer 0), scaled if its size differs; heat maps divide the counter by `scale`.
    /// Nothing is drawn before the first upload. The shader runs once per upload, mode or scale,
    /// into a texture; each frame then only copies that texture (a blit), which software GL does
    /// far faster than shading. Pixels inside `covered` (framebuffer pixels: opaque menus or popups
    /// drawn over the image next) are left as they are: under software GL the copy costs 7 ns a
    /// pixel. `logScale`: heat maps show heatValue(count, scale, true). `diverging`: the heat
    /// values are signed differences, drawn on the diverging map (divergingColor(diffValue(d,
    /// scale, logScale)); kNoDiff as grey stripes).
    void draw(int fbWidth, int fbHeight, ViewMode mode, float scale,
              const std::vector<PixelRect>& covered = {}, bool logScale = false,
              bool diverging = false) const;
    /// Where draw() puts the image: a rectangle of the framebuffer (row 0 at the top), the
    /// image viewport the panels leave; empty (the default): the whole framebuffer.
    void setViewport(const PixelRect& r) { viewport_ = r; }
    /// The rectangle draw() fills in a fbWidth x fbHeight framebuffer.
    PixelRect viewport(int fbWidth, int fbHeight) const;
    /// Composite a layer over the image when it is shaded: `texture` an RGBA8 texture of
    /// premultiplied colour drawn like the framebuffer (row 0 at the bottom), any size; 0: none.
    /// A layer that does not change costs nothing per frame (the draw stays one copy). The
    /// colour image is composited on the CPU from the layer's pixels, read back here once per
    /// version: llvmpipe shaded a 1280x720 image in 37-41 ms of the UI thread, each pass that
    /// arrived with an overlay shown. A new `version` of the same texture at the image's size
    /// composites again only the texels that differ from the layer the picture was made with
    /// (a part of a layer drawn over several frames changes few; each part composited the
    /// whole image before, 8-10 ms at 1280x720); another texture, or a heat map, shades the
    /// whole image again.
    void setOverlay(unsigned texture, uint64_t version);
    /// As setOverlay(), within a frame's budget: a new version is read back only when the
    /// read-back's learned cost fits in `budget` less `reserveMs` (or after kPatienceFrames
    /// frames of waiting, whatever the budget); until then the view keeps the layer it holds
    /// and the caller asks again with the next frame's version. A read-back is where llvmpipe
    /// finishes the layer's drawing: unbudgeted, it took 14-22 ms of frames already full
    /// (balls4 at 1280x720, a new layer texture's first and the irregular zones' filled
    /// triangles, 2026-12-07). A read-back that would need fresh memory first waits for its
    /// buffer, made on a worker (its page faults were 10-12 ms of a 1280x720 read-back).
    /// Returns whether the view holds `texture` at `version` now.
    bool setOverlay(unsigned texture, uint64_t version, FrameBudget& budget, double reserveMs);
    /// The learned cost of reading back a `width` x `height` layer, in ms: into fresh memory
    /// (no buffer of that size kept or prepared) it costs more than into a buffer kept.
    double readEstimateMs(int width, int height) const;
    /// Whether a read-back of a `width` x `height` layer needs fresh memory: the buffer kept is
    /// smaller and none of that size is prepared (upload() prepares one of the image's size).
    bool readNeedsFreshMemory(int width, int height) const;
    /// While held, draw() shows what it showed before and shades nothing: uploads go on, and
    /// the rows they changed are shaded once the hold ends (a new view's image coming in parts
    /// is never shown half). A hold keeps a picture of another size (drawn scaled), and before
    /// the first picture draws nothing.
    /// A colour view released from a hold with rows still to composite stays off the screen
    /// (draw() shows the picture before it) while draw() composites them in parts within the
    /// frame's budget (setFrameBudget()), at least one part a draw, and is shown once all its
    /// rows are in: released whole it took 36-44 ms of the image step in one frame (its first
    /// picture, balls4 at 1280x720, 2026-12-07).
    /// Without a frame budget a released view is shown at once.
    void setHold(bool hold) {
        hold_ = hold;
        offScreen_ = hold || (offScreen_ && budget_ != nullptr);
    }
    /// While held, composite the colour image's rows uploaded since the picture was shaded in
    /// parts of 48 rows, each only when its estimated cost (the time per row measured so far)
    /// fits in the frame's budget less the reserve setFrameBudget() gave (the one a pass's
    /// rows keep: given apart, it once left out the inspector's and the panels' copies, and a
    /// still frame on balls4 took 34.9 ms, 2026-12-07); they are copied to the texture when
    /// the view is shown (setHold()). A new view released whole took 16-25 ms of the image
    /// step in one frame (balls4 at 1280x720, 2026-12-06). Returns the rows composited; none
    /// without a budget, or unless colour rows come over a colour picture of the image's size,
    /// or a first picture, or one of a new size (its buffers then come page by page with its
    /// rows: ZeroedBytes).
    int composeHeld();
    /// Share a frame's budget from now on (null: none): draw() composites the rows of the
    /// view on screen uploaded since the last draw (a finer pass's part) in parts of 48 rows,
    /// each only when its learned cost fits in `budget` less `reserveMs`, at least one part a
    /// draw; the rest stay pending for the next draws. A view released from a hold is
    /// composited off the screen in such parts and shown whole (setHold()); a whole shade is
    /// composited at once (two views never share the screen). A
    /// pass's part with the image step took 10-12 ms of a frame beside its poll and upload
    /// (balls4's slabs with the inspector, 2026-12-07). The budget must outlive the view or
    /// be unset.
    void setFrameBudget(FrameBudget* budget, double reserveMs) {
        budget_ = budget;
        budgetReserveMs_ = reserveMs;
    }
    /// Image rows uploaded and not yet composited into the picture (draw() left them for the
    /// budget, or a hold), and those of a released view composited off the screen and not yet
    /// shown.
    int pendingRows() const {
        return (dirty_.empty() ? 0 : dirty_.end - dirty_.begin) +
               (offScreen_ && !hold_ && !precomposed_.empty()
                    ? precomposed_.end - precomposed_.begin
                    : 0);
    }
    /// draw() draws a picture: something was uploaded, and it is not held before a first one.
    bool showsPicture() const { return width_ > 0 && (shadedWidth_ > 0 || !(hold_ || offScreen_)); }
    /// What the last draw() that shaded composited: image rows composited whole, texels
    /// composited again for a new layer's changes (in each changed row, the span from its
    /// first to its last changed texel), the texels those uploaded (for each band of 16
    /// rows, the rectangle around its spans), and the rows a view composited off the screen
    /// needed copied to be shown.
    struct ShadeCount {
        int rows = 0;               ///< image rows composited whole
        size_t texels = 0;          ///< texels composited again for a new layer's changes
        size_t uploadedTexels = 0;  ///< texels those uploaded
        /// Rows copied to show a view composited off the screen (0 when all of them were in
        /// the back texture swapped in).
        int shownRows = 0;
    };
    /// What the last draw() that shaded composited (tests: a layer part costs what it changed).
    const ShadeCount& lastShade() const { return lastShade_; }
    /// The UI thread's CPU time the next draw() in `mode` would take to shade what is pending
    /// (rows uploaded, the whole image after a change), in ms: the rows times the time per row
    /// measured in the colour image's earlier composites; 0 while held.
    double shadeEstimateMs(ViewMode mode) const;
    /// The counters' texture has storage: only once a heat map is uploaded (its allocation took
    /// 10 ms of a colour image's first upload, balls4 at 1280x720, 2026-12-07).
    bool countersAllocated() const { return heatWidth_ > 0; }
    /// Size of the uploaded image (0 x 0 before the first upload).
    int width() const { return width_; }
    int height() const { return height_; }

  private:
    /// Shade image rows [rowBegin, rowEnd) into the FBO (the rest keeps its pixels): compose()
    /// for the colour image, shadeHeat() for the heat maps.
    void shade(ViewMode mode, float scale, bool logScale, bool diverging, int rowBegin,
               int rowEnd) const;
    /// The colour image's rows [rowBegin, rowEnd) with the layer over them, into the FBO's
    /// texture.
    void compose(int rowBegin, int rowEnd, bool upload = true) const;
    /// Copy the composited rows [rowBegin, rowEnd) (image rows) to the FBO's texture, or to
    /// `texture`.
    void uploadComposed(int rowBegin, int rowEnd) const {
        uploadComposed(rowBegin, rowEnd, shadedTex_);
    }
    void uploadComposed(int rowBegin, int rowEnd, unsigned texture) const;
    /// The picture on screen is a colour picture of the image's size.
    bool frontAtSize() const;
    /// A view composited off the screen is shown by swapping in the back texture: every row
    /// composited is in it, it is of the image's size, and the rows around them are on screen
    /// at that size (or there are none).
    bool swapsIn() const;
    /// The back texture is of the image's size, made now if it is not and its learned cost
    /// fits in `budget` less `reserveMs`: rows composited off the screen are copied into it as
    /// they come (composeParts()).
    bool backReady(FrameBudget& budget, double reserveMs) const;
    /// Rows a view composited off the screen needs copied when it is shown: the rows around
    /// those already in the back texture (it is then swapped in), or else the composited rows
    /// themselves.
    int showRows() const;
    /// The texels where the layer differs from the one the picture was composited with, into
    /// the FBO's texture: the other texels are already right. Image rows [skipBegin, skipEnd)
    /// are left out (composited whole by compose()).
    void composeLayerChanges(int skipBegin, int skipEnd) const;
    /// The layer's pixels are one per image pixel (the viewer draws it at the image's size).
    bool layerAtImageSize() const;
    /// One past the last pending row draw() composites now: parts of 48 rows while their
    /// learned cost fits in the frame's budget (setFrameBudget()), the first in any case.
    int budgetedRowsEnd() const;
    /// Rows uploaded since the picture may be composited off the screen into composed_, to be
    /// copied when the view is shown: colour uploads over a colour picture of the image's
    /// size, or a first picture, or one of a new size.
    bool composesOffScreen() const;
    /// Composite pending rows into composed_ (not the texture) in parts of 48 while their
    /// estimated cost fits in `budget` less `reserveMs`, the first part in any case if
    /// `atLeastOne`; returns the rows composited.
    int composeParts(FrameBudget& budget, double reserveMs, bool atLeastOne) const;
    /// A view released from a hold: its pending rows composited off the screen in parts
    /// (composeParts(), at least one a draw); offScreen_ ends once none is pending, or at once
    /// when they cannot be (a heat map, no budget).
    void finishOffScreen(ViewMode mode) const;
    /// What showing the view composited off the screen costs, in ms: its rows copied to the
    /// texture, and the texture made at a new size (learned: showRowCost_, textureCost_).
    double showEstimateMs() const;
    /// The heat map's rows [rowBegin, rowEnd) through the colour-map shader.
    void shadeHeat(float scale, bool logScale, bool diverging, int rowBegin, int rowEnd) const;

    std::unique_ptr<gl::Program> program_;
    /// shadedTex_ is the picture on screen (the FBO's); backTex_, of the same size, takes the
    /// rows of a view composited off the screen as they come, and is swapped in to show it:
    /// copying a released view's 720 rows in the frame that shows it took 13-19 ms of the
    /// image step at 1280x720, over the budget (balls4, 2026-12-07).
    mutable unsigned vao_ = 0, heatTex_ = 0, shadedTex_ = 0, fbo_ = 0, backTex_ = 0;
    ZeroedBytes colorRgba_;             ///< the colour image as 8-bit RGBA, row 0 on top
    std::vector<uint8_t> overlayRgba_;  ///< the layer's pixels (row 0 at the bottom); empty: none
    int overlayWidth_ = 0, overlayHeight_ = 0;
    /// The composited colour image (FBO rows, row 0 at the bottom), as in the FBO's texture.
    mutable ZeroedBytes composed_;
    /// The layer's pixels composed_ was composited with (empty: a layer of another size or
    /// none; then a new layer composites the whole image).
    mutable ZeroedBytes composedLayer_;
    mutable bool layerChanged_ = false;  ///< a new layer since the last shade()
    mutable ShadeCount lastShade_;
    /// The UI thread's CPU per row composited and uploaded (a running mean of
    /// the composites of 64 rows or more); 8.6 ms for a 720-row image to begin with (the
    /// composite of balls4 at 1280x720, 2026-12-06).
    mutable StepCost rowCost_{8.6 / 720.0};
    mutable bool shadedValid_ = false;
    mutable ViewMode shadedMode_ = ViewMode::Color;
    mutable float shadedScale_ = 0.0f;
    mutable bool shadedLog_ = false;
    mutable bool shadedDiverging_ = false;
    /// Image rows uploaded since the FBO was last shaded: only they are shaded again (a band of
    /// a progressive pass is a few rows; shading all of them per band cost llvmpipe a full-image
    /// pass each time).
    mutable RowRange dirty_;
    /// Image rows composited while held (composeHeld()) and not yet copied to the texture.
    mutable RowRange precomposed_;
    /// Every row of precomposed_ is in backTex_ too (each was copied there when composited).
    mutable bool backHoldsPrecomposed_ = false;
    mutable int backWidth_ = 0, backHeight_ = 0;  ///< backTex_'s size (0: no storage yet)
    int width_ = 0, height_ = 0;
    mutable int shadedWidth_ = 0, shadedHeight_ = 0;  ///< the size the FBO was last shaded at
    bool hold_ = false;
    /// A view held, or released with rows still to composite off the screen (setHold()).
    mutable bool offScreen_ = false;
    /// The image's size changed (or its first upload) since it was last shaded: composited
    /// whole unless every row was composited off the screen.
    mutable bool newSize_ = false;
    ViewMode uploadMode_ = ViewMode::Color;  ///< the mode of the last upload
    int heatWidth_ = 0, heatHeight_ = 0;     ///< the counters' texture's size (0: none)
    /// The UI thread's CPU per row copied to the texture when a view composited off the
    /// screen is shown (parts of 64 rows or more).
    mutable StepCost showRowCost_{4.0 / 720.0};
    /// The UI thread's CPU per texel to make the texture at a new size (9.6 ms at 1280x720 on
    /// the loaded 2-core machine, 2026-12-07).
    mutable StepCost textureCost_{9.6 / (1280.0 * 720.0)};
    /// The draws in a row a released view, all its rows composited, waited to be shown for
    /// the budget (finishOffScreen()): shown whatever the budget after kPatienceFrames.
    mutable Patience showPatience_{"the image's showing"};
    /// The UI thread's CPU per texel of a layer's read-back (setOverlay()), learned apart for a
    /// read into fresh memory and into a buffer kept: the first into a new 1280x720 buffer took
    /// 10-14 ms, nearly all of it the buffer's page faults, a later one 0.3-2 ms while the
    /// camera turns (balls4, 2026-12-07); one mean of both kept the later read-backs waiting
    /// their patience for 20-30 frames after each first one.
    StepCost freshReadCost_{10.6 / (1280.0 * 720.0)}, readCost_{1.0 / (1280.0 * 720.0)};
    Patience readPatience_{"the layer's read-back"};
    /// The read-back's buffer of the image's size, made on a worker when the image's size
    /// changes, so that the first read-back at a size (a new structure's first layer) writes
    /// into mapped pages.
    PreparedBytes readBuffer_;
    /// The last draw() was held: the next unheld one composites all pending rows (the view
    /// released must show whole).
    mutable bool drawnHeld_ = false;
    FrameBudget* budget_ = nullptr;  ///< setFrameBudget()
    double budgetReserveMs_ = 0.0;
    PixelRect viewport_;
    unsigned overlayTex_ = 0;
    uint64_t overlayVersion_ = 0;
    int locOverlay_ = -1, locHasOverlay_ = -1;
    int locMode_ = -1, locScale_ = -1, locStops_ = -1, locStopCount_ = -1, locHeat_ = -1,
        locDivStops_ = -1;
};

/// Read the current framebuffer's pixels as RGBA8, row 0 on top (as PNG files want).
std::vector<uint8_t> readFramebuffer(int width, int height);

}  // namespace lancer::viewer
