// The viewer's camera controls, camera JSON and saved settings (no GL needed, but they live in
// the viewer library this binary links).
#include <gtest/gtest.h>

#include <random>

#include "app/viewer/camera_control.h"
#include "app/viewer/image_view.h"
#include "app/viewer/panels/panels.h"
#include "app/viewer/viewer_settings.h"
#include "engine/scene/loader.h"
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
    EXPECT_EQ(s.build.scheme, cli::Knobs{}.build.scheme);
    EXPECT_EQ(s.build.regular.maxLevel, cli::Knobs{}.build.regular.maxLevel);
    EXPECT_EQ(s.build.regular.maxObjects, cli::Knobs{}.build.regular.maxObjects);
}

TEST(ViewerSettingsIni, LinesRoundTripAndBadValuesAreIgnored) {
    ViewerSettings s;
    s.scene = "assets/spd/balls4.nff";
    s.build.scheme = SchemeKind::Irregular;
    s.build.regular.maxLevel = 7;
    s.build.regular.maxObjects = s.build.irregular.maxObjects = 5;
    s.build.regular.step = StepMethod::Push;
    s.build.regular.delta = 3.5e-7;
    s.build.irregular.heuristic = BspHeuristic::FewestCuts;
    s.build.regular.splitAxes = SplitAxes::Cycle;  // not the default: the line must carry it
    s.build.mailboxes = false;
    s.build.regular.fullTable = true;  // options the ini once dropped
    s.build.irregular.frame = IrregularFrame::Camera;
    s.shading.offsetScale = 2.5e-8;
    s.shading.reflections = false;
    s.threads = 1;
    s.shading.bounces = 2;
    s.shading.shadows = false;
    s.windowWidth = 800;
    s.windowHeight = 600;
    s.showStatistics = false;
    s.mode = ViewMode::TimeUs;
    s.autoScale = false;
    s.heatScale = 42.0f;
    s.leftColumn = 300.0f;  // the columns and the split as dragged
    s.rightColumn = 412.0f;
    s.imageShare = 0.625f;
    ViewerSettings r;
    std::string lines = settingsLines(s);
    size_t start = 0;
    while (start < lines.size()) {
        size_t end = lines.find('\n', start);
        readSettingsLine(r, lines.substr(start, end - start));
        start = end + 1;
    }
    EXPECT_EQ(settingsLines(r), lines);
    // Every ini key of the parameter table is written, with the value set above.
    for (const cli::ParamDesc& d : cli::paramTable()) {
        if (d.iniKey) {
            EXPECT_NE(lines.find(std::string("\n") + d.iniKey + "=" +
                                 cli::formatValue(d, knobsOf(s)) + "\n"),
                      std::string::npos)
                << d.iniKey;
        }
    }
    EXPECT_TRUE(r.build.regular.fullTable);
    EXPECT_EQ(r.build.irregular.frame, IrregularFrame::Camera);
    EXPECT_EQ(r.shading.offsetScale, 2.5e-8);
    EXPECT_EQ(r.leftColumn, 300.0f);
    EXPECT_EQ(r.rightColumn, 412.0f);
    EXPECT_EQ(r.imageShare, 0.625f);
    ViewerSettings bad = r;
    for (const char* line :
         {"max_level=999", "max_objects=-1", "full_table=2", "scheme=octree", "split_axes=diagonal",
          "window=5 5", "delta=-1", "threads=x", "layout=1 2 3", "layout=-5 0 0.5", "garbage"})
        readSettingsLine(bad, line);
    EXPECT_EQ(settingsLines(bad), lines);
}

void readLines(ViewerSettings& r, const std::string& lines);

// The ini writes max-objects' automatic value as "auto" and reads it back; an explicit value
// replaces it (the report's rule), and "auto" restores the default.
TEST(ViewerSettingsIni, MaxObjectsAutoRoundTrips) {
    ViewerSettings s;
    EXPECT_NE(settingsLines(s).find("\nmax_objects=auto\n"), std::string::npos);
    readSettingsLine(s, "max_objects=2");
    EXPECT_EQ(s.build.regular.maxObjects, 2);
    EXPECT_FALSE(s.build.regular.usesCostStop());
    readSettingsLine(s, "max_objects=auto");
    EXPECT_EQ(s.build.irregular.maxObjects, kAutoObjects);
    EXPECT_TRUE(s.build.regular.usesCostStop());
    // An ini written before "auto" (no knob_format line) held its default as max_objects=4:
    // read as auto, the build it stood for; since, 4 is an explicit 4.
    ViewerSettings old;
    readSettingsLine(old, "max_objects=4");
    EXPECT_EQ(old.build.regular.maxObjects, kAutoObjects);
    ViewerSettings now;
    now.build.regular.maxObjects = now.build.irregular.maxObjects = 4;
    ViewerSettings back;
    readLines(back, settingsLines(now));
    EXPECT_EQ(back.build.regular.maxObjects, 4);
}

