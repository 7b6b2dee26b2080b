// The viewer drawn into an OSMesa context: the image quad must carry the traced image pixel for
// pixel, a heat map must show the counters through the colour map, and the panels must be drawn.
// GL prototypes first (GL_GLEXT_PROTOTYPES), then OSMesa, which includes GL/gl.h too.
#include "app/viewer/gl.h"
// (kept apart so the include sorter leaves this order)
#include <GL/osmesa.h>
#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>  // FindWindowByName: where the panels are
#include <sys/mman.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <set>
#include <thread>
#include <utility>

#include "app/viewer/camera_control.h"
#include "app/viewer/image_view.h"
#include "app/viewer/panel_cache.h"
#include "app/viewer/timing/frame_budget.h"
#include "app/viewer/viewer_app.h"
#include "engine/scene/loader.h"
#include "tests/gl/offscreen_gl.h"

namespace lancer::viewer {
namespace {

using testing::OffscreenGl;

struct Traced {
    Scene scene;
    std::unique_ptr<Accelerator> accel;
    Image img;
};

/// The CPU render the viewer must show: same scene, camera and size.
Traced traceCpu(const std::string& spec, const Camera* camera, int w, int h) {
    Traced t{loadScene(spec), nullptr, Image(w, h)};
    t.accel = buildAccelerator(t.scene, BuildParams{});
    RenderOptions opt;
    opt.width = w;
    opt.height = h;
    if (camera) opt.camera = *camera;
    render(t.scene, *t.accel, opt, t.img);
    return t;
}

int maxDiff(const uint8_t* a, const glm::vec3& expected) {
    int d = 0;
    for (int c = 0; c < 3; ++c)
        d = std::max(d, std::abs(int(a[c]) - int(std::lround(expected[c] * 255.0f))));
    return d;
}

TEST(ViewerGl, ImageQuadCarriesTheTracedImageAndHeatMapsItsCounters) {
    const int w = 160, h = 100;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    Traced t = traceCpu("builtin:default", nullptr, w, h);
    ImageView view;
    view.upload(t.img, ViewMode::Color);
    view.draw(w, h, ViewMode::Color, 1.0f);
    std::vector<uint8_t> shown = gl.read(), expected = t.img.rgba8();
    ASSERT_EQ(shown.size(), expected.size());
    size_t differing = 0;
    for (size_t i = 0; i < shown.size(); ++i)
        differing += std::abs(int(shown[i]) - int(expected[i])) > 1;
    EXPECT_EQ(differing, 0u) << "the quad must show every pixel of the image, row 0 on top";

    // Heat map of primitive tests: each pixel is the colour map of its count over the scale.
    std::vector<float> heat = heatChannel(t.img, ViewMode::PrimTests);
    const float scale = autoScale(heat);
    ASSERT_GT(scale, 1.0f);
    view.upload(t.img, ViewMode::PrimTests);
    view.draw(w, h, ViewMode::PrimTests, scale);
    std::vector<uint8_t> hot = gl.read();
    int worst = 0;
    size_t changed = 0;
    for (size_t i = 0; i < heat.size(); ++i) {
        worst = std::max(worst, maxDiff(&hot[4 * i], colormap(heat[i] / scale)));
        changed += std::abs(int(hot[4 * i]) - int(shown[4 * i])) > 8;
    }
    EXPECT_LE(worst, 2);
    EXPECT_GT(changed, heat.size() / 2) << "the heat map must replace the colour image";
    // The busiest pixel is drawn at the top of the map, an empty one at its bottom.
    size_t top = size_t(std::max_element(heat.begin(), heat.end()) - heat.begin());
    EXPECT_LE(maxDiff(&hot[4 * top], colormapStops().back()), 2);

    // Halving the scale saturates more pixels: the scale is applied.
    view.draw(w, h, ViewMode::PrimTests, scale * 0.5f);
    std::vector<uint8_t> hotter = gl.read();
    worst = 0;
    for (size_t i = 0; i < heat.size(); ++i)
        worst = std::max(worst, maxDiff(&hotter[4 * i], colormap(heat[i] / (scale * 0.5f))));
    EXPECT_LE(worst, 2);
}

/// Two w x h images of one colour each, a blue-grey with 1 test a pixel and a red with 7.
std::pair<Image, Image> twoPlainImages(int w, int h) {
    Image a(w, h), b(w, h);
    for (size_t i = 0; i < a.color.size(); ++i) {
        a.color[i] = glm::vec3(0.2f, 0.4f, 0.6f);
        b.color[i] = glm::vec3(0.9f, 0.1f, 0.3f);
        a.primTests[i] = 1;
        b.primTests[i] = 7;
    }
    return {a, b};
}

TEST(ViewerGl, AnUploadOfSomeRowsReplacesThoseRowsOnlyAndAHoldDefersThemAtAnySize) {
    const int w = 120, h = 80;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    const auto [a, b] = twoPlainImages(w, h);
    ImageView view;
    view.upload(a, ViewMode::Color);
    view.draw(w, h, ViewMode::Color, 1.0f);  // shades every row
    ASSERT_LE(maxDiff(&gl.read()[4 * a.index(5, 70)], a.color[0]), 1);
    // Then only the band's rows are shaded again; the others must keep their pixels.
    const int rowBegin = 30, rowEnd = 45;
    view.upload(b, ViewMode::Color, rowBegin, rowEnd);
    view.draw(w, h, ViewMode::Color, 1.0f);
    std::vector<uint8_t> shown = gl.read();
    for (int y = 0; y < h; ++y) {
        const Image& expected = y >= rowBegin && y < rowEnd ? b : a;
        for (int x = 0; x < w; ++x)
            ASSERT_LE(maxDiff(&shown[4 * a.index(x, y)], expected.color[a.index(x, y)]), 1)
                << x << "," << y;
    }
    // A heat map uploaded whole, then a band of it: the band's counters, the rest unchanged.
    view.upload(a, ViewMode::PrimTests);
    view.draw(w, h, ViewMode::PrimTests, 8.0f);
    view.upload(b, ViewMode::PrimTests, rowBegin, rowEnd);
    view.draw(w, h, ViewMode::PrimTests, 8.0f);
    std::vector<uint8_t> hot = gl.read();
    for (int y = 0; y < h; ++y) {
        const float v = (y >= rowBegin && y < rowEnd ? 7.0f : 1.0f) / 8.0f;
        ASSERT_LE(maxDiff(&hot[4 * a.index(0, y)], colormap(v)), 2) << "row " << y;
    }
    view.upload(a, ViewMode::Color);
    view.draw(w, h, ViewMode::Color, 1.0f);
    // While held (ImageView::setHold) the view shows the image before; a new view comes in
    // two parts, neither shown until the hold ends.
    view.setHold(true);
    view.upload(b, ViewMode::Color, 0, 40);
    view.draw(w, h, ViewMode::Color, 1.0f);
    shown = gl.read();
    for (int y : {0, 39, 40, 79})
        ASSERT_LE(maxDiff(&shown[4 * a.index(7, y)], a.color[0]), 1) << "held: row " << y;
    view.upload(b, ViewMode::Color, 40, 80);
    view.setHold(false);
    view.draw(w, h, ViewMode::Color, 1.0f);
    shown = gl.read();
    for (int y : {0, 39, 40, 79})
        ASSERT_LE(maxDiff(&shown[4 * a.index(7, y)], b.color[0]), 1) << "released: row " << y;
    // A hold keeps a picture of another size too: a new size comes in parts (its first part
    // uploaded alone), the old picture drawn until the hold ends.
    Image c(w / 2, h / 2);
    for (glm::vec3& col : c.color) col = glm::vec3(0.0f, 1.0f, 0.0f);
    view.setHold(true);
    view.upload(c, ViewMode::Color, 0, h / 4);
    view.draw(w, h, ViewMode::Color, 1.0f);
    shown = gl.read();
    for (int y : {0, h / 2, h - 1})
        ASSERT_LE(maxDiff(&shown[4 * a.index(w / 2, y)], b.color[0]), 1) << "held: row " << y;
    view.upload(c, ViewMode::Color, h / 4, h / 2);
    view.setHold(false);
    view.draw(w, h, ViewMode::Color, 1.0f);
    shown = gl.read();
    for (int y : {0, h / 2, h - 1})
        ASSERT_LE(maxDiff(&shown[4 * a.index(w / 2, y)], c.color[0]), 1) << "released: " << y;
    // The first picture of a view, held while its parts come, draws nothing until whole.
    ImageView first;
    glClearColor(0.0f, 0.0f, 1.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    first.setHold(true);
    first.upload(a, ViewMode::Color, 0, h / 2);
    EXPECT_FALSE(first.showsPicture());
    first.draw(w, h, ViewMode::Color, 1.0f);
    shown = gl.read();
    for (int y : {0, h - 1})
        ASSERT_LE(maxDiff(&shown[4 * a.index(7, y)], glm::vec3(0.0f, 0.0f, 1.0f)), 1) << y;
    first.upload(a, ViewMode::Color, h / 2, h);
    first.setHold(false);
    EXPECT_TRUE(first.showsPicture());
    first.draw(w, h, ViewMode::Color, 1.0f);
    shown = gl.read();
    for (int y : {0, h - 1}) ASSERT_LE(maxDiff(&shown[4 * a.index(7, y)], a.color[0]), 1) << y;
}

/// A w x h RGBA8 texture of premultiplied texels (GL's rows: row 0 at the bottom).
unsigned layerTextureOf(int w, int h, const std::vector<uint8_t>& texels) {
    unsigned tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    return tex;
}

/// The picture a view shows of `img` with `layer` (texels at its size) composited whole: a
/// view that never saw another.
std::vector<uint8_t> wholeComposite(const OffscreenGl& gl, const Image& img,
                                    const std::vector<uint8_t>& layer) {
    const unsigned t = layerTextureOf(img.width, img.height, layer);
    ImageView fresh;
    fresh.upload(img, ViewMode::Color);
    fresh.setOverlay(t, 1);
    gl.clear(0, 0, 0);
    fresh.draw(img.width, img.height, ViewMode::Color, 1.0f);
    glDeleteTextures(1, &t);
    return gl.read();
}

TEST(ViewerGl, ANewLayerCompositesOnlyTheTexelsItChangedAndEqualsTheWholeComposite) {
    const int w = 160, h = 96;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    // An image of many colours and a layer of scattered premultiplied texels.
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img.color[img.index(x, y)] =
                glm::vec3(float(x) / w, float(y) / h, float((x * 7 + y * 3) % 11) / 11.0f);
    std::vector<uint8_t> texels(size_t(w) * h * 4, 0);
    auto put = [&](int x, int y, uint8_t v, uint8_t a) {
        uint8_t* p = &texels[(size_t(y) * w + size_t(x)) * 4];
        p[0] = v, p[1] = uint8_t(v / 2), p[2] = 0, p[3] = a;
    };
    for (int i = 0; i < w * h; i += 37) put(i % w, i / w, 120, 200);
    const unsigned tex = layerTextureOf(w, h, texels);
    auto whole = [&](const std::vector<uint8_t>& layer) { return wholeComposite(gl, img, layer); };
    ImageView view;
    view.upload(img, ViewMode::Color);
    // The layer's texels as they stand now, as version `version` of the texture, drawn.
    auto newLayer = [&](uint64_t version) {
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
        glBindTexture(GL_TEXTURE_2D, 0);
        view.setOverlay(tex, version);
        gl.clear(0, 0, 0);
        view.draw(w, h, ViewMode::Color, 1.0f);
    };
    newLayer(1);
    EXPECT_EQ(view.lastShade().rows, h) << "the first layer: the whole image";
    // A part of the layer lights a few texels in rows 40-42 and clears one: only those are
    // composited again, and uploaded in their band's rectangle.
    size_t changed = 0;
    for (int x = 20; x < 50; ++x)
        for (int y = 40; y < 43; ++y) {
            uint8_t* p = &texels[(size_t(y) * w + size_t(x)) * 4];
            const bool was = p[3] == 230;
            put(x, y, 230, 230);
            changed += !was;
        }
    ASSERT_EQ(texels[(size_t(37) * w + 0) * 4 + 3], 200);  // (0, 37), lit: back to transparent
    std::fill_n(&texels[(size_t(37) * w + 0) * 4], 4, uint8_t(0));
    ++changed;
    newLayer(2);
    EXPECT_EQ(view.lastShade().rows, 0) << "no row composited whole";
    EXPECT_EQ(view.lastShade().texels, changed);
    EXPECT_LT(view.lastShade().uploadedTexels, size_t(w) * 16 * 2) << "two bands at most";
    EXPECT_EQ(gl.read(), whole(texels)) << "the same picture as the whole composite";
    // The same layer again: nothing composited.
    view.setOverlay(tex, 2);
    view.draw(w, h, ViewMode::Color, 1.0f);
    EXPECT_EQ(view.lastShade().texels, 0u);
    // Rows of a new pass and a new layer in one frame: the rows whole, the other rows' changed
    // texels; the picture is the whole composite of both.
    for (int y = 60; y < 70; ++y)
        for (int x = 0; x < w; ++x) img.color[img.index(x, y)] = glm::vec3(0.9f, 0.2f, 0.1f);
    view.upload(img, ViewMode::Color, 60, 70);
    for (int x = 0; x < w; x += 3) put(x, h - 1 - 65, 90, 90);  // inside the new rows
    for (int x = 0; x < w; x += 5) put(x, 10, 60, 255);         // outside them
    newLayer(3);
    EXPECT_EQ(view.lastShade().rows, 10);
    EXPECT_EQ(view.lastShade().texels, size_t(w - 4)) << "row 10's span, x 0 to w - 5";
    EXPECT_EQ(gl.read(), whole(texels));
    // While held, a new layer waits with the rows; once released the picture is the whole one.
    view.setHold(true);
    for (int x = 0; x < w; x += 2) put(x, 80, 200, 210);
    newLayer(4);
    view.setHold(false);
    gl.clear(0, 0, 0);
    view.draw(w, h, ViewMode::Color, 1.0f);
    EXPECT_EQ(view.lastShade().texels, size_t(w - 1)) << "row 80's span, x 0 to w - 2";
    EXPECT_EQ(gl.read(), whole(texels));
    glDeleteTextures(1, &tex);
}

/// Two views of many colours, w x h.
std::pair<Image, Image> twoViews(int w, int h) {
    Image a(w, h), b(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            a.color[a.index(x, y)] = glm::vec3(float(x) / w, float(y) / h, 0.3f);
            b.color[b.index(x, y)] = glm::vec3(0.2f, float((x * 5 + y) % 13) / 13.0f, float(y) / h);
        }
    return {std::move(a), std::move(b)};
}

/// A w x h layer of premultiplied texels, every `step`-th one lit: `channel` at `value`, alpha
/// `alpha`.
std::vector<uint8_t> scatteredLayer(int w, int h, size_t step, int channel, uint8_t value,
                                    uint8_t alpha) {
    std::vector<uint8_t> texels(size_t(w) * h * 4, 0);
    for (size_t i = 0; i < texels.size() / 4; i += step) {
        texels[i * 4 + size_t(channel)] = value;
        texels[i * 4 + 3] = alpha;
    }
    return texels;
}

TEST(ViewerGl, AHeldViewCompositedInPartsWithinTheBudgetEndsAsTheWholeComposite) {
    const int w = 160, h = 96;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    // Two views of many colours and a layer of scattered premultiplied texels.
    const auto [a, b] = twoViews(w, h);
    std::vector<uint8_t> texels = scatteredLayer(w, h, 29, 0, 150, 190);
    const unsigned tex = layerTextureOf(w, h, texels);
    ImageView view;
    view.upload(a, ViewMode::Color);
    view.setOverlay(tex, 1);
    gl.clear(0, 0, 0);
    view.draw(w, h, ViewMode::Color, 1.0f);
    const std::vector<uint8_t> shownA = gl.read();
    // A clock only the test moves: a frame with room, or one its earlier steps spent.
    double now = 0.0;
    FrameBudget budget(33.0, [&] { return now; });
    auto frame = [&](bool spent) {
        budget.begin();
        if (spent) now += 100.0;
        // The budget for the held parts alone: the releases below are drawn without one.
        view.setFrameBudget(&budget, 5.0);
        const int rows = view.composeHeld();
        view.setFrameBudget(nullptr, 0.0);
        return rows;
    };
    // View b comes in three parts while held: composited as it comes when the frame has room,
    // not when it is spent; the screen shows view a meanwhile.
    view.setHold(true);
    view.upload(b, ViewMode::Color, 0, 32);
    EXPECT_EQ(frame(false), 32);
    gl.clear(0, 0, 0);
    view.draw(w, h, ViewMode::Color, 1.0f);
    EXPECT_EQ(gl.read(), shownA) << "held: the view before";
    view.upload(b, ViewMode::Color, 32, 64);
    EXPECT_EQ(frame(true), 0);
    EXPECT_GE(budget.deferred(), 1);
    view.upload(b, ViewMode::Color, 64, 96);
    EXPECT_EQ(frame(false), 64) << "the rows of the spent frame too";
    // A new layer while held (a texel in a composited row changes), then the release: no row
    // composited there, only the layer's changed texel, and the whole composite's picture.
    texels[(size_t(10) * w + 7) * 4 + 1] = 220;
    texels[(size_t(10) * w + 7) * 4 + 3] = 230;
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    view.setOverlay(tex, 2);
    view.setHold(false);
    gl.clear(0, 0, 0);
    view.draw(w, h, ViewMode::Color, 1.0f);
    EXPECT_EQ(view.lastShade().rows, 0) << "composited while held";
    EXPECT_EQ(view.lastShade().texels, 1u);
    EXPECT_EQ(gl.read(), wholeComposite(gl, b, texels));
    // View a again, held, every frame spent: the release composites all its rows.
    view.setHold(true);
    view.upload(a, ViewMode::Color);
    EXPECT_EQ(frame(true), 0);
    view.setHold(false);
    gl.clear(0, 0, 0);
    view.draw(w, h, ViewMode::Color, 1.0f);
    EXPECT_EQ(view.lastShade().rows, h);
    EXPECT_EQ(gl.read(), wholeComposite(gl, a, texels));
    // Nothing composites while not held.
    view.upload(b, ViewMode::Color, 0, 10);
    EXPECT_EQ(frame(false), 0);
    glDeleteTextures(1, &tex);
}

TEST(ViewerGl, AFinerPassesRowsCompositeWithinTheBudgetAPartAtLeastAndEndAsTheWholeComposite) {
    double now = 0.0;  // a clock only the test moves
    FrameBudget budget(33.0, [&] { return now; });
    const int w = 160, h = 200;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImageView view;
    view.setFrameBudget(&budget, 5.0);
    // A coarse pass and a finer one of the same view (as two views' colours differ), and a
    // layer of scattered texels.
    const auto [coarse, fine] = twoViews(w, h);
    std::vector<uint8_t> texels = scatteredLayer(w, h, 37, 2, 120, 160);
    const unsigned tex = layerTextureOf(w, h, texels);
    auto draw = [&](bool spent) {
        budget.begin();
        if (spent) now += 100.0;
        gl.clear(0, 0, 0);
        view.draw(w, h, ViewMode::Color, 1.0f);
        return view.lastShade().rows;
    };
    view.upload(coarse, ViewMode::Color);
    view.setOverlay(tex, 1);
    EXPECT_EQ(draw(false), 0)
        << "a first picture: off the screen in parts, all in a frame with room";
    EXPECT_EQ(gl.read(), wholeComposite(gl, coarse, texels));
    // The finer pass's rows, the frame spent by the steps before: one part of 48 rows a frame,
    // the rest left for the next frames.
    view.upload(fine, ViewMode::Color);
    EXPECT_EQ(draw(true), 48);
    EXPECT_EQ(view.pendingRows(), h - 48);
    EXPECT_GE(budget.deferred(), 1);
    // A new layer meanwhile (a texel in a composited row, one in a pending row).
    for (int row : {5, 150}) {
        const size_t at = (size_t(h - 1 - row) * w + 9) * 4;  // the layer's rows go up
        texels[at + 0] = 200;
        texels[at + 3] = 210;
    }
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    view.setOverlay(tex, 2);
    EXPECT_EQ(draw(true), 48);
    EXPECT_EQ(view.pendingRows(), h - 96);
    // A frame with room composites the rest; the picture is the finer pass's whole composite.
    EXPECT_EQ(draw(false), h - 96);
    EXPECT_EQ(view.pendingRows(), 0);
    EXPECT_EQ(gl.read(), wholeComposite(gl, fine, texels));
    // A view released from a hold with every frame spent: composited off the screen a part of
    // 48 rows a frame, the view before shown meanwhile, then shown whole at once (two views
    // never share the screen).
    const std::vector<uint8_t> before = gl.read();
    view.setHold(true);
    view.upload(coarse, ViewMode::Color);
    draw(true);
    EXPECT_EQ(gl.read(), before) << "held";
    view.setHold(false);
    int draws = 0;
    while (view.pendingRows() > 0 && draws < 2 * h) {
        draw(true);
        ++draws;
        if (view.pendingRows() > 0) {
            EXPECT_EQ(gl.read(), before) << "released, draw " << draws;
        }
    }
    EXPECT_EQ(draws, (h + 47) / 48 + 1) << "a part a frame, and the showing in a frame of its own";
    EXPECT_EQ(view.lastShade().rows, 0) << "every row composited off the screen";
    EXPECT_EQ(gl.read(), wholeComposite(gl, coarse, texels));
    glDeleteTextures(1, &tex);
}

/// An OSMesa context of w x h and a frame budget of 33 ms on a clock only the test moves.
struct GlWithBudget {
    OffscreenGl gl;
    double now = 0.0;
    FrameBudget budget{33.0, [this] { return now; }};
    GlWithBudget(int w, int h) : gl(w, h) {}
};

/// A colour view of w x h under such a budget (5 ms kept for later steps), `layer`'s texels
/// over it, and two images to show in it.
struct ViewWithBudget : GlWithBudget {
    const int w, h;
    const std::pair<Image, Image> images;
    const std::vector<uint8_t> texels;
    unsigned tex = 0;
    ImageView view;
    ViewWithBudget(int width, int height, std::vector<uint8_t> layer)
        : GlWithBudget(width, height),
          w(width),
          h(height),
          images(twoViews(width, height)),
          texels(std::move(layer)) {
        if (!gl.ok()) return;
        tex = layerTextureOf(w, h, texels);
        view.setFrameBudget(&budget, 5.0);
        view.setOverlay(tex, 1);
    }
    ~ViewWithBudget() {
        if (tex) glDeleteTextures(1, &tex);
    }
    ViewWithBudget(const ViewWithBudget&) = delete;
    ViewWithBudget& operator=(const ViewWithBudget&) = delete;
    /// The first image uploaded whole (no hold); the view to draw it.
    ImageView& uploadFirst() {
        view.upload(images.first, ViewMode::Color);
        return view;
    }
    /// A draw over the framebuffer's blue: whether anything was drawn.
    bool draw() {
        gl.clear(0, 0, 1);
        view.draw(w, h, ViewMode::Color, 1.0f);
        const std::vector<uint8_t> px = gl.read();
        for (size_t i = 0; i < px.size(); i += 4)
            if (px[i] != 0 || px[i + 1] != 0 || px[i + 2] != 255) return true;
        return false;
    }
};

// The rows of a view composited off the screen at the picture's size are copied into the back
// texture as they are composited, and showing the view swaps that texture in: the frame that
// shows it copies no row (a released view's 720 rows took 13-19 ms of that frame's image step
// at 1280x720, over the budget, 2026-12-07). A view composited only in part has the rows
// around it copied from the picture before. Each picture equals its whole composite.
TEST(ViewerGl, AViewCompositedOffTheScreenIsShownBySwappingInItsBackTexture) {
    ViewWithBudget set(160, 120, scatteredLayer(160, 120, 23, 2, 160, 200));
    ASSERT_TRUE(set.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImageView& view = set.view;
    const Image &a = set.images.first, &b = set.images.second;
    const int w = set.w, h = set.h;
    view.upload(a, ViewMode::Color);
    ASSERT_TRUE(set.draw());
    EXPECT_EQ(view.lastShade().rows, 0)
        << "the first picture: off the screen, in a frame with room";
    EXPECT_EQ(set.gl.read(), wholeComposite(set.gl, a, set.texels));
    // Rows [0, rows) of `img` held and composited in a frame with room, then released.
    auto show = [&](const Image& img, int rows) {
        view.setHold(true);
        view.upload(img, ViewMode::Color, 0, rows);
        set.budget.begin();
        EXPECT_EQ(view.composeHeld(), rows);
        view.setHold(false);
        set.draw();
        return set.gl.read();
    };
    // View b whole: no row copied to show it.
    EXPECT_EQ(show(b, h), wholeComposite(set.gl, b, set.texels));
    EXPECT_EQ(view.lastShade().rows, 0);
    EXPECT_EQ(view.lastShade().shownRows, 0) << "the back texture swapped in";
    // View a's first 40 rows: the other rows, b's, copied beside them.
    Image mixed = b;
    for (int y = 0; y < 40; ++y)
        for (int x = 0; x < w; ++x) mixed.color[mixed.index(x, y)] = a.color[a.index(x, y)];
    EXPECT_EQ(show(a, 40), wholeComposite(set.gl, mixed, set.texels));
    EXPECT_EQ(view.lastShade().shownRows, h - 40);
    // And b whole again, into the texture that was on screen before.
    EXPECT_EQ(show(b, h), wholeComposite(set.gl, b, set.texels));
    EXPECT_EQ(view.lastShade().shownRows, 0);
}

// A held view's parts keep back what the view's budget keeps for the steps after the image (the
// inspector's and the panels' copies), as a finer pass's rows do: given apart, the held parts
// kept the layer's reserve alone, and a still frame on balls4 with the inspector took 34.9 ms
// of UI CPU (the back texture and three parts after it, 2026-12-07).
TEST(ViewerGl, AHeldViewsPartsKeepTheReserveOfTheViewsBudget) {
    ViewWithBudget set(160, 120, scatteredLayer(160, 120, 19, 0, 90, 120));
    ASSERT_TRUE(set.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImageView& view = set.view;
    view.upload(set.images.first, ViewMode::Color);
    ASSERT_TRUE(set.draw());
    view.setHold(true);
    view.upload(set.images.second, ViewMode::Color);
    // 13 ms of the frame's 33 left: room for the parts beside a reserve of 5 ms, none beside
    // one of 20 ms.
    set.budget.begin();
    set.now += 20.0;
    view.setFrameBudget(&set.budget, 20.0);
    EXPECT_EQ(view.composeHeld(), 0);
    view.setFrameBudget(&set.budget, 5.0);
    EXPECT_EQ(view.composeHeld(), set.h);
    view.setFrameBudget(nullptr, 0.0);
    EXPECT_EQ(view.composeHeld(), 0) << "no budget, no held parts";
}

// A new layer version is read back only when the read-back's learned cost fits in the frame's
// budget, or after its patience: until then the picture keeps the layer it was made with (a
// read-back is where llvmpipe finishes the layer's drawing: 14-22 ms of frames already full,
// balls4 at 1280x720, 2026-12-07).
TEST(ViewerGl, ALayersReadBackWaitsForTheBudgetAndThePictureKeepsTheLayerBefore) {
    ViewWithBudget set(160, 120, scatteredLayer(160, 120, 17, 1, 130, 170));
    ASSERT_TRUE(set.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImageView& view = set.uploadFirst();
    const Image& a = set.images.first;
    ASSERT_TRUE(set.draw());
    const std::vector<uint8_t> before = set.gl.read();
    ASSERT_EQ(before, wholeComposite(set.gl, a, set.texels));
    // Version 2 lights one more texel.
    std::vector<uint8_t> texels = set.texels;
    const size_t at = (size_t(40) * size_t(set.w) + 33) * 4;
    texels[at + 0] = 240;
    texels[at + 3] = 250;
    glBindTexture(GL_TEXTURE_2D, set.tex);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, set.w, set.h, GL_RGBA, GL_UNSIGNED_BYTE, texels.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    ASSERT_NE(wholeComposite(set.gl, a, texels), before);
    // Frames spent by the steps before: the read-back waits kPatienceFrames frames, the
    // picture keeps the layer before.
    for (unsigned f = 0; f < kPatienceFrames; ++f) {
        set.budget.begin();
        set.now += 100.0;
        EXPECT_FALSE(view.setOverlay(set.tex, 2, set.budget, 5.0)) << "frame " << f;
        EXPECT_EQ(set.budget.forced(), 0);
        ASSERT_TRUE(set.draw());
        EXPECT_EQ(set.gl.read(), before) << "the layer before, frame " << f;
    }
    // The next spent frame lets it in over the budget: the new layer's texel composites.
    set.budget.begin();
    set.now += 100.0;
    EXPECT_TRUE(view.setOverlay(set.tex, 2, set.budget, 5.0));
    EXPECT_EQ(set.budget.forced(), 1);
    ASSERT_TRUE(set.draw());
    EXPECT_EQ(view.lastShade().texels, 1u) << "the changed texel alone";
    EXPECT_EQ(set.gl.read(), wholeComposite(set.gl, a, texels));
    // A frame with room reads version 3 (the layer before again) at once; the one it holds
    // asks nothing.
    set.budget.begin();
    EXPECT_TRUE(view.setOverlay(set.tex, 2, set.budget, 5.0));
    glBindTexture(GL_TEXTURE_2D, set.tex);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, set.w, set.h, GL_RGBA, GL_UNSIGNED_BYTE,
                    set.texels.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    EXPECT_TRUE(view.setOverlay(set.tex, 3, set.budget, 5.0));
    EXPECT_EQ(set.budget.deferred(), 0);
    ASSERT_TRUE(set.draw());
    EXPECT_EQ(set.gl.read(), before);
}

// A read-back into fresh memory (10-14 ms for a new 1280x720 buffer, nearly all of it page
// faults) is learned apart from one into the buffer the view keeps (0.3-2 ms while the camera
// turns): one mean of both kept the later read-backs waiting their patience for 20-30 frames
// after each first one (balls4, 2026-12-07).
TEST(ViewerGl, AReadBackIntoFreshMemoryIsLearnedApartFromOneIntoTheBufferKept) {
    const int w = 160, h = 120;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    const std::vector<uint8_t> texels = scatteredLayer(w, h, 11, 1, 90, 140);
    const unsigned tex = layerTextureOf(w, h, texels), other = layerTextureOf(w, h, texels);
    ImageView view;  // no image uploaded: no buffer prepared
    const double texelShare = double(w) * double(h) / (1280.0 * 720.0);
    // Nothing read yet: a read-back needs fresh memory, at the fresh one's guess.
    EXPECT_TRUE(view.readNeedsFreshMemory(w, h));
    EXPECT_DOUBLE_EQ(view.readEstimateMs(w, h), 10.6 * texelShare);
    view.setOverlay(tex, 1);
    // The buffer is kept: any texture's next read-back at that size or smaller goes into it,
    // at the kept one's guess; a larger one needs fresh memory, at what the first learned.
    EXPECT_FALSE(view.readNeedsFreshMemory(w, h));
    const double kept = view.readEstimateMs(w, h);
    EXPECT_DOUBLE_EQ(kept, 1.0 * texelShare);
    EXPECT_TRUE(view.readNeedsFreshMemory(w, 2 * h));
    const double freshLearned = view.readEstimateMs(w, 2 * h) / 2.0;
    EXPECT_NE(freshLearned, 10.6 * texelShare) << "the fresh read-back's measure is learned";
    // Another texture's read-back into the kept buffer moves the kept one's cost only.
    view.setOverlay(other, 1);
    EXPECT_NE(view.readEstimateMs(w, h), kept);
    EXPECT_DOUBLE_EQ(view.readEstimateMs(w, 2 * h), 2.0 * freshLearned);
    const unsigned both[2] = {tex, other};
    glDeleteTextures(2, both);
}

// An image of a new size has the layer's read-back buffer of its size made on a worker: the
// first read-back at that size (a new structure's first layer) writes into mapped pages and
// is no fresh one (it was let in at 10.6 ms over the budget after its patience, making frames
// of 34-44 ms: balls4 at 1280x720, 2026-12-07).
TEST(ViewerGl, AnImagesUploadPreparesTheReadBackBufferOfItsSizeOnAWorker) {
    const int w = 160, h = 120;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    const std::vector<uint8_t> texels = scatteredLayer(w, h, 11, 1, 90, 140);
    const unsigned tex = layerTextureOf(w, h, texels);
    ImageView view;
    const double texelShare = double(w) * double(h) / (1280.0 * 720.0);
    view.upload(twoViews(w, h).first, ViewMode::Color);
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (view.readNeedsFreshMemory(w, h) && std::chrono::steady_clock::now() < until)
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    ASSERT_FALSE(view.readNeedsFreshMemory(w, h)) << "the buffer of the image's size is ready";
    EXPECT_DOUBLE_EQ(view.readEstimateMs(w, h), 1.0 * texelShare);
    EXPECT_TRUE(view.readNeedsFreshMemory(w, 2 * h)) << "only the image's size is prepared";
    view.setOverlay(tex, 1);
    // The read went into the prepared buffer: the kept read-back's cost moved, the fresh one's
    // is still its guess.
    EXPECT_NE(view.readEstimateMs(w, h), 1.0 * texelShare);
    EXPECT_DOUBLE_EQ(view.readEstimateMs(w, 2 * h), 2.0 * 10.6 * texelShare);
    glDeleteTextures(1, &tex);
}

// A first picture uploaded whole without a hold (the irregular scheme's first after a turn,
// its structure rebuilt) comes off the screen in parts too: composited whole with its texture
// made in one frame, it took 41-55 ms of the image step (balls4 at 1280x720, 2026-12-07).
TEST(ViewerGl, AFirstPictureUploadedWithoutAHoldComesOffTheScreenInParts) {
    ViewWithBudget set(160, 200, scatteredLayer(160, 200, 13, 0, 110, 150));
    ASSERT_TRUE(set.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImageView& view = set.uploadFirst();
    const Image& a = set.images.first;
    // Every frame spent: a part of 48 rows a draw, nothing shown before the last.
    int draws = 0;
    bool drawn = false;
    while (!drawn && draws < 20) {
        set.budget.begin();
        set.now += 100.0;
        drawn = set.draw();
        ++draws;
        EXPECT_EQ(view.lastShade().rows, 0) << "draw " << draws;
    }
    EXPECT_TRUE(drawn);
    EXPECT_EQ(draws, (set.h + 47) / 48 + 1)
        << "a part a draw, and the showing (after its patience) in a draw of its own";
    EXPECT_EQ(set.gl.read(), wholeComposite(set.gl, a, set.texels));
    // Without a budget a first picture is composited whole at once, as before.
    ImageView plain;
    plain.setOverlay(set.tex, 1);
    plain.upload(set.images.second, ViewMode::Color);
    set.gl.clear(0, 0, 1);
    plain.draw(set.w, set.h, ViewMode::Color, 1.0f);
    EXPECT_EQ(plain.lastShade().rows, set.h);
    EXPECT_EQ(set.gl.read(), wholeComposite(set.gl, set.images.second, set.texels));
}

TEST(ViewerGl, AFirstPictureComesOffTheScreenInPartsAndShowsOnlyWhenWhole) {
    ViewWithBudget set(160, 200, scatteredLayer(160, 200, 31, 1, 140, 170));
    ASSERT_TRUE(set.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    const OffscreenGl& gl = set.gl;
    FrameBudget& budget = set.budget;
    ImageView& view = set.view;
    const Image& a = set.images.first;
    const int h = set.h;
    const auto begin = [&](bool spent) {
        budget.begin();
        if (spent) set.now += 100.0;
    };
    // Nothing drawn over the framebuffer's blue before the picture is whole (set.draw()).
    // Its parts come held: composited as they come when the frame has room.
    view.setHold(true);
    view.upload(a, ViewMode::Color, 0, 80);
    begin(false);
    EXPECT_EQ(view.composeHeld(), 80);
    EXPECT_FALSE(set.draw()) << "held, no picture yet";
    view.upload(a, ViewMode::Color, 80, 160);
    begin(true);
    EXPECT_EQ(view.composeHeld(), 0) << "a spent frame";
    view.upload(a, ViewMode::Color, 160, 200);
    view.setHold(false);
    EXPECT_FALSE(view.showsPicture());
    // Released with every frame spent: a part of 48 rows a draw off the screen, none shown
    // until the last, then all of it, no row composited whole.
    int draws = 0;
    bool drawn = false;
    while (!drawn && draws < h) {
        begin(true);
        drawn = set.draw();
        ++draws;
        if (!drawn) {
            EXPECT_GT(view.pendingRows(), 0) << draws;
        }
    }
    EXPECT_EQ(draws, 4) << "120 rows left: 48, 48, 24, then the showing in a frame of its own";
    EXPECT_EQ(view.pendingRows(), 0);
    EXPECT_EQ(view.lastShade().rows, 0);
    EXPECT_EQ(gl.read(), wholeComposite(gl, a, set.texels));
    // The counters' texture is made only for a heat map.
    EXPECT_FALSE(view.countersAllocated());
    view.upload(a, ViewMode::PrimTests);
    EXPECT_TRUE(view.countersAllocated());
}

TEST(ViewerGl, AReleasedViewIsShownWithinItsPatienceWhileAFinerPassesRowsKeepComing) {
    // A view released with every frame spent, and a finer pass's rows coming in every frame
    // after the one its last part is composited in: each draw composites what came and has
    // the view to show, whose learned cost never fits. It is shown once the showing has
    // waited kPatienceFrames draws, not only when the pass's rows stop.
    ViewWithBudget set(160, 200, scatteredLayer(160, 200, 29, 2, 120, 160));
    ASSERT_TRUE(set.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImageView& view = set.view;
    const auto& [a, b] = set.images;
    const int h = set.h;
    view.setHold(true);
    view.upload(a, ViewMode::Color, 0, h);
    view.setHold(false);
    // Off the screen a part of 48 rows a draw: the last of the 200 in the fifth.
    const int lastPart = (h + 47) / 48;
    constexpr int kRowsADraw = 5;  // the finer pass: 40 draws of rows
    int draws = 0, shownAt = 0, row = 0;
    while (row < h || shownAt == 0) {
        ASSERT_LT(draws, 4 * h) << "never shown";
        set.budget.begin();
        set.now += 100.0;
        ++draws;
        if (draws > lastPart && row < h) {
            view.upload(b, ViewMode::Color, row, std::min(h, row + kRowsADraw));
            row += kRowsADraw;
        }
        if (set.draw() && shownAt == 0) shownAt = draws;
    }
    EXPECT_EQ(shownAt, lastPart + int(kPatienceFrames)) << "after its patience";
    EXPECT_LT(shownAt, lastPart + h / kRowsADraw) << "shown while the pass's rows still came";
    // The rest of the pass composites on screen; the picture ends as the whole composite's.
    for (int i = 0; i < 8 && view.pendingRows() > 0; ++i) {
        set.budget.begin();
        set.now += 100.0;
        set.draw();
    }
    EXPECT_EQ(view.pendingRows(), 0);
    set.draw();
    EXPECT_EQ(set.gl.read(), wholeComposite(set.gl, b, set.texels));
}

TEST(ViewerGl, ZeroedBytesMapAPageOnlyWhenItIsWritten) {
    const size_t page = size_t(sysconf(_SC_PAGESIZE)), pages = 64;
    ZeroedBytes bytes;
    bytes.assignZeroed(pages * page);
    auto resident = [&] {
        std::vector<unsigned char> in(pages);
        EXPECT_EQ(mincore(bytes.data(), pages * page, in.data()), 0);
        return size_t(std::count_if(in.begin(), in.end(), [](unsigned char c) { return c & 1; }));
    };
    EXPECT_EQ(resident(), 0u) << "none before a write";
    bytes.data()[5 * page + 7] = 9;
    EXPECT_EQ(resident(), 1u);
    EXPECT_EQ(bytes.data()[5 * page + 6], 0);
    bytes.resize(pages * page);
    EXPECT_EQ(bytes.data()[5 * page + 7], 9) << "the same size keeps the bytes";
    bytes.resize(pages * page / 2);
    EXPECT_EQ(bytes.size(), pages * page / 2);
    EXPECT_EQ(bytes.data()[5 * page + 7], 0) << "another size: zero again";
}

TEST(ViewerImage, TheFirstImageAndEachViewOfADragComeInPartsNeverWhole) {
    // The state alone (no GL): its snapshots at 1280x720, where a part is a third of the rows.
    ImGui::CreateContext();
    ViewerSettings settings;
    settings.scene = "builtin:default";
    constexpr int kW = 1280, kH = 720;
    const int maxRows = kSnapshotPixels / kW;
    ASSERT_LT(maxRows, kH);
    {
        ViewerState state(settings, false, {});
        // Rows the screen's job has uploaded since it became the shown job; a job is shown
        // (not held) only once all of its rows are in: never two views at once.
        std::vector<bool> covered(kH, false);
        uint64_t job = 0;
        int uploads = 0, partsHeld = 0, viewsShown = 0;
        bool firstHeld = false;
        auto frame = [&] {
            state.poll();
            RowRange rows;
            if (state.takeUpload(rows)) {
                ++uploads;
                EXPECT_LE(rows.end - rows.begin, maxRows) << "upload " << uploads << " came whole";
                if (state.shownJob() != job) {
                    job = state.shownJob();
                    covered.assign(kH, false);
                }
                for (int y = std::max(rows.begin, 0); y < std::min(rows.end, kH); ++y)
                    covered[size_t(y)] = true;
                if (uploads == 1) firstHeld = state.holdImage();
                if (state.holdImage()) {
                    ++partsHeld;
                } else {
                    EXPECT_EQ(std::count(covered.begin(), covered.end(), true), kH)
                        << "job " << job << " shown before all its rows were in";
                    ++viewsShown;
                }
            }
            state.startWork(kW, kH);
        };
        auto start = std::chrono::steady_clock::now();
        const auto within = [&] {
            return std::chrono::steady_clock::now() - start < std::chrono::seconds(60);
        };
        while (viewsShown == 0 && within()) {
            frame();
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        ASSERT_GT(viewsShown, 0);
        EXPECT_TRUE(firstHeld) << "the first image's first part is held off the screen";
        EXPECT_GE(partsHeld, 2) << "the first image came in parts";
        // A drag: a new view every frame. Each view begun is finished in parts (the renderer
        // keeps it while newer ones render), and some are shown while the camera turns.
        const int shownBefore = viewsShown;
        std::set<uint64_t> jobsShown;
        for (int f = 0; f < 60 && within(); ++f) {
            Camera c = state.camera();
            orbit(c, 2.0 * 3.14159265358979 / 180.0, 0.0);
            state.setCamera(c);
            const int before = viewsShown;
            frame();
            if (viewsShown > before) jobsShown.insert(state.shownJob());
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        EXPECT_GE(jobsShown.size(), 2u) << viewsShown - shownBefore << " views shown";
    }
    ImGui::DestroyContext();
}

TEST(ViewerState, ARebuildAfterACameraMoveTakesTheLightsStructuresOfTheLastBuild) {
    // The irregular scheme's structure follows the camera; its lights' structures and the light
    // buffer do not, so the rebuild after a move takes them from the structure it replaces.
    ImGui::CreateContext();
    ViewerSettings settings;
    settings.scene = "builtin:balls:2";
    settings.build.scheme = SchemeKind::Irregular;
    {
        ViewerState state(settings, false, {});
        const auto start = std::chrono::steady_clock::now();
        const auto waitFor = [&](auto done) {
            while (!done() && std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
                state.poll();
                state.startWork(320, 200);  // where a camera move asks for the rebuild
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
            return done();
        };
        ASSERT_TRUE(waitFor([&] { return state.sceneBuild() != nullptr; }));
        const std::shared_ptr<const SceneBuild> first = state.sceneBuild();
        const nlohmann::json& x0 = first->accel->info().extra;
        ASSERT_GT(x0["light_structures"].get<size_t>(), 0u);
        EXPECT_FALSE(x0["lights_lent"].get<bool>());
        Camera c = state.camera();
        orbit(c, 0.5, 0.0);
        state.setCamera(c);
        ASSERT_TRUE(waitFor([&] { return state.sceneBuild() != first; }));
        const nlohmann::json& x1 = state.sceneBuild()->accel->info().extra;
        EXPECT_TRUE(x1["lights_lent"].get<bool>());
        EXPECT_TRUE(x1["light_buffer_lent"].get<bool>());
        EXPECT_EQ(x1["light_slabs"], x0["light_slabs"]);
        EXPECT_EQ(state.sceneBuild()->scene->camera.from, c.from);
    }
    ImGui::DestroyContext();
}

TEST(ViewerGl, PanelsFromTheirTexturesMatchImGuisOwnDrawingAndRedrawOnlyWhenChanged) {
    const int w = 420, h = 300;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::GetIO().DisplaySize = ImVec2(float(w), float(h));
    ASSERT_TRUE(ImGui_ImplOpenGL3_Init("#version 330 core"));
    ImGuiStyle& style = ImGui::GetStyle();  // opaque panels, as the viewer has them
    style.Colors[ImGuiCol_WindowBg].w = 1.0f;
    style.Colors[ImGuiCol_PopupBg].w = 1.0f;
    style.Colors[ImGuiCol_TitleBgCollapsed].w = 1.0f;
    {
        PanelCache cache;
        // Two panels, one partly off the window, one with a child region and a table; a
        // counter in the first changes when asked.
        // `tip` (optional): a small third panel over free space at that place, as the
        // overlays' hover tooltip over the image.
        auto frame = [&](int counter, const ImVec2* tip = nullptr) {
            ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
            ImGui_ImplOpenGL3_NewFrame();  // builds the font atlas on the first frame
            ImGui::NewFrame();
            if (tip) {
                ImGui::SetNextWindowPos(*tip);
                ImGui::SetNextWindowSize(ImVec2(90, 50));
                ImGui::Begin("tip", nullptr,
                             ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoFocusOnAppearing |
                                 ImGuiWindowFlags_NoInputs);
                ImGui::Text("tip");
                ImGui::End();
            }
            ImGui::SetNextWindowPos(ImVec2(10, 10));
            ImGui::SetNextWindowSize(ImVec2(200, 150));
            ImGui::Begin("first");
            ImGui::Text("counter %d", counter);
            ImGui::Button("a button");
            float f = 0.5f;
            ImGui::SliderFloat("slider", &f, 0.0f, 1.0f);
            ImGui::End();
            ImGui::SetNextWindowPos(ImVec2(260, 120));
            ImGui::SetNextWindowSize(ImVec2(220, 220));
            ImGui::Begin("second");
            ImGui::BeginChild("child", ImVec2(0, 80), true);
            for (int i = 0; i < 8; ++i) ImGui::Text("line %d", i);
            ImGui::EndChild();
            if (ImGui::BeginTable("t", 2, ImGuiTableFlags_Borders)) {
                ImGui::TableNextColumn();
                ImGui::Text("x");
                ImGui::TableNextColumn();
                ImGui::Text("y");
                ImGui::EndTable();
            }
            ImGui::End();
            ImGui::Render();
        };
        auto background = [&] {  // stands for the image under the panels
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            glViewport(0, 0, w, h);
            glClearColor(0.3f, 0.6f, 0.2f, 1.0f);
            glClear(GL_COLOR_BUFFER_BIT);
        };
        // Within 1 of ImGui's own drawing: blended edges (the resize grip's) round by 1 in a few
        // channels when drawn into the panel's texture.
        auto near = [](const std::vector<uint8_t>& a, const std::vector<uint8_t>& b) {
            if (a.size() != b.size()) return false;
            for (size_t i = 0; i < a.size(); ++i)
                if (std::abs(int(a[i]) - int(b[i])) > 1) return false;
            return true;
        };
        // The frame's draw data drawn by ImGui's backend, then through the cache, each over the
        // background: both images.
        struct Drawn {
            std::vector<uint8_t> direct, cached;
            size_t covered = 0;  ///< rectangles the cache said its panels fill
        };
        auto drawBoth = [&] {
            Drawn d;
            background();
            ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
            d.direct = gl.read();
            background();
            d.covered = cache.layout(ImGui::GetDrawData(), w, h).size();
            cache.render();
            d.cached = gl.read();
            return d;
        };
        for (int warm = 0; warm < 3; ++warm) frame(0);  // let ImGui settle its layout
        const Drawn first = drawBoth();
        EXPECT_EQ(cache.redrawn(), 2) << "both panels drawn into the layer";
        EXPECT_EQ(first.covered, 2u);
        EXPECT_TRUE(near(first.cached, first.direct)) << "the panels must be ImGui's own pixels";

        frame(0);  // the same content: copied, not drawn again
        const Drawn same = drawBoth();
        EXPECT_EQ(cache.redrawn(), 0);
        EXPECT_TRUE(near(same.cached, first.direct));

        frame(1);  // the counter changes: that panel only
        const Drawn changed = drawBoth();
        EXPECT_FALSE(near(changed.direct, first.direct));
        EXPECT_EQ(cache.redrawn(), 1);
        EXPECT_TRUE(near(changed.cached, changed.direct));

        // A tooltip-like panel appearing, moving and vanishing where no panel is: only it is
        // drawn; the others are copied (all were drawn again before, 11-13 ms under Xvfb).
        const ImVec2 tipAt(290, 20), tipMoved(300, 30);
        for (const ImVec2* at : {&tipAt, &tipMoved}) {
            for (int warm = 0; warm < 2; ++warm) frame(1, at);
            const Drawn tip = drawBoth();
            EXPECT_EQ(cache.redrawn(), 1) << "new or moved: the tip only";
            EXPECT_TRUE(near(tip.cached, tip.direct));
        }
        frame(1);
        const Drawn gone = drawBoth();
        EXPECT_EQ(cache.redrawn(), 0) << "vanished over nothing: nothing drawn again";
        EXPECT_TRUE(near(gone.cached, gone.direct));
        // Moved over the first panel, then gone: the panel it uncovers is drawn again.
        const ImVec2 overFirst(150, 100);
        for (int warm = 0; warm < 2; ++warm) frame(1, &overFirst);
        drawBoth();
        EXPECT_EQ(cache.redrawn(), 1);
        frame(1);
        const Drawn uncovered = drawBoth();
        EXPECT_EQ(cache.redrawn(), 1) << "the first panel, which the tip covered";
        EXPECT_TRUE(near(uncovered.cached, uncovered.direct));

        // With the frame's budget spent a changed panel keeps its last content for the frame,
        // and is drawn in the next one with budget left: then ImGui's own pixels again.
        double now = 0.0;
        FrameBudget budget(33.0, [&] { return now; });
        cache.setFrameBudget(&budget, 5.0);
        budget.begin();
        now = 30.0;
        frame(2);
        const Drawn deferred = drawBoth();
        EXPECT_EQ(cache.redrawn(), 0);
        EXPECT_EQ(cache.deferred(), 1);
        EXPECT_TRUE(near(deferred.cached, changed.direct)) << "the counter's last content";
        EXPECT_FALSE(near(deferred.cached, deferred.direct));
        budget.begin();
        frame(2);
        const Drawn caught = drawBoth();
        EXPECT_EQ(cache.redrawn(), 1);
        EXPECT_EQ(cache.deferred(), 0);
        EXPECT_TRUE(near(caught.cached, caught.direct));
        // A changed panel is drawn again only when its learned cost fits beside the copies'
        // (the test's clock stands still in both, so they were learned cheaper than their
        // first figures): with less left than that, though some is, it waits for a frame that
        // has room, then is ImGui's own pixels again.
        const double redrawMs = cache.redrawEstimateMs(200 * 150);  // the first panel's
        const double copyMs = cache.copyEstimateMs();
        ASSERT_GT(redrawMs, 0.0);
        budget.begin();
        now += 33.0 - 5.0 - copyMs - redrawMs / 2;
        EXPECT_GT(budget.leftMs(5.0), 0.0) << "some budget is left beyond the reserve";
        frame(3);
        const Drawn tight = drawBoth();
        EXPECT_EQ(cache.redrawn(), 0);
        EXPECT_EQ(cache.deferred(), 1);
        EXPECT_TRUE(near(tight.cached, caught.direct)) << "the counter's last content";
        budget.begin();
        frame(3);
        const Drawn roomy = drawBoth();
        EXPECT_EQ(cache.redrawn(), 1);
        EXPECT_TRUE(near(roomy.cached, roomy.direct));
        // What a frame's render() takes in any case, for the steps before it: the copies when no
        // panel must be drawn, and the redraw of the pixels of a panel that appears.
        cache.layout(ImGui::GetDrawData(), w, h);
        EXPECT_DOUBLE_EQ(cache.estimateMs(), cache.copyEstimateMs());
        for (int warm = 0; warm < 2; ++warm) frame(3, &tipAt);
        cache.layout(ImGui::GetDrawData(), w, h);
        EXPECT_DOUBLE_EQ(cache.estimateMs(),
                         cache.copyEstimateMs() + cache.redrawEstimateMs(90 * 50));
        cache.render();
        frame(2);
        drawBoth();
        // A panel that must be drawn (moved, new) is drawn whatever the budget.
        budget.begin();
        now = 1000.0;
        for (int warm = 0; warm < 2; ++warm) frame(2, &tipAt);
        const Drawn must = drawBoth();
        EXPECT_EQ(cache.redrawn(), 1) << "the new tip";
        EXPECT_TRUE(near(must.cached, must.direct));
        frame(2);
        drawBoth();
        cache.setFrameBudget(nullptr, 0.0);

        // A high-density display (ImGui's units are 2 framebuffer pixels): a panel's border
        // reaches a pixel outside its rectangle there, so the panels are drawn directly.
        ImGui::GetIO().DisplaySize = ImVec2(float(w) / 2, float(h) / 2);
        ImGui::GetIO().DisplayFramebufferScale = ImVec2(2.0f, 2.0f);
        for (int warm = 0; warm < 3; ++warm) frame(2);
        const Drawn dense = drawBoth();
        EXPECT_EQ(cache.redrawn(), 0);
        EXPECT_EQ(dense.cached, dense.direct) << "at a framebuffer scale of 2";
        EXPECT_EQ(dense.covered, 0u) << "drawn directly, the panels let the image be drawn whole";
        // Back at scale 1 with the second panel off the right and bottom edges: the layer is
        // drawn again and still matches.
        ImGui::GetIO().DisplaySize = ImVec2(float(w), float(h));
        ImGui::GetIO().DisplayFramebufferScale = ImVec2(1.0f, 1.0f);
        for (int warm = 0; warm < 3; ++warm) frame(3);
        const Drawn again = drawBoth();
        EXPECT_EQ(cache.redrawn(), 2);
        EXPECT_TRUE(near(again.cached, again.direct));
    }
    ImGui_ImplOpenGL3_Shutdown();
    ImGui::DestroyContext();
}

/// Run the whole viewer (panels, progressive render, drawing) until it has settled.
class ViewerFrames : public ::testing::Test {
  protected:
    static constexpr int kW = 900, kH = 560;
    void SetUp() override {
        gl_ = std::make_unique<OffscreenGl>(kW, kH);
        ASSERT_TRUE(gl_->ok());
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr;
        ImGui::GetIO().DisplaySize = ImVec2(float(kW), float(kH));
        ASSERT_TRUE(ImGui_ImplOpenGL3_Init("#version 330 core"));
        settings_.scene = "builtin:default";
        app_ = std::make_unique<ViewerApp>(settings_, false);
    }
    void TearDown() override {
        app_.reset();
        ImGui_ImplOpenGL3_Shutdown();
        ImGui::DestroyContext();
        gl_.reset();
    }
    /// Frames until the render has finished (at most 120 s, so a bug fails instead of hanging; a
    /// loaded 2-core machine took over 30 s for balls:3 on one thread).
    int runUntilSettled() {
        int frames = 0;
        auto start = std::chrono::steady_clock::now();
        do {
            ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
            app_->frame(kW, kH);
            ++frames;
            if (!app_->settled()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        } while ((!app_->settled() || frames < 3) &&
                 std::chrono::steady_clock::now() - start < std::chrono::seconds(120));
        return frames;
    }
    /// The image viewport (framebuffer pixels) of the last frame.
    PixelRect area() const { return app_->state().imageArea(); }
    int imageW() const { return area().x1 - area().x0; }
    int imageH() const { return area().y1 - area().y0; }
    /// Image pixel (x, y) inside the colour keys' box (display units = pixels here).
    bool inKeys(int x, int y) const {
        const Rect& k = app_->keys().box;
        const float wx = float(x + area().x0) + 0.5f, wy = float(y + area().y0) + 0.5f;
        return !k.empty() && wx >= k.x0 && wx < k.x1 && wy >= k.y0 && wy < k.y1;
    }
    /// The framebuffer's pixel `i` of image pixel (x, y).
    size_t windowIndex(int x, int y) const {
        return size_t(y + area().y0) * kW + size_t(x + area().x0);
    }

    std::unique_ptr<OffscreenGl> gl_;
    ViewerSettings settings_;
    std::unique_ptr<ViewerApp> app_;
};

TEST_F(ViewerFrames, ShowListShowsTheInspectorOverTheRightHalf) {
    const std::vector<std::string> left = app_->applyInspectorShow({"inspector", "boxes", "ray"});
    EXPECT_EQ(left, std::vector<std::string>{"ray"});
    EXPECT_TRUE(app_->inspector().options().boxes);
    EXPECT_FALSE(app_->inspector().options().frustum);
    runUntilSettled();
    ASSERT_TRUE(app_->settled());
    ASSERT_TRUE(app_->inspector().shown());
    // Settled means the inspector's surfaces are traced for its camera, and it drew regions.
    EXPECT_TRUE(app_->inspector().surfacesShown());
    EXPECT_FALSE(app_->inspector().model().regions.empty());
    // Beside the panels, the image area shows the traced image, the inspector's view (the
    // right part of what the panels leave) the inspector, not the traced image.
    std::vector<uint8_t> shown = gl_->read();
    Camera cam = app_->camera();
    Traced t = traceCpu("builtin:default", &cam, imageW(), imageH());
    std::vector<uint8_t> cpu = t.img.rgba8();
    const Rect image = app_->layout().image, insp = app_->layout().inspector;
    ASSERT_FALSE(insp.empty());
    ASSERT_LE(image.x1, insp.x0) << "the inspector lies beside the image, not over it";
    // The image viewport is the CPU render at its size; the inspector's view, at the same
    // offsets from its corner, is not.
    size_t image0 = 0, imageSame = 0, insp0 = 0, inspSame = 0;
    for (int y = 0; y < imageH(); ++y)
        for (int x = 0; x < imageW(); ++x) {
            const size_t c = 4 * (size_t(y) * size_t(imageW()) + size_t(x));
            auto same = [&](size_t w) {
                bool eq = true;
                for (int k = 0; k < 3; ++k)
                    eq &= std::abs(int(shown[4 * w + size_t(k)]) - int(cpu[c + size_t(k)])) <= 1;
                return eq;
            };
            ++image0;
            imageSame += same(windowIndex(x, y));
            const int ix = int(insp.x0) + x, iy = int(insp.y0) + y;
            if (ix < int(insp.x1) && iy < int(insp.y1)) {
                ++insp0;
                inspSame += same(size_t(iy) * kW + size_t(ix));
            }
        }
    EXPECT_EQ(imageSame, image0);
    EXPECT_LT(inspSame, insp0 / 2);
}

TEST_F(ViewerFrames, ShowsTheRenderedSceneAndThePanels) {
    runUntilSettled();
    ASSERT_TRUE(app_->settled());
    ASSERT_TRUE(app_->error().empty()) << app_->error();
    // The render is the image viewport's size, which the status line shows.
    ASSERT_EQ(app_->displayed().width, imageW());
    ASSERT_EQ(app_->displayed().height, imageH());
    ASSERT_LT(imageW(), kW);
    std::vector<uint8_t> shown = gl_->read();
    Camera cam = app_->camera();
    Traced t = traceCpu("builtin:default", &cam, imageW(), imageH());
    std::vector<uint8_t> cpu = t.img.rgba8();
    size_t differs = 0;
    for (int y = 0; y < imageH(); ++y)
        for (int x = 0; x < imageW(); ++x) {
            const size_t w = 4 * windowIndex(x, y),
                         c = 4 * (size_t(y) * size_t(imageW()) + size_t(x));
            for (int k = 0; k < 3; ++k)
                differs += std::abs(int(shown[w + size_t(k)]) - int(cpu[c + size_t(k)])) > 1;
        }
    EXPECT_EQ(differs, 0u) << "the image viewport shows the CPU render at its size exactly";
    // The Parameters panel is drawn beside it: its pixels are not the render's.
    const Rect p = app_->layout()[PanelId::Parameters];
    ASSERT_FALSE(p.empty());
    EXPECT_LE(p.x1, float(area().x0));
    size_t panel = 0, panelDiff = 0;
    for (int y = int(p.y0) + 20; y < int(p.y1) - 4; y += 3)
        for (int x = int(p.x0) + 4; x < int(p.x1) - 4; x += 3) {
            const size_t i = 4 * (size_t(y) * kW + size_t(x));
            ++panel;
            panelDiff += shown[i] != 0 || shown[i + 1] != 0 || shown[i + 2] != 0;
        }
    EXPECT_GT(panelDiff, 0u);
    EXPECT_GT(panel, 100u);
}

TEST_F(ViewerFrames, EagerUntilAChangeIsOnScreenThenRefinesAtTheWindowsPace) {
    // What the window's loop reads to pace frames: eager while a build runs or waits and until
    // the new render's first pass is drawn; then, while the passes only refine the image, not;
    // eager again once the render is complete (its last band is drawn at once).
    settings_.threads = 1;  // a render long enough to be seen refining
    app_->openScene("builtin:balls:3");
    runUntilSettled();
    ASSERT_TRUE(app_->settled());
    ASSERT_TRUE(app_->error().empty()) << app_->error();
    EXPECT_FALSE(app_->eager()) << "settled: nothing more to draw";
    app_->rebuild("test");
    EXPECT_TRUE(app_->eager()) << "a build is under way";
    int refiningFrames = 0, eagerWhileRefining = 0;
    bool newJobShown = false;
    const Image before = app_->displayed();
    auto start = std::chrono::steady_clock::now();
    do {  // settled() still describes the frame before the rebuild
        ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
        app_->frame(kW, kH);
        // Until the first pass of the rebuilt structure's render is drawn, the display is the
        // old complete image (the same pixels: only the structure changed).
        if (!newJobShown && app_->displayed().color != before.color) newJobShown = true;
        if (newJobShown && !app_->settled()) {
            ++refiningFrames;
            eagerWhileRefining += app_->eager();
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    } while (!app_->settled() &&
             std::chrono::steady_clock::now() - start < std::chrono::seconds(60));
    ASSERT_TRUE(app_->settled());
    EXPECT_TRUE(newJobShown) << "the coarse passes show as blocks, unlike the full image";
    ASSERT_GT(refiningFrames, 10);
    // Eager only when a finer pass (of stride 4, then 1) or the end arrived between the frame's
    // snapshot and the question: at most 3 times.
    EXPECT_LE(eagerWhileRefining, 3) << refiningFrames << " frames while refining";
    EXPECT_FALSE(app_->eager());
}

TEST_F(ViewerFrames, EagerAsSoonAsAFinerPassIsReady) {
    // A new pass is drawn at once, not at the window's refining pace: once the first pass of a
    // change is on screen, the next one (of stride 4) makes the app eager before the render is
    // complete.
    settings_.threads = 1;
    app_->openScene("builtin:balls:3");
    runUntilSettled();
    ASSERT_TRUE(app_->settled());
    const Image before = app_->displayed();
    app_->rebuild("test");
    auto start = std::chrono::steady_clock::now();
    const auto within = [&] {
        return std::chrono::steady_clock::now() - start < std::chrono::seconds(60);
    };
    while (app_->displayed().color == before.color && within()) {
        ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
        app_->frame(kW, kH);
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    const Image coarse = app_->displayed();
    ASSERT_NE(coarse.color, before.color) << "the first pass shows as blocks";
    ASSERT_FALSE(app_->settled());
    while (!app_->eager() && within()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_TRUE(app_->eager());
    ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
    app_->frame(kW, kH);
    EXPECT_NE(app_->displayed().color, coarse.color) << "the finer pass is drawn";
    EXPECT_FALSE(app_->settled()) << "eager before the render was complete";
    runUntilSettled();
}

TEST_F(ViewerFrames, HeatMapModeShowsPrimitiveTests) {
    runUntilSettled();
    ASSERT_TRUE(app_->settled());
    std::vector<uint8_t> colour = gl_->read();
    app_->setViewMode(ViewMode::RegionVisits);
    app_->setViewMode(ViewMode::PrimTests);
    runUntilSettled();
    std::vector<uint8_t> hot = gl_->read();
    const Image& img = app_->displayed();
    const float scale = app_->heatScale();
    // The 99th percentile, up to a whole decade (the key's scale).
    EXPECT_EQ(scale, decadeScale(autoScale(heatChannel(img, ViewMode::PrimTests))));
    ASSERT_EQ(img.width, imageW());
    int worst = 0;
    size_t changed = 0, n = 0;
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            if (inKeys(x, y)) continue;
            const size_t i = img.index(x, y), w = windowIndex(x, y);
            worst =
                std::max(worst, maxDiff(&hot[4 * w], colormap(float(img.primTests[i]) / scale)));
            changed += std::abs(int(hot[4 * w]) - int(colour[4 * w])) > 8;
            ++n;
        }
    ASSERT_FALSE(app_->keys().keys.empty()) << "the heat map draws its key";
    EXPECT_LE(worst, 2);
    EXPECT_GT(changed, n / 2);
}

TEST_F(ViewerFrames, DragsMoveTheCameraExceptWhenImGuiWantsTheMouse) {
    runUntilSettled();
    ImGuiIO& io = ImGui::GetIO();
    auto frame = [&] {
        io.DeltaTime = 1.0f / 60.0f;
        app_->frame(kW, kH);
    };
    auto drag = [&](float x0, float y0, float x1, float y1) {
        io.MousePos = ImVec2(x0, y0);
        frame();
        io.MouseDown[0] = true;
        frame();
        for (int i = 1; i <= 5; ++i) {
            io.MousePos =
                ImVec2(x0 + (x1 - x0) * float(i) / 5.0f, y0 + (y1 - y0) * float(i) / 5.0f);
            frame();
        }
        io.MouseDown[0] = false;
        frame();
    };
    const Camera home = app_->camera();
    drag(150.0f, 200.0f, 250.0f, 260.0f);  // starts on the Parameters panel: ImGui's
    EXPECT_EQ(app_->camera().from, home.from);
    // Starts on the image, between the columns of panels: orbits about the target.
    drag(450.0f, 300.0f, 530.0f, 300.0f);
    EXPECT_NE(app_->camera().from, home.from);
    EXPECT_EQ(app_->camera().at, home.at);
    EXPECT_NEAR(glm::length(app_->camera().from - home.at), glm::length(home.from - home.at), 1e-9);
    const Camera orbited = app_->camera();
    io.MousePos = ImVec2(450.0f, 300.0f);
    io.MouseWheel = 1.0f;  // zoom in
    frame();
    io.MouseWheel = 0.0f;
    EXPECT_LT(glm::length(app_->camera().from - home.at), glm::length(orbited.from - home.at));
    io.AddInputCharacter('r');  // reset
    frame();
    EXPECT_EQ(app_->camera().from, home.from);
    io.AddInputCharacter('o');  // orthographic
    frame();
    EXPECT_EQ(app_->camera().projection, Projection::Orthographic);
    // The new view is rendered: once settled, the screen shows the orthographic CPU render.
    runUntilSettled();
    Camera cam = app_->camera();
    Traced t = traceCpu("builtin:default", &cam, imageW(), imageH());
    EXPECT_EQ(app_->displayed().color, t.img.color);
}

TEST_F(ViewerFrames, ASceneThatFailsToLoadKeepsThePreviousOne) {
    runUntilSettled();
    auto before = app_->sceneBuild();
    ASSERT_TRUE(before);
    app_->openScene("/nonexistent/scene.nff");
    runUntilSettled();
    EXPECT_NE(app_->error().find("/nonexistent/scene.nff"), std::string::npos) << app_->error();
    EXPECT_EQ(app_->sceneBuild(), before);
    EXPECT_EQ(settings_.scene, "builtin:default");
    // A scheme that cannot be built (or an invalid parameter) keeps the structure too.
    settings_.build.regular.maxLevel = 18;
    app_->openScene("builtin:balls:1");
    runUntilSettled();
    EXPECT_TRUE(app_->error().empty()) << app_->error();
    EXPECT_EQ(settings_.scene, "builtin:balls:1");
}

// The Statistics panel's speedup: both runs trace the same pixels and, giving the same hits,
// the same rays; brute force tests the live primitives for every ray (fewer where a
// difference or intersection has nothing on its left), the scheme far fewer.
TEST_F(ViewerFrames, SpeedupTracesTheSamePixelsAndRaysWithBothSchemes) {
    settings_.build.scheme = SchemeKind::Regular;
    app_->rebuild("scheme");
    runUntilSettled();
    ASSERT_TRUE(app_->sceneBuild());
    ASSERT_EQ(app_->sceneBuild()->accel->params().scheme, SchemeKind::Regular);
    EXPECT_FALSE(app_->speedupResult()) << "nothing measured before it is asked for";
    app_->measureSpeedup(4);
    std::optional<SpeedupResult> r;
    auto start = std::chrono::steady_clock::now();
    while (!(r = app_->speedupResult()) &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
        app_->frame(kW, kH);  // the panel shows the result once done
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_TRUE(r) << "the measurement did not finish";
    ASSERT_TRUE(r->error.empty()) << r->error;
    EXPECT_EQ(r->scheme, "regular");
    const bench::Speedup& m = r->speedup;
    EXPECT_EQ(m.pixels, size_t((imageW() + 3) / 4) * size_t((imageH() + 3) / 4));
    EXPECT_GE(m.scheme.counters.rays, m.pixels);
    EXPECT_EQ(m.scheme.counters.rays, m.brute.counters.rays);
    const Scene& scene = *app_->sceneBuild()->scene;
    EXPECT_LE(m.brute.counters.primTests, m.brute.counters.rays * scene.livePrimitives().size());
    EXPECT_GT(m.brute.counters.primTests, m.brute.counters.rays);
    EXPECT_LT(m.scheme.counters.primTests, m.brute.counters.primTests);
    EXPECT_GT(m.scheme.renderMs, 0.0);
    EXPECT_GT(m.brute.renderMs, 0.0);
}

TEST_F(ViewerFrames, CameraCopiedAsJsonPastesBackAndABadPasteKeepsTheCamera) {
    runUntilSettled();
    // ImGui's clipboard: the app's GLFW backend routes the same calls to the desktop's.
    app_->copyCameraJson();
    const char* clip = ImGui::GetClipboardText();
    ASSERT_NE(clip, nullptr);
    const Camera copied = app_->camera();
    EXPECT_EQ(std::string(clip), copied.toJson());
    ImGui::GetIO().AddInputCharacter('o');  // orthographic: another camera
    ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
    app_->frame(kW, kH);
    ASSERT_EQ(app_->camera().projection, Projection::Orthographic);
    ASSERT_TRUE(app_->pasteCameraJson()) << app_->cameraError();
    EXPECT_EQ(app_->camera().projection, copied.projection);
    EXPECT_EQ(app_->camera().from, copied.from);
    EXPECT_EQ(app_->camera().at, copied.at);
    EXPECT_EQ(app_->camera().fov, copied.fov);
    // Not a camera: refused with the reason, the camera unchanged.
    ImGui::SetClipboardText("{\"fov\": 200}");
    EXPECT_FALSE(app_->pasteCameraJson());
    EXPECT_FALSE(app_->cameraError().empty());
    EXPECT_EQ(app_->camera().fov, copied.fov);
    // The pasted view is the one rendered.
    runUntilSettled();
    Camera cam = app_->camera();
    Traced t = traceCpu("builtin:default", &cam, imageW(), imageH());
    EXPECT_EQ(app_->displayed().color, t.img.color);
}

// A panel showing a texture: the layer knows the texture by its id, so when its pixels change the
// panel is copied stale until the panel says so (PanelCache::invalidate), then drawn again.
TEST(ViewerGl, APanelShowingALiveTextureIsDrawnAgainWhenInvalidated) {
    const int w = 320, h = 240;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::GetIO().DisplaySize = ImVec2(float(w), float(h));
    ASSERT_TRUE(ImGui_ImplOpenGL3_Init("#version 330 core"));
    ImGui::GetStyle().Colors[ImGuiCol_WindowBg].w = 1.0f;
    {
        unsigned tex = 0;
        glGenTextures(1, &tex);
        auto fill = [&](uint8_t r, uint8_t g, uint8_t b) {
            std::vector<uint8_t> px(16 * 16 * 4);
            for (size_t i = 0; i < px.size(); i += 4)
                px[i] = r, px[i + 1] = g, px[i + 2] = b, px[i + 3] = 255;
            glBindTexture(GL_TEXTURE_2D, tex);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 16, 16, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                         px.data());
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            glBindTexture(GL_TEXTURE_2D, 0);
        };
        PanelCache cache;
        unsigned windowId = 0;
        auto frame = [&] {
            ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
            ImGui_ImplOpenGL3_NewFrame();
            ImGui::NewFrame();
            ImGui::SetNextWindowPos(ImVec2(10, 10));
            ImGui::SetNextWindowSize(ImVec2(200, 160));
            ImGui::Begin("inspector");
            windowId = ImGui::GetCurrentWindow()->ID;
            ImGui::Image(ImTextureID(uintptr_t(tex)), ImVec2(100, 100));
            ImGui::End();
            ImGui::Render();
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            glViewport(0, 0, w, h);
            glClearColor(0.3f, 0.6f, 0.2f, 1.0f);
            glClear(GL_COLOR_BUFFER_BIT);
            cache.layout(ImGui::GetDrawData(), w, h);
            cache.render();
            return gl.read();
        };
        // A pixel inside the image, at (60, 80) from the top left.
        auto at = [&](const std::vector<uint8_t>& px) { return &px[4 * (size_t(80) * w + 60)]; };
        fill(255, 0, 0);
        for (int warm = 0; warm < 3; ++warm) frame();
        std::vector<uint8_t> red = frame();
        EXPECT_EQ(cache.redrawn(), 0);
        EXPECT_EQ(at(red)[0], 255);
        EXPECT_EQ(at(red)[1], 0);
        fill(0, 0, 255);  // the same texture id, other pixels: the draw lists are the same
        std::vector<uint8_t> stale = frame();
        EXPECT_EQ(cache.redrawn(), 0);
        EXPECT_EQ(at(stale)[0], 255) << "without invalidate() the layer keeps the old pixels";
        cache.invalidate(windowId);
        std::vector<uint8_t> blue = frame();
        EXPECT_EQ(cache.redrawn(), 1);
        EXPECT_EQ(at(blue)[0], 0);
        EXPECT_EQ(at(blue)[2], 255);
        frame();
        EXPECT_EQ(cache.redrawn(), 0) << "an invalidation holds for one frame";
        glDeleteTextures(1, &tex);
    }
    ImGui_ImplOpenGL3_Shutdown();
    ImGui::DestroyContext();
}

// The log scale: each pixel is the colour map of log(1 + count) / log(1 + scale).
TEST(ViewerGl, HeatMapsOnALogScale) {
    const int w = 160, h = 100;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    Traced t = traceCpu("builtin:default", nullptr, w, h);
    ImageView view;
    std::vector<float> heat = heatChannel(t.img, ViewMode::PrimTests);
    const float scale = autoScale(heat);
    view.upload(t.img, ViewMode::PrimTests);
    view.draw(w, h, ViewMode::PrimTests, scale, {}, true);
    std::vector<uint8_t> shown = gl.read();
    int worst = 0;
    size_t differ = 0;
    for (size_t i = 0; i < heat.size(); ++i) {
        worst = std::max(worst, maxDiff(&shown[4 * i], colormap(heatValue(heat[i], scale, true))));
        differ += heatValue(heat[i], scale, true) != heatValue(heat[i], scale, false);
    }
    EXPECT_LE(worst, 2);
    EXPECT_GT(differ, heat.size() / 2) << "the log scale must differ from the linear one";
}

namespace {
ImGuiWindow* panelWindow(const char* name) {
    ImGuiWindow* w = ImGui::FindWindowByName(name);
    return w && w->Active ? w : nullptr;
}

/// Every panel lies inside the display and, if `apart`, none overlaps another.
void expectPanelsOnScreen(float width, float height, bool apart) {
    std::vector<ImGuiWindow*> shown;
    for (const char* name : {"Parameters", "Camera", "Statistics", "View"}) {
        ImGuiWindow* w = panelWindow(name);
        ASSERT_TRUE(w) << name;
        EXPECT_GE(w->Pos.x, 0.0f) << name;
        EXPECT_GE(w->Pos.y, 0.0f) << name;
        EXPECT_LE(w->Pos.x + w->Size.x, width) << name;
        EXPECT_LE(w->Pos.y + w->Size.y, height) << name;
        shown.push_back(w);
    }
    for (size_t i = 0; apart && i < shown.size(); ++i)
        for (size_t j = i + 1; j < shown.size(); ++j) {
            const ImGuiWindow* a = shown[i];
            const ImGuiWindow* b = shown[j];
            const bool apart = a->Pos.x + a->Size.x <= b->Pos.x ||
                               b->Pos.x + b->Size.x <= a->Pos.x ||
                               a->Pos.y + a->Size.y <= b->Pos.y || b->Pos.y + b->Size.y <= a->Pos.y;
            EXPECT_TRUE(apart) << a->Name << " overlaps " << b->Name;
        }
}
}  // namespace

// Panels are as tall as their content (bounces and the speedup result are never under a
// scrollbar or another panel while the window has room) and stay on screen when it shrinks.
TEST_F(ViewerFrames, PanelsFitTheirContentAndStayOnScreen) {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(1280.0f, 720.0f);  // a 1280 x 720 window (the buffer is smaller)
    runUntilSettled();
    app_->measureSpeedup(4);
    auto start = std::chrono::steady_clock::now();
    while (!app_->speedupResult() &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
        app_->frame(kW, kH);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_TRUE(app_->speedupResult());
    // The layout follows the content a frame late, and ImGui's scrollbar the size a frame later.
    for (int i = 0; i < 4; ++i) app_->frame(kW, kH);
    expectPanelsOnScreen(1280.0f, 720.0f, true);
    for (const char* name : {"Parameters", "Camera", "Statistics", "View"})
        EXPECT_FALSE(panelWindow(name)->ScrollbarY)
            << name << " needs a scrollbar at 1280 x 720: " << panelWindow(name)->Size.y << " for "
            << panelWindow(name)->ContentSize.y;

    // A smaller window: the right column follows its edge, every panel stays inside (the
    // panels no longer all fit: the last one scrolls, over another if it must).
    io.DisplaySize = ImVec2(700.0f, 520.0f);
    for (int i = 0; i < 3; ++i) app_->frame(700, 520);
    expectPanelsOnScreen(700.0f, 520.0f, false);
    io.DisplaySize = ImVec2(float(kW), float(kH));
    runUntilSettled();
}

// The image step's GL work is finished and learned in every frame, and the steps before it
// keep back its learned cost with room for the inspector's pieces when that is more than
// their fixed 9 ms (with the inspector shown, that flush was 3-7 ms of its step on balls4,
// which no learned cost covered).
TEST_F(ViewerFrames, TheImagesFlushIsLearnedAndKeptBackWhenMoreThanTheFixedReserve) {
    EXPECT_DOUBLE_EQ(app_->imageFlushEstimateMs(), 6.0) << "the figure until measured";
    app_->frame(kW, kH);
    EXPECT_NE(app_->imageFlushEstimateMs(), 6.0) << "measured in the frame";
    EXPECT_DOUBLE_EQ(ViewerApp::layerReserveMs(0.0), 9.0);
    EXPECT_DOUBLE_EQ(ViewerApp::layerReserveMs(6.0), 9.0);
    EXPECT_DOUBLE_EQ(ViewerApp::layerReserveMs(10.0), 13.0);
}

// With every frame's budget spent (a clock that moves 40 ms at each reading: no part of any
// step ever fits), every step the budget defers still makes progress, each after
// kPatienceFrames frames of waiting at most: once the render is done the image shows whole,
// the overlay layer is made and drawn whole, the inspector's picture completes and no panel
// waits, within a bounded number of frames. Without that bound the layer's texture, its
// first part, the inspector's first piece and a changed panel waited for ever: the viewer
// never settled (a quiet machine's run on balls4 went on for over 10 minutes, 2026-12-07).
TEST_F(ViewerFrames, WithEveryFramesBudgetSpentEveryStepStillCompletesWithinBoundedFrames) {
    double now = 0.0;
    app_->frameBudget() = FrameBudget(kFrameBudgetMs, [&] { return now += 40.0; });
    app_->overlays().options.leaves = true;
    app_->applyInspectorShow({"inspector"});
    // Frames after the render is done: what is left of the layer's texture and parts, the
    // inspector's framebuffer, pieces and the image's showing, each after its patience. Most
    // runs need 1 frame (the rest came while the render ran); a render done in the first
    // frames leaves them all, one part every kPatienceFrames + 1 frames (61 frames in one run,
    // the inspector's two storages and 24 bands of surfaces among them).
    constexpr int kBound = 120;
    int frames = 0, rendered = -1;
    const auto start = std::chrono::steady_clock::now();
    while (std::chrono::steady_clock::now() - start < std::chrono::seconds(120)) {
        ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
        app_->frame(kW, kH);
        ++frames;
        if (app_->settled() && frames >= 3) break;
        if (rendered < 0 && app_->state().settledSince()) rendered = frames;
        if (rendered >= 0 && frames - rendered > 2 * kBound) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    EXPECT_TRUE(app_->settled()) << frames << " frames, the render done at frame " << rendered;
    EXPECT_GE(rendered, 0) << "the render finished";
    EXPECT_LE(frames - rendered, kBound) << "the steps left when the render was done";
    EXPECT_GT(app_->overlays().layerVersion(), 0u);
    EXPECT_FALSE(app_->overlays().layerPending());
    EXPECT_FALSE(app_->inspector().picturePending());
    app_->frameBudget() = FrameBudget(kFrameBudgetMs);  // `now` goes out of scope
}

// An error line appearing in Parameters does not move the controls under it.
TEST_F(ViewerFrames, TheErrorLineIsReservedSoTheControlsStayPut) {
    runUntilSettled();
    ASSERT_TRUE(app_->error().empty());
    const float before = panelWindow("Parameters")->Size.y;
    app_->openScene("/nonexistent/scene.nff");
    runUntilSettled();
    for (int i = 0; i < 3; ++i) app_->frame(kW, kH);
    ASSERT_FALSE(app_->error().empty());
    EXPECT_EQ(panelWindow("Parameters")->Size.y, before);
}

// The overlays' and the inspector's options and the inspector's camera are written to ImGui's
// ini and come back in a new viewer that loads it.
TEST_F(ViewerFrames, OverlayAndInspectorSettingsComeBackFromTheIni) {
    registerSettingsHandler(&settings_);
    app_->showInspector(true);
    runUntilSettled();
    overlay::OverlayOptions& o = app_->overlays().options;
    o.leaves = o.grid = true;
    o.cap = 4321;
    o.levelMax = 7;
    app_->overlays().look.lineOpacity = 0.5f;
    inspector::InspectorOptions& io = app_->inspector().options();
    io.boxes = true;
    io.levelHi = 5;
    io.colorBy = inspector::ColorBy::Level;
    app_->inspector().changed();
    Camera ic = app_->inspector().camera();
    orbit(ic, 0.3, 0.1);
    app_->inspector().setCamera(ic);
    app_->frame(kW, kH);
    const overlay::OverlayOptions savedOverlays = o;
    const inspector::InspectorOptions savedInspector = io;
    const std::string ini = ImGui::SaveIniSettingsToMemory();

    // A new run: a new context and settings, the ini loaded before the viewer starts.
    app_.reset();
    ImGui_ImplOpenGL3_Shutdown();
    ImGui::DestroyContext();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::GetIO().DisplaySize = ImVec2(float(kW), float(kH));
    ASSERT_TRUE(ImGui_ImplOpenGL3_Init("#version 330 core"));
    settings_ = ViewerSettings{};
    registerSettingsHandler(&settings_);
    ImGui::LoadIniSettingsFromMemory(ini.c_str(), ini.size());
    app_ = std::make_unique<ViewerApp>(settings_, false);
    runUntilSettled();
    EXPECT_TRUE(app_->overlays().options == savedOverlays);
    EXPECT_EQ(app_->overlays().look.lineOpacity, 0.5f);
    EXPECT_TRUE(app_->inspector().shown());
    EXPECT_TRUE(app_->inspector().options() == savedInspector);
    // The camera the inspector was left with, not one framed afresh on the structure.
    EXPECT_EQ(app_->inspector().camera().toJson(), ic.toJson());
}

// Tab hides every panel (and the menu bar): the window shows the render alone; Tab again
// brings them back.
TEST_F(ViewerFrames, TabHidesThePanels) {
    settings_.showRay = true;  // the playback's panel hides with the others
    runUntilSettled();
    EXPECT_TRUE(panelWindow("Ray"));
    ImGuiIO& io = ImGui::GetIO();
    io.KeyMap[ImGuiKey_Tab] = 9;  // as a platform backend maps its keys
    auto tab = [&] {
        io.KeysDown[9] = true;
        io.DeltaTime = 1.0f / 60.0f;
        app_->frame(kW, kH);
        io.KeysDown[9] = false;
        app_->frame(kW, kH);
    };
    tab();
    EXPECT_TRUE(app_->state().panelsHidden());
    runUntilSettled();
    Camera cam = app_->camera();
    Traced t = traceCpu("builtin:default", &cam, kW, kH);
    std::vector<uint8_t> shown = gl_->read(), cpu = t.img.rgba8();
    size_t differing = 0;
    for (size_t i = 0; i < shown.size(); i += 4)
        for (size_t c = 0; c < 3; ++c)
            differing += std::abs(int(shown[i + c]) - int(cpu[i + c])) > 1;
    EXPECT_EQ(differing, 0u) << "with the panels hidden, every pixel is the render's";
    tab();
    EXPECT_FALSE(app_->state().panelsHidden());
    runUntilSettled();
    EXPECT_TRUE(panelWindow("Parameters"));
    EXPECT_TRUE(panelWindow("Ray"));
}

// What the panels said of a scene goes with it: the speedup result, a camera paste's error and
// the screenshot note.
TEST_F(ViewerFrames, ASceneChangeClearsWhatThePanelsSaidOfTheLastOne) {
    runUntilSettled();
    app_->measureSpeedup(8);
    auto start = std::chrono::steady_clock::now();
    while (!app_->speedupResult() &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
        app_->frame(kW, kH);
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    ASSERT_TRUE(app_->speedupResult());
    ImGui::SetClipboardText("not a camera");
    EXPECT_FALSE(app_->pasteCameraJson());
    ASSERT_FALSE(app_->cameraError().empty());
    const std::string shot = ::testing::TempDir() + "lancer-clear-test.png";
    app_->state().notes().pendingScreenshot = shot;
    app_->frame(kW, kH);
    ASSERT_EQ(app_->state().notes().screenshotNote, "saved " + shot);
    std::remove(shot.c_str());
    app_->openScene("builtin:balls:1");
    runUntilSettled();
    ASSERT_EQ(settings_.scene, "builtin:balls:1");
    EXPECT_FALSE(app_->speedupResult());
    EXPECT_TRUE(app_->cameraError().empty());
    EXPECT_TRUE(app_->state().notes().screenshotNote.empty());
}

// A scene that cannot be opened at start: the error shows, and nothing claims to be rendering.
TEST_F(ViewerFrames, ASceneThatNeverLoadedShowsNoRenderInProgress) {
    app_.reset();
    settings_.scene = "/no/such/file.nff";
    app_ = std::make_unique<ViewerApp>(settings_, false);
    runUntilSettled();
    EXPECT_TRUE(app_->settled());
    EXPECT_FALSE(app_->sceneBuild());
    EXPECT_NE(app_->error().find("/no/such/file.nff"), std::string::npos) << app_->error();
    EXPECT_FALSE(app_->state().rendering());
}

}  // namespace
}  // namespace lancer::viewer
