#include "app/viewer/image_view.h"

#include <sys/mman.h>

#include <algorithm>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "app/viewer/gl.h"
#include "app/viewer/gl/program.h"
#include "app/viewer/timing/frame_budget.h"
#include "app/viewer/timing/frame_times.h"

namespace lancer::viewer {

namespace {

/// An RGBA8 texel that adds nothing over the image (premultiplied: alpha and colour zero).
bool transparent(const uint8_t* p) {
    uint32_t v;
    std::memcpy(&v, p, 4);
    return v == 0;
}

void setupTexture(GLuint tex) {
    glBindTexture(GL_TEXTURE_2D, tex);
    // Nearest: the texture has one texel per framebuffer pixel, and heat values must not blend.
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

}  // namespace

void ZeroedBytes::Unmap::operator()(uint8_t* p) const { munmap(p, size); }

void ZeroedBytes::resize(size_t n) {
    if (n != size()) assignZeroed(n);
}

void ZeroedBytes::assignZeroed(size_t n) {
    clear();
    if (n == 0) return;
    // Anonymous pages are zero and mapped only when first written (malloc may reuse pages and
    // calloc then clears them all at once).
    void* p = mmap(nullptr, n, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    data_ = std::unique_ptr<uint8_t, Unmap>(static_cast<uint8_t*>(p), Unmap{n});
}

ImageView::ImageView() {
    program_ = std::make_unique<gl::Program>("image.vert", "image.frag");
    locMode_ = program_->uniform("mode");
    locScale_ = program_->uniform("scale");
    locStops_ = program_->uniform("stops");
    locStopCount_ = program_->uniform("stopCount");
    locDivStops_ = program_->uniform("divStops");
    locHeat_ = program_->uniform("heatTex");
    locOverlay_ = program_->uniform("overlayTex");
    locHasOverlay_ = program_->uniform("hasOverlay");
    glGenVertexArrays(1, &vao_);  // core profile draws need a bound VAO, even an empty one
    GLuint tex[3];
    glGenTextures(3, tex);
    heatTex_ = tex[0];
    shadedTex_ = tex[1];
    backTex_ = tex[2];
    for (GLuint t : tex) setupTexture(t);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenFramebuffers(1, &fbo_);
}

ImageView::~ImageView() {
    GLuint tex[3] = {heatTex_, shadedTex_, backTex_};
    glDeleteTextures(3, tex);
    glDeleteFramebuffers(1, &fbo_);
    glDeleteVertexArrays(1, &vao_);
}

void ImageView::upload(const Image& img, ViewMode mode, int rowBegin, int rowEnd,
                       const std::vector<float>* heat) {
    if (img.width <= 0 || img.height <= 0) return;
    const bool resized = img.width != width_ || img.height != height_;
    if (rowEnd < 0 || rowEnd > img.height) rowEnd = img.height;
    rowBegin = std::clamp(rowBegin, 0, rowEnd);
    const int rows = rowEnd - rowBegin;
    width_ = img.width;
    height_ = img.height;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    if (resized) {  // the shaded texture is made when it is shaded, the counters' below
        colorRgba_.assignZeroed(size_t(width_) * size_t(height_) * 4);
        // The layer's read-back buffer of the image's size, made ahead (setOverlay()).
        if (overlayRgba_.capacity() < colorRgba_.size()) readBuffer_.prepare(colorRgba_.size());
        newSize_ = true;
        dirty_.clear();
        precomposed_.clear();
        // Held or not, a picture of a new size (a first one) comes off the screen in parts
        // within the budget: uploaded whole without a hold, it was composited and its texture
        // made in one frame (41-55 ms of the image step, balls4's first irregular picture after
        // a turn, 2026-12-07).
        offScreen_ = offScreen_ || budget_ != nullptr;
    }
    uploadMode_ = mode;
    if (mode != ViewMode::Color && (heatWidth_ != width_ || heatHeight_ != height_)) {
        // Only for a heat map: a colour image never reads it.
        glBindTexture(GL_TEXTURE_2D, heatTex_);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, width_, height_, 0, GL_RED, GL_FLOAT, nullptr);
        heatWidth_ = width_;
        heatHeight_ = height_;
    }
    if (rows > 0) {
        // 8 bits per channel, quantised as the PNG writer does: the screen shows what `render`
        // saves. Kept in every mode, so a change to the colour image needs no upload.
        img.rgba8Into(colorRgba_.data() + size_t(rowBegin) * size_t(width_) * 4, rowBegin, rowEnd,
                      false);
        if (mode != ViewMode::Color) {
            // Texture row y is image row y; the shader flips.
            std::vector<float> own;
            if (!heat) own = heatChannel(img, mode, rowBegin, rowEnd);
            const std::vector<float>& values = heat ? *heat : own;
            if (values.size() != size_t(width_) * size_t(rows))
                throw std::invalid_argument("ImageView::upload: " + std::to_string(values.size()) +
                                            " heat values for " + std::to_string(rows) +
                                            " rows of " + std::to_string(width_));
            glBindTexture(GL_TEXTURE_2D, heatTex_);
            glTexSubImage2D(GL_TEXTURE_2D, 0, 0, rowBegin, width_, rows, GL_RED, GL_FLOAT,
                            values.data());
        }
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    dirty_.add(rowBegin, rowEnd);
}

namespace {

/// A 2D texture's level 0 size (its width, its height).
std::pair<int, int> textureSize(unsigned texture) {
    GLint w = 0, h = 0;
    glBindTexture(GL_TEXTURE_2D, texture);
    glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_WIDTH, &w);
    glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, GL_TEXTURE_HEIGHT, &h);
    glBindTexture(GL_TEXTURE_2D, 0);
    return {int(w), int(h)};
}

}  // namespace

void ImageView::setOverlay(unsigned texture, uint64_t version) {
    if (texture == overlayTex_ && (texture == 0 || version == overlayVersion_)) return;
    // A new version of the same texture: the colour image composites again only the texels
    // that changed (shade()); anything else shades the whole image.
    if (texture == 0 || texture != overlayTex_) shadedValid_ = false;
    layerChanged_ = true;
    overlayTex_ = texture;
    overlayVersion_ = version;
    // The colour image is composited on the CPU (compose()): the layer's pixels are read back
    // once per version, not once per pass.
    overlayRgba_.clear();
    overlayWidth_ = overlayHeight_ = 0;
    if (texture == 0) return;
    const double start = threadCpuMs();
    std::tie(overlayWidth_, overlayHeight_) = textureSize(texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    const size_t bytes =
        size_t(std::max(overlayWidth_, 0)) * size_t(std::max(overlayHeight_, 0)) * 4;
    const bool fresh = readNeedsFreshMemory(overlayWidth_, overlayHeight_);
    if (overlayRgba_.capacity() < bytes)
        if (std::vector<uint8_t> prepared = readBuffer_.take(bytes); !prepared.empty())
            overlayRgba_ = std::move(prepared);
    overlayRgba_.resize(bytes);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    if (!overlayRgba_.empty())
        glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, overlayRgba_.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    (fresh ? freshReadCost_ : readCost_).record(double(bytes / 4), threadCpuMs() - start);
}

bool ImageView::readNeedsFreshMemory(int width, int height) const {
    const size_t bytes = size_t(std::max(width, 0)) * size_t(std::max(height, 0)) * 4;
    return overlayRgba_.capacity() < bytes && !readBuffer_.ready(bytes);
}

double ImageView::readEstimateMs(int width, int height) const {
    return (readNeedsFreshMemory(width, height) ? freshReadCost_ : readCost_)
        .estimateMs(double(width) * double(height));
}

bool ImageView::setOverlay(unsigned texture, uint64_t version, FrameBudget& budget,
                           double reserveMs) {
    if (texture == overlayTex_ && (texture == 0 || version == overlayVersion_)) return true;
    if (texture != 0) {
        const auto [w, h] = textureSize(texture);
        if (readNeedsFreshMemory(w, h)) {
            // Its buffer is made on a worker first: written in the frame, its fresh pages
            // took 10-12 ms of the 1280x720 read-back (2026-12-07). The layer held stays.
            const size_t bytes = size_t(std::max(w, 0)) * size_t(std::max(h, 0)) * 4;
            readBuffer_.prepare(bytes);
            if (readBuffer_.making(bytes)) return false;
        }
        if (!budget.fits(readEstimateMs(w, h), reserveMs, readPatience_)) return false;
    }
    setOverlay(texture, version);
    return true;
}

namespace {

/// One composited pixel: the image's colour `c` under the premultiplied layer texel `p`
/// (out = image (1 - a) + layer, rounded as the shader's 8-bit target rounds), opaque.
void blendTexel(const uint8_t* c, const uint8_t* p, uint8_t* o) {
    const unsigned keep = 255u - p[3];
    for (size_t k = 0; k < 3; ++k)
        o[k] = uint8_t(std::min((unsigned(c[k]) * keep + 127u) / 255u + p[k], 255u));
    o[3] = 255;
}

/// Texels [x0, x1) of an image row `c` with the layer's texels `l` (texel x at l + column[x])
/// over them, into `o`. Runs of transparent layer texels (most of a layer of lines:
/// premultiplied, all zero) are the image's bytes, copied as a run.
void composeSpan(const uint8_t* c, const uint8_t* l, const size_t* column, uint8_t* o, size_t x0,
                 size_t x1) {
    for (size_t x = x0; x < x1;) {
        size_t run = x;
        while (run < x1 && transparent(l + column[run])) ++run;
        if (run > x) {
            std::memcpy(o + 4 * x, c + 4 * x, 4 * (run - x));
            x = run;
            continue;
        }
        blendTexel(c + 4 * x, l + column[x], o + 4 * x);
        ++x;
    }
}

/// The first texel at or after `x` where rows `a` and `b` of `w` texels differ (w: none),
/// blocks of 16 equal texels skipped at once.
size_t firstDiff(const uint8_t* a, const uint8_t* b, size_t x, size_t w) {
    while (x + 16 <= w && std::memcmp(a + 4 * x, b + 4 * x, 64) == 0) x += 16;
    while (x < w && std::memcmp(a + 4 * x, b + 4 * x, 4) == 0) ++x;
    return x;
}

/// One past the last texel before `x` where the rows differ (0: none), from the right.
size_t lastDiff(const uint8_t* a, const uint8_t* b, size_t x) {
    while (x >= 16 && std::memcmp(a + 4 * (x - 16), b + 4 * (x - 16), 64) == 0) x -= 16;
    while (x > 0 && std::memcmp(a + 4 * (x - 1), b + 4 * (x - 1), 4) == 0) --x;
    return x;
}

}  // namespace

bool ImageView::layerAtImageSize() const {
    return !overlayRgba_.empty() && overlayWidth_ == width_ && overlayHeight_ == height_;
}

void ImageView::compose(int rowBegin, int rowEnd, bool upload) const {
    // Image row r is FBO row height - 1 - r: rows [b, e) are FBO rows [h - e, h - b), written
    // bottom row first. The layer is premultiplied (blendTexel); a layer of another size is
    // sampled at the nearest texel, as the heat maps' shader samples it.
    const int rows = rowEnd - rowBegin;
    if (rows <= 0) return;
    const size_t w = size_t(width_);
    const bool layer = !overlayRgba_.empty();
    if (composed_.size() != w * size_t(height_) * 4) {
        // A new size: the layer each row is composited with is kept from its first row on, so
        // that a picture composited in parts takes a new layer's changes as one composited
        // whole does.
        composed_.assignZeroed(w * size_t(height_) * 4);
        if (layerAtImageSize())
            composedLayer_.assignZeroed(overlayRgba_.size());
        else
            composedLayer_.clear();
    }
    std::vector<size_t> column;
    if (layer)
        for (size_t x = 0; x < w; ++x)
            column.push_back(4 * ((2 * x + 1) * size_t(overlayWidth_) / (2 * w)));
    for (int r = rowBegin; r < rowEnd; ++r) {
        const uint8_t* c = colorRgba_.data() + size_t(r) * w * 4;
        uint8_t* o = composed_.data() + size_t(height_ - 1 - r) * w * 4;
        if (!layer) {
            std::copy_n(c, w * 4, o);
            continue;
        }
        const int fboRow = height_ - 1 - r;
        const size_t ly = size_t(2 * fboRow + 1) * size_t(overlayHeight_) / size_t(2 * height_);
        composeSpan(c, overlayRgba_.data() + ly * size_t(overlayWidth_) * 4, column.data(), o, 0,
                    w);
    }
    // The layer these rows were composited with, for the next version's changed texels.
    if (layerAtImageSize() && (composedLayer_.size() == overlayRgba_.size() || rows == height_)) {
        composedLayer_.resize(overlayRgba_.size());
        const size_t from = size_t(height_ - rowEnd) * w * 4;
        std::copy_n(overlayRgba_.data() + from, size_t(rows) * w * 4, composedLayer_.data() + from);
    } else {
        composedLayer_.clear();
    }
    if (!upload) return;
    uploadComposed(rowBegin, rowEnd);
    lastShade_.rows += rows;
}

void ImageView::uploadComposed(int rowBegin, int rowEnd, unsigned texture) const {
    if (rowEnd <= rowBegin) return;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glBindTexture(GL_TEXTURE_2D, texture);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, height_ - rowEnd, width_, rowEnd - rowBegin, GL_RGBA,
                    GL_UNSIGNED_BYTE,
                    composed_.data() + size_t(height_ - rowEnd) * size_t(width_) * 4);
    glBindTexture(GL_TEXTURE_2D, 0);
}

bool ImageView::composesOffScreen() const {
    // Anything else is shaded whole when the view is shown.
    if (uploadMode_ != ViewMode::Color) return false;
    if (newSize_) return true;
    return shadedValid_ && shadedMode_ == ViewMode::Color && shadedWidth_ == width_ &&
           shadedHeight_ == height_;
}

int ImageView::composeHeld() {
    if (!budget_ || !hold_ || !composesOffScreen()) return 0;
    return composeParts(*budget_, budgetReserveMs_, false);
}

int ImageView::composeParts(FrameBudget& budget, double reserveMs, bool atLeastOne) const {
    constexpr int kRows = 48;
    int done = 0;
    while (!dirty_.empty()) {
        const int end = std::min(dirty_.end, dirty_.begin + kRows);
        if ((!atLeastOne || done > 0) &&
            !budget.fits(rowCost_.estimateMs(end - dirty_.begin), reserveMs))
            break;
        compose(dirty_.begin, end, false);
        if (precomposed_.empty()) backHoldsPrecomposed_ = backReady(budget, reserveMs);
        if (backHoldsPrecomposed_) uploadComposed(dirty_.begin, end, backTex_);
        precomposed_.add(dirty_.begin, end);
        done += end - dirty_.begin;
        dirty_.begin = end;
    }
    if (dirty_.empty()) dirty_.clear();
    return done;
}

void ImageView::finishOffScreen(ViewMode mode) const {
    if (budget_ && mode == ViewMode::Color && composesOffScreen()) {
        const bool composing = !dirty_.empty();
        composeParts(*budget_, budgetReserveMs_, true);
        if (!dirty_.empty()) return;  // the next draws go on; the picture before meanwhile
        // Showing it copies its rows (and makes the texture at a new size: 30-40 ms of the
        // image step with the last parts in one frame, balls4 at 1280x720 under load,
        // 2026-12-07): after parts in this draw only if its learned cost fits, else in the
        // next draw whatever the budget, or, while a finer pass's rows keep coming, after
        // kPatienceFrames draws.
        if (composing && !budget_->fits(showEstimateMs(), budgetReserveMs_, showPatience_)) return;
    }
    offScreen_ = false;
}

bool ImageView::frontAtSize() const {
    return shadedValid_ && shadedMode_ == ViewMode::Color && shadedWidth_ == width_ &&
           shadedHeight_ == height_ && !newSize_;
}

bool ImageView::swapsIn() const {
    return !precomposed_.empty() && backHoldsPrecomposed_ && backWidth_ == width_ &&
           backHeight_ == height_ &&
           (frontAtSize() || (precomposed_.begin <= 0 && precomposed_.end >= height_));
}

bool ImageView::backReady(FrameBudget& budget, double reserveMs) const {
    if (backWidth_ == width_ && backHeight_ == height_) return true;
    // Made when its learned cost fits (else this view is shown by copying its rows, and at a
    // new size by making the picture's texture then, as without it).
    const double texels = double(width_) * double(height_);
    if (!budget.fits(textureCost_.estimateMs(texels), reserveMs)) return false;
    const double made = budget.spentMs();
    glBindTexture(GL_TEXTURE_2D, backTex_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width_, height_, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                 nullptr);
    glBindTexture(GL_TEXTURE_2D, 0);
    glFinish();  // timed: the storage is made
    textureCost_.record(texels, budget.spentMs() - made);
    backWidth_ = width_;
    backHeight_ = height_;
    return true;
}

int ImageView::showRows() const {
    if (precomposed_.empty()) return 0;
    const int rows = precomposed_.end - precomposed_.begin;
    return swapsIn() ? height_ - rows : rows;
}

double ImageView::showEstimateMs() const {
    double ms = showRowCost_.estimateMs(showRows());
    if (!swapsIn() && (shadedWidth_ != width_ || shadedHeight_ != height_))
        ms += textureCost_.estimateMs(double(width_) * double(height_));
    return ms;
}

void ImageView::composeLayerChanges(int skipBegin, int skipEnd) const {
    // Only texels where the layer differs from the one composited change the picture: rows of
    // the layer equal to the old ones are skipped whole (memcmp), the others composite again
    // the span from their first to their last changed texel, and each band of kBand rows
    // uploads the rectangle of its spans. Image rows [skipBegin, skipEnd) were composited
    // whole with this layer already.
    constexpr int kBand = 16;
    const size_t w = size_t(width_), rowBytes = w * 4;
    std::vector<size_t> column(w);
    for (size_t x = 0; x < w; ++x) column[x] = 4 * x;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, width_);
    glBindTexture(GL_TEXTURE_2D, shadedTex_);
    for (int band = 0; band < height_; band += kBand) {
        int y0 = height_, y1 = 0;
        size_t x0 = w, x1 = 0;
        for (int fr = band; fr < std::min(height_, band + kBand); ++fr) {
            const int r = height_ - 1 - fr;
            if (r >= skipBegin && r < skipEnd) continue;
            const size_t at = size_t(fr) * rowBytes;
            const uint8_t* nl = overlayRgba_.data() + at;
            uint8_t* ol = composedLayer_.data() + at;
            const size_t a = firstDiff(nl, ol, 0, w);
            if (a == w) continue;
            const size_t b = lastDiff(nl, ol, w);
            composeSpan(colorRgba_.data() + size_t(r) * rowBytes, nl, column.data(),
                        composed_.data() + at, a, b);
            std::memcpy(ol + 4 * a, nl + 4 * a, 4 * (b - a));
            x0 = std::min(x0, a);
            x1 = std::max(x1, b);
            y0 = std::min(y0, fr);
            y1 = std::max(y1, fr + 1);
            lastShade_.texels += b - a;
        }
        if (y0 >= y1) continue;
        glTexSubImage2D(GL_TEXTURE_2D, 0, GLint(x0), y0, GLsizei(x1 - x0), y1 - y0, GL_RGBA,
                        GL_UNSIGNED_BYTE, composed_.data() + size_t(y0) * rowBytes + 4 * x0);
        lastShade_.uploadedTexels += (x1 - x0) * size_t(y1 - y0);
    }
    glBindTexture(GL_TEXTURE_2D, 0);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
}

