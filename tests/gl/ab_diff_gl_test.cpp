// The rebuild A/B driven through the whole viewer in an OSMesa context: a rebuild from one
// max-level to another keeps the old image's counters, and the diff drawn is old minus new of
// two renders made independently with the engine's renderer at the same parameters; a rebuild
// before the old image is complete gives no diff.
#include "app/viewer/gl.h"
// (kept apart so the include sorter leaves this order)
#include <GL/osmesa.h>
#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_impl_opengl3.h>

#include <chrono>
#include <thread>

#include "app/viewer/viewer_app.h"
#include "engine/scene/loader.h"
#include "tests/gl/offscreen_gl.h"

namespace lancer::viewer {
namespace {

using testing::OffscreenGl;

class AbFrames : public ::testing::Test {
  protected:
    static constexpr int kW = 400, kH = 260;
    void SetUp() override {
        gl_ = std::make_unique<OffscreenGl>(kW, kH);
        ASSERT_TRUE(gl_->ok());
        ImGui::CreateContext();
        ImGui::GetIO().IniFilename = nullptr;
        ImGui::GetIO().DisplaySize = ImVec2(float(kW), float(kH));
        ASSERT_TRUE(ImGui_ImplOpenGL3_Init("#version 330 core"));
        settings_.scene = "builtin:balls:2";
        settings_.build.scheme = SchemeKind::Regular;
        settings_.build.regular.maxLevel = 3;
        app_ = std::make_unique<ViewerApp>(settings_, false);
        app_->state().setPanelsHidden(true);  // every pixel is the image's
    }
    void TearDown() override {
        app_.reset();
        ImGui_ImplOpenGL3_Shutdown();
        ImGui::DestroyContext();
        gl_.reset();
    }
    /// Pixel `i` of the window (the image, panels hidden) lies under the colour keys' box.
    bool inKeys(size_t i) const {
        const Rect& k = app_->keys().box;
        const float x = float(i % kW) + 0.5f, y = float(i / kW) + 0.5f;
        return !k.empty() && x >= k.x0 && x < k.x1 && y >= k.y0 && y < k.y1;
    }
    void frame() {
        ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
        app_->frame(kW, kH);
    }
    void runUntilSettled() {
        int frames = 0;
        auto start = std::chrono::steady_clock::now();
        do {
            frame();
            ++frames;
            if (!app_->settled()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        } while ((!app_->settled() || frames < 3) &&
                 std::chrono::steady_clock::now() - start < std::chrono::seconds(120));
        ASSERT_TRUE(app_->settled());
    }
    /// The engine's render of the viewer's view, with the structure of `maxLevel`.
    Image engineRender(int maxLevel) const {
        const Scene scene = loadScene(settings_.scene);
        BuildParams p = settings_.build;
        p.regular.maxLevel = maxLevel;
        const std::unique_ptr<Accelerator> accel = buildAccelerator(scene, p);
        RenderOptions opt;
        opt.width = kW;
        opt.height = kH;
        opt.shading = settings_.shading;
        opt.camera = app_->camera();
        Image img(kW, kH);
        render(scene, *accel, opt, img);
        return img;
    }

    std::unique_ptr<OffscreenGl> gl_;
    ViewerSettings settings_;
    std::unique_ptr<ViewerApp> app_;
};

TEST_F(AbFrames, TheDiffAfterAMaxLevelRebuildIsOldMinusNewOfTheEngineRenders) {
    runUntilSettled();
    app_->setViewMode(ViewMode::PrimTests);
    app_->setAbView(compare::AbView::Diff);
    frame();
    EXPECT_FALSE(app_->state().abStatus().comparable) << "nothing to compare before a rebuild";
    // The Parameters panel's change: max-level 3 -> 10.
    settings_.build.regular.maxLevel = 10;
    app_->rebuild("max-level");
    runUntilSettled();
    ASSERT_EQ(app_->sceneBuild()->accel->params().regular.maxLevel, 10);
    const compare::AbStatus& status = app_->state().abStatus();
    ASSERT_TRUE(status.comparable) << status.note;
    EXPECT_EQ(status.rows, kH);
    EXPECT_TRUE(status.note.empty()) << status.note;

    const Image a = engineRender(3), b = engineRender(10);
    const compare::CounterImage* old = app_->state().abOld();
    ASSERT_NE(old, nullptr);
    EXPECT_EQ(old->params.regular.maxLevel, 3);
    EXPECT_EQ(old->primTests, a.primTests) << "A holds the old structure's counters";
    EXPECT_EQ(old->regionVisits, a.regionVisits);
    EXPECT_EQ(app_->displayed().primTests, b.primTests);
    // The diff's values, as uploaded, are old minus new; and the drawn pixels their colours.
    const std::vector<float> diff = app_->state().heatRows(0, -1);
    ASSERT_EQ(diff.size(), size_t(kW) * kH);
    size_t better = 0, worse = 0;
    for (size_t i = 0; i < diff.size(); ++i) {
        ASSERT_EQ(diff[i], float(double(a.primTests[i]) - double(b.primTests[i]))) << "pixel " << i;
        better += diff[i] > 0.0f;
        worse += diff[i] < 0.0f;
    }
    EXPECT_GT(better, diff.size() / 4) << "a finer structure tests fewer primitives";
    EXPECT_TRUE(app_->state().heatDiverging());
    const float scale = app_->heatScale();
    EXPECT_EQ(scale, decadeScale(compare::diffAutoScale(diff)));
    const std::vector<uint8_t> px = gl_->read();
    int worst = 0;
    for (size_t i = 0; i < diff.size(); ++i) {
        if (inKeys(i)) continue;
        const glm::vec3 c = divergingColor(diffValue(diff[i], scale, false));
        for (int k = 0; k < 3; ++k)
            worst = std::max(
                worst, std::abs(int(px[4 * i + size_t(k)]) - int(std::lround(c[k] * 255.0f))));
    }
    EXPECT_LE(worst, 2) << "each pixel is the diverging colour of its difference";

    // Totals: the sums of the two renders' counters, and per ray from the passes' counters.
    const AbTotals& t = app_->state().abTotals();
    ASSERT_TRUE(t.complete);
    uint64_t sa = 0, sb = 0;
    for (size_t i = 0; i < diff.size(); ++i) sa += a.primTests[i], sb += b.primTests[i];
    EXPECT_EQ(t.a.primTests, sa);
    EXPECT_EQ(t.b.primTests, sb);
    EXPECT_EQ(t.aCounters.primTests, sa) << "the passes' counters add up to the pixels'";
    EXPECT_EQ(t.bCounters.primTests, sb);

    // Flipped: the old image's counters, then the new one's, on one scale.
    app_->setAbView(compare::AbView::Old);
    frame();
    EXPECT_FALSE(app_->state().heatDiverging());
    const std::vector<float> oldHeat = app_->state().heatRows(0, -1);
    for (size_t i = 0; i < oldHeat.size(); ++i) ASSERT_EQ(oldHeat[i], float(a.primTests[i]));
    const float oldScale = app_->heatScale();
    const std::vector<uint8_t> oldPx = gl_->read();
    for (size_t i = 0; i < oldHeat.size(); i += 97) {
        if (inKeys(i)) continue;
        const glm::vec3 c = colormap(oldHeat[i] / oldScale);
        for (int k = 0; k < 3; ++k)
            ASSERT_LE(std::abs(int(oldPx[4 * i + size_t(k)]) - int(std::lround(c[k] * 255.0f))), 2);
    }
    ImGui::GetIO().AddInputCharacter('b');  // the B key flips to the new image
    frame();
    EXPECT_EQ(app_->state().abView(), compare::AbView::New);
    EXPECT_EQ(app_->heatScale(), oldScale) << "old and new share their scale";

    // Another camera: the pixels are other rays, nothing compares.
    Camera moved = app_->camera();
    moved.from.x += 0.5;
    app_->setCamera(moved);
    runUntilSettled();
    EXPECT_FALSE(app_->state().abStatus().comparable);
}

TEST_F(AbFrames, ARebuildBeforeTheOldImageIsCompleteGivesNoDiff) {
    app_.reset();
    settings_.threads = 1;
    settings_.scene = "builtin:balls:3";  // long enough a render to rebuild in the middle of it
    app_ = std::make_unique<ViewerApp>(settings_, false);
    app_->state().setPanelsHidden(true);
    app_->setViewMode(ViewMode::PrimTests);
    app_->setAbView(compare::AbView::Diff);
    auto start = std::chrono::steady_clock::now();
    while (app_->state().shownJob() == 0 &&  // no snapshot yet (the image is made ahead)
           std::chrono::steady_clock::now() - start < std::chrono::seconds(60)) {
        frame();
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    ASSERT_TRUE(app_->state().rendering()) << "the first image must still be rendering";
    settings_.build.regular.maxLevel = 10;
    app_->rebuild("max-level");
    runUntilSettled();
    const compare::AbStatus& status = app_->state().abStatus();
    EXPECT_FALSE(status.comparable);
    EXPECT_EQ(app_->state().abOld(), nullptr);
    EXPECT_NE(status.note.find("no complete old image to compare"), std::string::npos)
        << status.note;
    // Nothing is drawn as a difference: every value says "not compared", drawn as grey stripes.
    const std::vector<float> diff = app_->state().heatRows(0, -1);
    ASSERT_EQ(diff.size(), size_t(kW) * kH);
    for (float d : diff) ASSERT_EQ(d, kNoDiff);
    const std::vector<uint8_t> px = gl_->read();
    for (size_t i = 0; i < diff.size(); i += 37) {
        if (inKeys(i)) continue;
        ASSERT_EQ(px[4 * i], px[4 * i + 1]);
        ASSERT_EQ(px[4 * i], px[4 * i + 2]);
        ASSERT_LT(px[4 * i], 80) << "dark grey, unlike the map's near-white 'no change'";
    }
    // The next rebuild, with the new image complete, compares.
    settings_.build.regular.maxLevel = 12;
    app_->rebuild("max-level");
    runUntilSettled();
    EXPECT_TRUE(app_->state().abStatus().comparable) << app_->state().abStatus().note;
}

}  // namespace
}  // namespace lancer::viewer
