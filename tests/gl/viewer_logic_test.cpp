// The viewer's camera controls, camera JSON and saved settings (no GL needed, but they live in
// the viewer library this binary links).
#include <gtest/gtest.h>

#include <random>

#include "app/viewer/camera_control.h"
#include "app/viewer/image_view.h"
#include "app/viewer/viewer_settings.h"
#include "engine/scene/scene.h"

namespace lancer::viewer {
namespace {

Camera sample() {
    Camera c;
    c.from = {1.5, -10.0, 4.5};
    c.at = {0.0, 0.0, -0.2};
    c.up = {0.0, 0.0, 1.0};
    c.fov = 38.0;
    return c;
}

TEST(CameraControl, OrbitKeepsTheDistanceAndTheTarget) {
    Camera c = sample();
    double d = glm::length(c.from - c.at);
    orbit(c, 0.7, 0.3);
    EXPECT_NEAR(glm::length(c.from - c.at), d, 1e-9);
    EXPECT_EQ(c.at, sample().at);
    EXPECT_TRUE(c.validate().empty());
    // Pitching far past the pole stops short of it: the view never looks along `up`.
    orbit(c, 0.0, 10.0);
    Vec3 f = glm::normalize(c.at - c.from);
    EXPECT_LT(std::abs(glm::dot(f, c.up)), std::cos(glm::radians(0.5)));
    EXPECT_TRUE(c.validate().empty());
}

TEST(CameraControl, PanMovesEyeAndTargetTogetherInTheImagePlane) {
    Camera c = sample();
    Vec3 f, r, u;
    c.basis(f, r, u);
    pan(c, 100.0, 0.0, 500);
    Vec3 move = c.at - sample().at;
    EXPECT_NEAR(glm::length((c.from - sample().from) - move), 0.0, 1e-12);
    EXPECT_NEAR(glm::dot(move, f), 0.0, 1e-12);
    EXPECT_LT(glm::dot(move, r), 0.0)
        << "dragging right moves the camera left: the scene follows the mouse";
    // A drag the height of the viewport moves by the visible height at the target.
    Camera d = sample();
    pan(d, 0.0, 500.0, 500);
    double visible = 2.0 * glm::length(sample().at - sample().from) * std::tan(glm::radians(19.0));
    EXPECT_NEAR(glm::length(d.at - sample().at), visible, 1e-9);
}

TEST(CameraControl, ZoomAndProjectionToggleKeepTheFraming) {
    Camera c = sample();
    double d = glm::length(c.from - c.at);
    zoom(c, 0.5);
    EXPECT_NEAR(glm::length(c.from - c.at), 0.5 * d, 1e-9);
    toggleProjection(c);
    EXPECT_EQ(c.projection, Projection::Orthographic);
    EXPECT_NEAR(c.orthoHeight, 2.0 * 0.5 * d * std::tan(glm::radians(19.0)), 1e-9);
    zoom(c, 2.0);
    EXPECT_NEAR(c.orthoHeight, 2.0 * d * std::tan(glm::radians(19.0)), 1e-9);
    toggleProjection(c);
    EXPECT_EQ(c.projection, Projection::Perspective);
    EXPECT_NEAR(glm::length(c.from - c.at), d, 1e-9);
}

TEST(CameraControl, JsonRoundTripAndErrors) {
    Camera c = sample();
    Camera back = cameraFromJson(c.toJson(), Camera{});
    EXPECT_EQ(back.from, c.from);
    EXPECT_EQ(back.at, c.at);
    EXPECT_EQ(back.up, c.up);
    EXPECT_EQ(back.fov, c.fov);
    toggleProjection(c);
    back = cameraFromJson(c.toJson(), sample());
    EXPECT_EQ(back.projection, Projection::Orthographic);
    EXPECT_EQ(back.orthoHeight, c.orthoHeight);
    try {
        cameraFromJson("{\"from\": [0, 0, 0],\n \"at\": [0, 0, 0]}", sample());
        FAIL() << "a camera looking at its own eye must be refused";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("camera JSON:1:1"), std::string::npos) << e.what();
    }
    EXPECT_THROW(cameraFromJson("{\"fov\": 200}", sample()), SceneError);
    EXPECT_THROW(cameraFromJson("not json", sample()), SceneError);
}

// With no ini and no option, the viewer builds what `lancer render` would: the regular scheme
// (a viewer that silently fell back to brute force took minutes on balls4).
TEST(ViewerSettingsIni, DefaultsAreTheCommandLineDefaults) {
    ViewerSettings s;
    EXPECT_EQ(s.build.scheme, SchemeKind::Regular);
    EXPECT_EQ(s.build.scheme, cli::CommonOptions{}.build.scheme);
    EXPECT_EQ(s.build.maxLevel, cli::CommonOptions{}.build.maxLevel);
    EXPECT_EQ(s.build.maxObjects, cli::CommonOptions{}.build.maxObjects);
}

TEST(ViewerSettingsIni, LinesRoundTripAndBadValuesAreIgnored) {
    ViewerSettings s;
    s.scene = "assets/spd/balls4.nff";
    s.build.scheme = SchemeKind::Irregular;
    s.build.maxLevel = 7;
    s.build.maxObjects = 5;
    s.build.step = StepMethod::Push;
    s.build.delta = 3.5e-7;
    s.build.heuristic = BspHeuristic::FewestCuts;
    s.build.splitAxes = SplitAxes::Cycle;  // not the default: the line must carry it
    s.build.mailboxes = false;
    s.threads = 1;
    s.shading.bounces = 2;
    s.shading.shadows = false;
    s.windowWidth = 800;
    s.windowHeight = 600;
    s.showStatistics = false;
    s.mode = ViewMode::TimeUs;
    s.autoScale = false;
    s.heatScale = 42.0f;
    ViewerSettings r;
    std::string lines = settingsLines(s);
    size_t start = 0;
    while (start < lines.size()) {
        size_t end = lines.find('\n', start);
        readSettingsLine(r, lines.substr(start, end - start));
        start = end + 1;
    }
    EXPECT_EQ(settingsLines(r), lines);
    ViewerSettings bad = r;
    for (const char* line : {"max_level=999", "scheme=octree", "split_axes=diagonal", "window=5 5",
                             "delta=-1", "threads=x", "garbage"})
        readSettingsLine(bad, line);
    EXPECT_EQ(settingsLines(bad), lines);
}

}  // namespace
}  // namespace lancer::viewer