std::vector<PixelRect> uncovered(int width, int height, const std::vector<PixelRect>& covered) {
    std::vector<int> ys = {0, height};
    for (const PixelRect& r : covered)
        for (int y : {r.y0, r.y1}) ys.push_back(std::clamp(y, 0, height));
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    std::vector<PixelRect> out;
    std::vector<std::pair<int, int>> spans;
    for (size_t b = 0; b + 1 < ys.size(); ++b) {
        const int ya = ys[b], yb = ys[b + 1];
        spans.clear();
        for (const PixelRect& r : covered)
            if (r.y0 <= ya && r.y1 >= yb && r.x0 < r.x1)
                spans.push_back({std::clamp(r.x0, 0, width), std::clamp(r.x1, 0, width)});
        std::sort(spans.begin(), spans.end());
        int x = 0;
        for (const auto& [a, e] : spans) {
            if (a > x) out.push_back({x, ya, a, yb});
            x = std::max(x, e);
        }
        if (x < width) out.push_back({x, ya, width, yb});
    }
    // A run continues the identical run of the band above: one taller copy.
    std::vector<PixelRect> merged;
    for (const PixelRect& r : out) {
        auto same = std::find_if(merged.begin(), merged.end(), [&](const PixelRect& m) {
            return m.x0 == r.x0 && m.x1 == r.x1 && m.y1 == r.y0;
        });
        if (same != merged.end())
            same->y1 = r.y1;
        else
            merged.push_back(r);
    }
    return merged;
}