// The Parameters panel's line of stop reasons, from a build's --stats figures.
TEST(ParametersPanel, StopReasonsLineCountsEachReason) {
    Scene scene = loadScene("builtin:default");
    BuildParams p;
    p.scheme = SchemeKind::Regular;
    p.regular.maxLevel = 6;
    p.regular.maxObjects = 1;
    const auto a = buildAccelerator(scene, p);
    const nlohmann::json& r = a->info().extra["stop_reasons"];
    const size_t covered = a->info().extra["covered_leaves"];
    EXPECT_EQ(stopReasonsLine(a->info().extra, SchemeKind::Regular),
              "leaves stopped by max-objects " + std::to_string(size_t(r["max_objects"])) +
                  ", max-level " + std::to_string(size_t(r["max_level"])) + ", cost " +
                  std::to_string(size_t(r["cost"])) +
                  (covered ? " (" + std::to_string(covered) + " covered)" : "") + ", memory 0");
    EXPECT_GT(size_t(r["max_level"]), 0u);
    p.scheme = SchemeKind::Irregular;
    const auto b = buildAccelerator(scene, p);
    EXPECT_EQ(stopReasonsLine(b->info().extra, SchemeKind::Irregular).rfind("zones stopped by ", 0),
              0u);
    p.scheme = SchemeKind::Brute;
    EXPECT_EQ(stopReasonsLine(buildAccelerator(scene, p)->info().extra, SchemeKind::Brute), "");
}

/// Every line of `lines` read into `r`.
void readLines(ViewerSettings& r, const std::string& lines) {
    size_t start = 0;
    while (start < lines.size()) {
        size_t end = lines.find('\n', start);
        readSettingsLine(r, lines.substr(start, end - start));
        start = end + 1;
    }
}

TEST(ViewerSettingsIni, OverlayAndInspectorOptionsRoundTrip) {
    ViewerSettings s;
    overlay::OverlayOptions& o = s.overlays;
    o.bsp = o.slabs = o.grid = true;
    o.zoneFill = overlay::ZoneFill::Slabs;
    o.leafColor = overlay::LeafColor::Prims;
    o.gridColor = overlay::GridColor::TableDepth;
    o.projective = false;
    o.levelMin = 3;
    o.levelMax = 9;
    o.cap = 12345;
    s.overlayLook.fillOpacity = 0.6f;
    s.overlayLook.lineOpacity = 0.25f;
    s.overlayLook.tooltip = false;
    s.overlayLook.movingLines = 750;
    inspector::InspectorOptions& i = s.inspector;
    i.regions = false;
    i.grid = i.boxes = i.zoneSlabsOnly = true;
    i.frustum = i.surfaces = false;
    i.colorBy = inspector::ColorBy::Level;
    i.levelLo = 2;
    i.levelHi = 11;
    i.slab = {true, 2, -0.25, 0.75};
    i.cap = 777;
    s.showInspector = true;
    Camera c = sample();
    c.projection = Projection::Orthographic;
    c.orthoHeight = 3.25;
    s.inspectorCamera = c;
    s.inspectorScene = "assets/spd/balls4.nff";

    ViewerSettings r;
    const std::string lines = settingsLines(s);
    readLines(r, lines);
    EXPECT_EQ(settingsLines(r), lines);
    EXPECT_TRUE(r.overlays == s.overlays);
    EXPECT_TRUE(r.overlayLook == s.overlayLook);
    EXPECT_TRUE(r.inspector == s.inspector);
    EXPECT_TRUE(r.showInspector);
    ASSERT_TRUE(r.inspectorCamera);
    EXPECT_EQ(r.inspectorCamera->toJson(), c.toJson());
    EXPECT_EQ(r.inspectorScene, s.inspectorScene);
    // The defaults differ from every value above: nothing was left at its default by chance.
    const ViewerSettings d;
    EXPECT_FALSE(d.overlays.bsp || d.overlays.slabs || d.overlays.grid);
    EXPECT_NE(d.overlays.cap, o.cap);
    EXPECT_FALSE(d.inspector == i);

    // Bad values leave what was read.
    ViewerSettings bad = r;
    for (const char* line :
         {"overlay_levels=5 2", "overlay_cap=-3", "overlay_opacity=2 0.5", "overlay_fill=area",
          "overlay_color=", "overlay_grid_color=blue", "inspector_slice=1 3 0 1", "inspector_cap=x",
          "inspector_levels=-1 4", "inspector_color=heat",
          "inspector_camera=1 2 3 1 2 3 0 0 1 45 fisheye 1",
          "inspector_camera=0 0 0 0 0 0 0 0 1 45 perspective 1"})
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