namespace lancer::viewer {
namespace {

TEST(ImageCopy, UncoveredRectanglesTileExactlyWhatNoPanelCovers) {
    // What the window copies of the image around opaque panels: every pixel outside the panels
    // in exactly one rectangle, none inside one; panels may overlap, touch or leave the window.
    std::mt19937 rng(7);
    for (int trial = 0; trial < 200; ++trial) {
        const int w = 40 + int(rng() % 60), h = 30 + int(rng() % 50);
        std::vector<PixelRect> panels(rng() % 6);
        for (PixelRect& p : panels) {
            p.x0 = int(rng() % unsigned(w + 20)) - 10;
            p.y0 = int(rng() % unsigned(h + 20)) - 10;
            p.x1 = p.x0 + int(rng() % unsigned(w));
            p.y1 = p.y0 + int(rng() % unsigned(h));
        }
        std::vector<int> count(size_t(w * h), 0);
        const std::vector<PixelRect> rects = uncovered(w, h, panels);
        for (const PixelRect& r : rects) {
            ASSERT_TRUE(0 <= r.x0 && r.x0 < r.x1 && r.x1 <= w && 0 <= r.y0 && r.y0 < r.y1 &&
                        r.y1 <= h);
            for (int y = r.y0; y < r.y1; ++y)
                for (int x = r.x0; x < r.x1; ++x) ++count[size_t(y * w + x)];
        }
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                bool covered = false;
                for (const PixelRect& p : panels)
                    covered |= x >= p.x0 && x < p.x1 && y >= p.y0 && y < p.y1;
                ASSERT_EQ(count[size_t(y * w + x)], covered ? 0 : 1)
                    << "trial " << trial << " pixel " << x << "," << y;
            }
        if (panels.empty()) {
            ASSERT_EQ(rects.size(), 1u);  // the whole window, one copy
        }
    }
}

}  // namespace
}  // namespace lancer::viewer

namespace lancer::viewer {
namespace {

// The automatic heat scale is a high percentile, not the largest value: a few outliers (a
// preempted pixel in the time map) leave the rest of the map readable.
TEST(HeatScale, AutomaticScaleIgnoresAFewOutliers) {
    std::vector<float> heat(1000, 10.0f);
    for (int i = 0; i < 5; ++i) heat[size_t(i) * 100] = 1e6f;
    EXPECT_EQ(autoScale(heat), 10.0f);
    std::vector<float> ramp(1000);
    for (size_t i = 0; i < ramp.size(); ++i) ramp[i] = float(i);
    EXPECT_EQ(autoScale(ramp), 989.0f) << "the 99th percentile";
    EXPECT_EQ(autoScale({}), 1.0f);
    EXPECT_EQ(autoScale(std::vector<float>(10, 0.0f)), 1.0f) << "at least 1";
    EXPECT_FLOAT_EQ(heatValue(5.0f, 10.0f, false), 0.5f);
    EXPECT_FLOAT_EQ(heatValue(20.0f, 10.0f, false), 1.0f);
    EXPECT_FLOAT_EQ(heatValue(std::expm1(0.5f * std::log1p(99.0f)), 99.0f, true), 0.5f);
    EXPECT_FLOAT_EQ(heatValue(0.0f, 99.0f, true), 0.0f);
}

}  // namespace
}  // namespace lancer::viewer