void ImageView::draw(int fbWidth, int fbHeight, ViewMode mode, float scale,
                     const std::vector<PixelRect>& covered, bool logScale, bool diverging) const {
    if (width_ == 0) return;
    scale = scale > 0.0f ? scale : 1.0f;
    diverging = diverging && mode != ViewMode::Color;
    // A view released from a hold is composited off the screen until all its rows are in.
    if (!hold_ && offScreen_) finishOffScreen(mode);
    // Held (setHold): drawn as shaded before, whatever its size; nothing before a first
    // picture (showsPicture()).
    if (!showsPicture()) return;
    const bool held = hold_ || offScreen_;
    // A new layer composites only its changed texels over a colour image already composited
    // with the layer before it, at the image's size; anything else shades the whole image.
    const bool layerInPlace = mode == ViewMode::Color && layerAtImageSize() &&
                              composedLayer_.size() == overlayRgba_.size();
    // Every row of a colour view composited off the screen, with the layer or one whose
    // changes composite in place: copied as it is, even at a new size.
    const bool offScreenWhole = mode == ViewMode::Color && uploadMode_ == ViewMode::Color &&
                                dirty_.empty() && precomposed_.begin <= 0 &&
                                precomposed_.end >= height_ && (!layerChanged_ || layerInPlace);
    const bool whole =
        newSize_ || !shadedValid_
            ? !offScreenWhole
            : mode != shadedMode_ || (layerChanged_ && !layerInPlace) ||
                  (mode != ViewMode::Color && (scale != shadedScale_ || logScale != shadedLog_ ||
                                               diverging != shadedDiverging_));
    if (!held) lastShade_ = {};
    if (!held && whole) {
        shade(mode, scale, logScale, diverging, 0, height_);
    } else if (!held && (!dirty_.empty() || layerChanged_ || !precomposed_.empty())) {
        // A finer pass of the view on screen already shows in parts: its rows may wait for
        // the next frames. A released view's may not.
        const int end =
            drawnHeld_ || !precomposed_.empty() || mode != ViewMode::Color || dirty_.empty()
                ? dirty_.end
                : budgetedRowsEnd();
        shade(mode, scale, logScale, diverging, dirty_.begin, end);
    }
    drawnHeld_ = held;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glDisable(GL_SCISSOR_TEST);
    const PixelRect d = viewport(fbWidth, fbHeight);
    const int dw = d.x1 - d.x0, dh = d.y1 - d.y0;
    const int sw = shadedWidth_, sh = shadedHeight_;  // a held picture may be of another size
    if (covered.empty() || sw != dw || sh != dh) {
        glBlitFramebuffer(0, 0, sw, sh, d.x0, fbHeight - d.y1, d.x1, fbHeight - d.y0,
                          GL_COLOR_BUFFER_BIT, GL_NEAREST);
    } else {
        // One texel per pixel: each uncovered rectangle is copied as is (GL's rows go up).
        std::vector<PixelRect> inImage;
        for (const PixelRect& c : covered)
            inImage.push_back({c.x0 - d.x0, c.y0 - d.y0, c.x1 - d.x0, c.y1 - d.y0});
        for (const PixelRect& r : uncovered(dw, dh, inImage))
            glBlitFramebuffer(r.x0, dh - r.y1, r.x1, dh - r.y0, d.x0 + r.x0, fbHeight - d.y0 - r.y1,
                              d.x0 + r.x1, fbHeight - d.y0 - r.y0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbWidth, fbHeight);
}

int ImageView::budgetedRowsEnd() const {
    if (!budget_) return dirty_.end;
    // Parts of kRows from the first pending row, the first in any case (never starved).
    constexpr int kRows = 48;
    int end = std::min(dirty_.end, dirty_.begin + kRows);
    while (end < dirty_.end &&
           budget_->fits(rowCost_.estimateMs(std::min(dirty_.end, end + kRows) - dirty_.begin),
                         budgetReserveMs_))
        end = std::min(dirty_.end, end + kRows);
    return end;
}

double ImageView::shadeEstimateMs(ViewMode mode) const {
    if (width_ == 0 || hold_ || mode != ViewMode::Color) return 0.0;
    // A released view still off the screen: a part at least (finishOffScreen()).
    if (offScreen_) return rowCost_.estimateMs(std::min(pendingRows(), 48));
    const bool whole =
        !shadedValid_ || mode != shadedMode_ || shadedWidth_ != width_ || shadedHeight_ != height_;
    const int rows = whole ? height_ : dirty_.end - dirty_.begin;
    return rowCost_.estimateMs(std::max(rows, 0));
}

PixelRect ImageView::viewport(int fbWidth, int fbHeight) const {
    if (viewport_.x1 <= viewport_.x0 || viewport_.y1 <= viewport_.y0)
        return {0, 0, fbWidth, fbHeight};
    return viewport_;
}

void ImageView::shade(ViewMode mode, float scale, bool logScale, bool diverging, int rowBegin,
                      int rowEnd) const {
    // The rows composited off the screen are shown by swapping in the back texture they are
    // in (at a new size too, when they are all the image's rows).
    const bool copies =
        !precomposed_.empty() && (rowBegin > precomposed_.begin || rowEnd < precomposed_.end);
    const bool swap = mode == ViewMode::Color && copies && swapsIn();
    if ((shadedWidth_ != width_ || shadedHeight_ != height_) && !swap) {
        const double made = threadCpuMs();
        // The shaded texture at the new size (made only now: until then a hold drew the last
        // picture), the FBO on it; shaded whole.
        glBindTexture(GL_TEXTURE_2D, shadedTex_);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width_, height_, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                     nullptr);
        glBindTexture(GL_TEXTURE_2D, 0);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, shadedTex_, 0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        textureCost_.record(double(width_) * double(height_), threadCpuMs() - made);
        // Shaded whole, unless every row was composited off the screen (copied below).
        if (mode != ViewMode::Color || precomposed_.begin > 0 || precomposed_.end < height_) {
            rowBegin = 0;
            rowEnd = height_;
        }
    }
    if (mode == ViewMode::Color) {
        // Rows composited while held are copied now (those composited again below after).
        if (copies) {
            const double copied = threadCpuMs();
            const int rows = showRows();
            if (swap) {
                // The back texture holds the rows composited off the screen: the rows around
                // them (as on screen) join them there, and it becomes the picture; the one on
                // screen becomes the back texture, of its size.
                uploadComposed(0, precomposed_.begin, backTex_);
                uploadComposed(precomposed_.end, height_, backTex_);
                std::swap(shadedTex_, backTex_);
                backWidth_ = shadedWidth_;
                backHeight_ = shadedHeight_;
                glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
                glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                                       shadedTex_, 0);
                glBindFramebuffer(GL_FRAMEBUFFER, 0);
            } else {
                uploadComposed(precomposed_.begin, precomposed_.end);
            }
            if (rows >= 64) showRowCost_.record(rows, threadCpuMs() - copied);
            lastShade_.shownRows = rows;
        }
        const double start = threadCpuMs();
        compose(rowBegin, rowEnd);
        if (rowEnd - rowBegin >= 64)  // the running mean of the time a row takes
            rowCost_.record(rowEnd - rowBegin, threadCpuMs() - start);
        const bool wholeRows = rowBegin <= 0 && rowEnd >= height_;
        if (layerChanged_ && !wholeRows && layerAtImageSize() &&
            composedLayer_.size() == overlayRgba_.size())
            composeLayerChanges(rowBegin, rowEnd);
    } else {
        shadeHeat(scale, logScale, diverging, rowBegin, rowEnd);
    }
    layerChanged_ = false;
    // Rows left for the next draws (budgetedRowsEnd()) stay pending.
    if (rowEnd < dirty_.end && rowBegin <= dirty_.begin && !dirty_.empty())
        dirty_.begin = std::max(dirty_.begin, rowEnd);
    else
        dirty_.clear();
    precomposed_.clear();
    newSize_ = false;
    shadedValid_ = true;
    shadedWidth_ = width_;
    shadedHeight_ = height_;
    shadedMode_ = mode;
    shadedScale_ = scale;
    shadedLog_ = logScale;
    shadedDiverging_ = diverging;
}

