// The docked layout driven through the whole viewer in an OSMesa context, at 1280x720 and
// 1920x1080, with the inspector shown or not: the panels, the image viewport and the inspector
// are disjoint and inside the window; the viewport shows `lancer render` at its size, and the
// overlays' lines fall on the pixels their world points project to, offset by the viewport's
// corner; the colour keys are drawn in the viewport with the colours they name; the Ray panel's
// step list holds at least 8 lines with the panels as a first run opens them.
#include "app/viewer/gl.h"
// (kept apart so the include sorter leaves this order)
#include <GL/osmesa.h>
#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>  // the windows ImGui drew, and their rectangles

#include <chrono>
#include <cstring>
#include <thread>

#include "app/viewer/gl/transforms.h"
#include "app/viewer/viewer_app.h"
#include "engine/accel/accelerator.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "tests/gl/offscreen_gl.h"

namespace lancer::viewer {
namespace {

using testing::OffscreenGl;

struct LayoutCase {
    int w, h;
    bool inspector;
};

std::string caseName(const ::testing::TestParamInfo<LayoutCase>& p) {
    return std::to_string(p.param.w) + "x" + std::to_string(p.param.h) +
           (p.param.inspector ? "_inspector" : "");
}

class DockedLayout : public ::testing::TestWithParam<LayoutCase> {
  protected:
    void SetUp() override {
        const LayoutCase c = GetParam();
        gl_ = std::make_unique<OffscreenGl>(c.w, c.h);
        ASSERT_TRUE(gl_->ok());
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr;
        ImGui::GetIO().DisplaySize = ImVec2(float(c.w), float(c.h));
        ASSERT_TRUE(ImGui_ImplOpenGL3_Init("#version 330 core"));
        settings_.scene = "builtin:default";
        settings_.build.scheme = SchemeKind::Regular;
        settings_.showInspector = c.inspector;
        settings_.overlays.leaves = true;  // leaves by level: a key and lines to find
        app_ = std::make_unique<ViewerApp>(settings_, false);
    }
    void TearDown() override {
        app_.reset();
        ImGui_ImplOpenGL3_Shutdown();
        ImGui::DestroyContext();
        gl_.reset();
    }
    void runUntilSettled() {
        int frames = 0;
        const auto start = std::chrono::steady_clock::now();
        do {
            ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
            app_->frame(GetParam().w, GetParam().h);
            ++frames;
            if (!app_->settled()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        } while ((!app_->settled() || frames < 5) &&
                 std::chrono::steady_clock::now() - start < std::chrono::seconds(120));
        ASSERT_TRUE(app_->settled());
    }
    /// The top-level windows ImGui drew this frame, but the keys (which lie on the image by
    /// design) and the menu bar (above the viewport).
    std::vector<ImGuiWindow*> panelWindows() const {
        std::vector<ImGuiWindow*> out;
        for (ImGuiWindow* w : ImGui::GetCurrentContext()->Windows)
            if (w->WasActive && !w->Hidden && !(w->Flags & ImGuiWindowFlags_ChildWindow) &&
                !(w->Flags & ImGuiWindowFlags_Tooltip) &&
                std::strcmp(w->Name, "##colour keys") != 0 &&
                std::strcmp(w->Name, "##MainMenuBar") != 0 &&
                std::strncmp(w->Name, "Debug##", 7) != 0)
                out.push_back(w);
        return out;
    }

    std::unique_ptr<OffscreenGl> gl_;
    ViewerSettings settings_;
    std::unique_ptr<ViewerApp> app_;
};

TEST_P(DockedLayout, NothingCoversTheImageAndItsPixelsAreTheRendersAtItsSize) {
    runUntilSettled();
    const LayoutCase c = GetParam();
    const PanelLayout& l = app_->layout();
    const Rect window{0.0f, 0.0f, float(c.w), float(c.h)};
    ASSERT_FALSE(l.image.empty());
    EXPECT_TRUE(window.contains(l.image)) << l.image.toString();
    EXPECT_EQ(l.inspector.empty(), !c.inspector);
    if (c.inspector) {
        EXPECT_TRUE(window.contains(l.inspector)) << l.inspector.toString();
        EXPECT_FALSE(l.image.overlaps(l.inspector));
    }
    // Every panel (and handle) ImGui drew lies inside the window, off the image and the
    // inspector, and apart from the others.
    const std::vector<ImGuiWindow*> panels = panelWindows();
    EXPECT_GE(panels.size(), 4u);
    for (size_t i = 0; i < panels.size(); ++i) {
        const ImGuiWindow* w = panels[i];
        const Rect r{w->Pos.x, w->Pos.y, w->Pos.x + w->Size.x, w->Pos.y + w->Size.y};
        EXPECT_TRUE(window.contains(r)) << w->Name << " " << r.toString();
        EXPECT_FALSE(r.overlaps(l.image)) << w->Name << " " << r.toString() << " over the image";
        EXPECT_FALSE(r.overlaps(l.inspector)) << w->Name << " over the inspector";
        for (size_t j = i + 1; j < panels.size(); ++j) {
            const ImGuiWindow* o = panels[j];
            const Rect q{o->Pos.x, o->Pos.y, o->Pos.x + o->Size.x, o->Pos.y + o->Size.y};
            EXPECT_FALSE(r.overlaps(q)) << w->Name << " overlaps " << o->Name;
        }
    }
    // The render is the viewport's size.
    const PixelRect a = app_->state().imageArea();
    const int iw = a.x1 - a.x0, ih = a.y1 - a.y0;
    EXPECT_EQ(float(iw), l.image.width());
    EXPECT_EQ(float(ih), l.image.height());
    ASSERT_EQ(app_->displayed().width, iw);
    ASSERT_EQ(app_->displayed().height, ih);
    const Scene scene = loadScene(settings_.scene);
    const std::unique_ptr<Accelerator> accel = buildAccelerator(scene, settings_.build);
    RenderOptions opt;
    opt.width = iw;
    opt.height = ih;
    opt.shading = settings_.shading;
    opt.camera = app_->camera();
    Image cpu(iw, ih);
    render(scene, *accel, opt, cpu);
    EXPECT_EQ(app_->displayed().color, cpu.color) << "the viewer's rays are `render`'s";

    // The leaves' lines land where their edges project in the image, shifted by the
    // viewport's corner: near each visible edge's midpoint a pixel differs from the render.
    const std::vector<uint8_t> shown = gl_->read(), plain = cpu.rgba8();
    const StructureView* sv = app_->overlays().view();
    ASSERT_NE(sv, nullptr);
    const gl::ImageProjector proj(app_->camera(), iw, ih);
    const Rect& keys = app_->keys().box;
    size_t edges = 0, found = 0;
    for (uint32_t r = 0; r < sv->regionCount(); ++r) {
        const std::array<Vec3, 8> k = sv->regionCorners(r);
        for (int e = 0; e < 8; ++e)
            for (int bit : {1, 2, 4}) {
                if (e & bit) continue;
                const auto m = proj.toImage(0.5 * (k[size_t(e)] + k[size_t(e | bit)]));
                if (!m || m->x < 3 || m->y < 3 || m->x > iw - 4 || m->y > ih - 4) continue;
                const float wx = float(a.x0) + float(m->x), wy = float(a.y0) + float(m->y);
                if (wx >= keys.x0 - 3 && wx < keys.x1 + 3 && wy >= keys.y0 - 3 && wy < keys.y1 + 3)
                    continue;
                ++edges;
                bool lit = false;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int x = int(m->x) + dx, y = int(m->y) + dy;
                        const size_t wi = 4 * (size_t(y + a.y0) * size_t(c.w) + size_t(x + a.x0));
                        const size_t ci = 4 * (size_t(y) * size_t(iw) + size_t(x));
                        int d = 0;
                        for (int ch = 0; ch < 3; ++ch)
                            d = std::max(d, std::abs(int(shown[wi + size_t(ch)]) -
                                                     int(plain[ci + size_t(ch)])));
                        lit |= d > 40;
                    }
                found += lit;
            }
    }
    EXPECT_GE(edges, 4u);
    EXPECT_GE(found * 10, edges * 9) << found << " of " << edges << " edge midpoints drawn";
}

TEST_P(DockedLayout, TheKeysAreInTheImageViewportAndDrawTheColoursTheyName) {
    app_->setViewMode(ViewMode::PrimTests);  // a heat map's key too
    runUntilSettled();
    const KeyReport& r = app_->keys();
    ASSERT_FALSE(r.box.empty());
    EXPECT_TRUE(app_->layout().image.contains(r.box)) << r.box.toString();
    ASSERT_EQ(r.keys.size(), 2u);
    EXPECT_EQ(r.keys[0].title, "leaf level");
    EXPECT_NE(r.keys[1].title.find("primitive tests per pixel"), std::string::npos);
    // Leaves by their absolute level: a swatch per level drawn, in the fixed palette.
    const StructureView* sv = app_->overlays().view();
    ASSERT_NE(sv, nullptr);
    int lo = 1 << 30, hi = -1;
    for (uint32_t i = 0; i < sv->regionCount(); ++i) {
        lo = std::min(lo, sv->leafLevel(i));
        hi = std::max(hi, sv->leafLevel(i));
    }
    ASSERT_EQ(r.keys[0].swatches.size(), size_t(hi - lo + 1));
    for (int level = lo; level <= hi; ++level) {
        const KeySwatch& s = r.keys[0].swatches[size_t(level - lo)];
        EXPECT_EQ(s.label, std::to_string(level));
        EXPECT_EQ(s.color, levelColor(level));
    }
    // The heat map's swatches are the map's colours at their values on the scale in use.
    const std::vector<KeySwatch>& heat = r.keys[1].swatches;
    ASSERT_GE(heat.size(), 3u);
    EXPECT_EQ(heat.front().color, colormap(0.0f));
    EXPECT_EQ(heat.back().color, colormap(1.0f));
    // Sampled pixels: each swatch's corner holds its colour (labels are drawn in the middle).
    const std::vector<uint8_t> px = gl_->read();
    for (const Key& k : r.keys)
        for (const KeySwatch& s : k.swatches) {
            const int x = int(s.rect.x0) + 1, y = int(s.rect.y0) + 1;
            const uint8_t* p = &px[4 * (size_t(y) * size_t(GetParam().w) + size_t(x))];
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(int(p[ch]), int(std::lround(s.color[ch] * 255.0f)), 1)
                    << k.title << " " << s.label;
        }
}

TEST_P(DockedLayout, TheRayPanelsStepListHoldsAtLeastEightLines) {
    // A first run's panels (the Overlays panel folded), then a pick: the Ray and Selection
    // panels open as a user's Shift+click opens them.
    settings_.overlays.leaves = false;
    runUntilSettled();
    const PixelRect a = app_->state().imageArea();
    app_->pickPixel((a.x1 - a.x0) / 2, (a.y1 - a.y0) * 2 / 3, 0, 0);  // the green box
    runUntilSettled();
    ASSERT_FALSE(app_->rayPlayer().playback().empty()) << app_->rayPlayer().note();
    const ImGuiWindow* steps = nullptr;
    for (ImGuiWindow* w : ImGui::GetCurrentContext()->Windows)
        if (w->WasActive && std::strncmp(w->Name, "Ray/steps", 9) == 0) steps = w;
    ASSERT_NE(steps, nullptr) << "the step list is drawn";
    // Inside its border and padding, and within the window: what a user sees of it.
    const float bottom = std::min(steps->Pos.y + steps->Size.y, float(GetParam().h));
    const float lines = (bottom - steps->Pos.y - 2.0f * ImGui::GetStyle().WindowPadding.y) /
                        ImGui::GetTextLineHeightWithSpacing();
    EXPECT_GE(lines, 8.0f) << "the step list is " << steps->Size.y << " units high";
    // And the Ray panel is whole inside the window, clear of the image.
    const Rect& ray = app_->layout()[PanelId::Ray];
    EXPECT_FALSE(ray.empty());
    EXPECT_FALSE(ray.overlaps(app_->layout().image));
}

INSTANTIATE_TEST_SUITE_P(Sizes, DockedLayout,
                         ::testing::Values(LayoutCase{1280, 720, false},
                                           LayoutCase{1280, 720, true},
                                           LayoutCase{1920, 1080, false},
                                           LayoutCase{1920, 1080, true}),
                         caseName);

}  // namespace
}  // namespace lancer::viewer