void ImageView::shadeHeat(float scale, bool logScale, bool diverging, int rowBegin,
                          int rowEnd) const {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, width_, height_);
    glDisable(GL_BLEND);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    // Image row r is FBO row height - 1 - r (the shader flips): rows [b, e) are [h - e, h - b).
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, height_ - rowEnd, width_, rowEnd - rowBegin);
    glUseProgram(program_->id());
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, heatTex_);
    glUniform1i(locHeat_, 1);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, overlayTex_);
    glUniform1i(locOverlay_, 2);
    glUniform1i(locHasOverlay_, overlayTex_ != 0);
    glUniform1i(locMode_, (diverging ? 2 : 0) + (logScale ? 1 : 0));
    glUniform1f(locScale_, scale);
    const auto& stops = colormapStops();
    glUniform3fv(locStops_, GLsizei(stops.size()), &stops[0].x);
    glUniform1i(locStopCount_, GLint(stops.size()));
    const auto& divStops = divergingStops();
    glUniform3fv(locDivStops_, GLsizei(divStops.size()), &divStops[0].x);
    glBindVertexArray(vao_);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glBindVertexArray(0);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
    glUseProgram(0);
    glDisable(GL_SCISSOR_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

std::vector<uint8_t> readFramebuffer(int width, int height) {
    std::vector<uint8_t> rows(size_t(width) * size_t(height) * 4), out(rows.size());
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rows.data());
    const size_t stride = size_t(width) * 4;
    for (int y = 0; y < height; ++y)  // GL's row 0 is the bottom one
        std::copy_n(rows.data() + size_t(height - 1 - y) * stride, stride,
                    out.data() + size_t(y) * stride);
    for (size_t i = 3; i < out.size(); i += 4) out[i] = 255;  // the window is opaque
    return out;
}

}  // namespace lancer::viewer
