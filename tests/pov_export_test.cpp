// `lancer export --pov`: the POV-Ray 3.7 scene's text (every shape, its matrix, the CSG tree),
// its camera against Lancer's primary rays (POV-Ray's own formula for a pixel's ray, applied to
// the vectors written), and, where povray is installed, POV-Ray's depth image of the scene
// against brute force's hits, perspective and orthographic, at an odd, non-square size.
#include "app/bench/pov_export.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <regex>
#include <sstream>

#include "app/bench/pov_peer.h"
#include "engine/render/renderer.h"

namespace lancer::bench {
namespace {

/// A scene of every shape: CSG of solids (a block minus a sphere and a rotated cylinder, a cone
/// of two radii intersected with a sphere), a scaled and rotated block, a tilted torus, and
/// surfaces under the union (a floor polygon, a triangle, a smooth triangle, an open cone).
Scene everyShape(Projection projection) {
    Scene s;
    auto prim = [&](Shape shape, const Transform& xf = Transform()) {
        s.prims.push_back(makePrimitive(std::move(shape), xf, 0));
        return s.tree.leaf(uint32_t(s.prims.size() - 1));
    };
    std::vector<int> parts;
    int block = prim(Block{{-2.0, -1.0, 0.0}, {0.0, 1.0, 2.0}});
    int hole = prim(Sphere{{-1.0, -1.0, 2.0}, 0.9});
    int drill = prim(Cone{0.35, 0.35, 4.0, false}, Transform::translate({-1.0, 0.0, 1.0}) *
                                                       Transform::rotate(90.0, {0.0, 1.0, 0.0}) *
                                                       Transform::translate({0.0, 0.0, -2.0}));
    parts.push_back(
        s.tree.combine(Op::Difference, s.tree.combine(Op::Difference, block, hole), drill));
    int cone = prim(Cone{1.0, 0.3, 2.0, false}, Transform::translate({1.5, 0.0, 0.0}));
    int ball = prim(Sphere{{1.5, 0.0, 0.8}, 1.05});
    parts.push_back(s.tree.combine(Op::Intersection, cone, ball));
    parts.push_back(
        prim(Block{{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}},
             Transform::translate({0.2, 1.8, 0.6}) * Transform::rotate(30.0, {0.3, 0.2, 1.0}) *
                 Transform::scale({1.0, 0.6, 0.8})));
    // A torus tilted towards the camera, its hole in view.
    parts.push_back(prim(Torus{0.5, 0.18}, Transform::translate({0.5, -1.9, 0.75}) *
                                               Transform::rotate(40.0, {1.0, 0.0, 0.0})));
    Polygon floor;
    EXPECT_TRUE(makePolygon(
        {{-4, -3, -0.01}, {4, -3, -0.01}, {4, 4, -0.01}, {-3, 4, -0.01}, {-4, 0, -0.01}}, floor));
    parts.push_back(prim(floor));
    Triangle t;
    t.p[0] = {2.5, 1.5, 0.0};
    t.p[1] = {3.5, 1.5, 0.0};
    t.p[2] = {3.0, 2.0, 1.5};
    parts.push_back(prim(t));
    Triangle st = t;
    for (Vec3& p : st.p) p += Vec3(-6.0, 0.0, 0.0);
    st.smooth = true;
    st.n[0] = glm::normalize(Vec3(0, -1, 0.2));
    st.n[1] = glm::normalize(Vec3(0.2, -1, 0.2));
    st.n[2] = glm::normalize(Vec3(0, -1, 0.5));
    parts.push_back(prim(st));
    parts.push_back(prim(Cone{0.4, 0.2, 1.2, true}, Transform::translate({-2.5, -2.0, 0.0})));
    s.tree.root = s.tree.balanced(Op::Union, parts);
    s.prepare();
    s.camera.from = {1.5, -6.0, 3.8};
    s.camera.at = {0.0, 0.0, 0.7};
    s.camera.up = {0.0, 0.0, 1.0};
    s.camera.fov = 45.0;
    s.camera.projection = projection;
    s.camera.orthoHeight = 6.0;
    s.defaultLights();
    return s;
}

std::string povText(const Scene& s, PovOptions o = {}) {
    std::ostringstream os;
    writePov(os, s, s.camera, o);
    return os.str();
}

Vec3 vectorAfter(const std::string& text, const std::string& key, double& scale) {
    const std::regex re("\\n  " + key + " <([^,]+), ([^,]+), ([^>]+)>(?: \\* ([0-9.e+-]+))?");
    std::smatch m;
    EXPECT_TRUE(std::regex_search(text, m, re)) << key;
    scale = m[4].matched ? std::stod(m[4]) : 1.0;
    return {std::stod(m[1]), std::stod(m[2]), std::stod(m[3])};
}

TEST(PovExport, WritesEveryShapeTheTreeAndTheMatrices) {
    const std::string pov = povText(everyShape(Projection::Perspective));
    for (const char* s : {"#version 3.7;",
                          "max_trace_level 4",
                          "camera {",
                          "perspective",
                          "light_source {",
                          "difference {",
                          "intersection {",
                          "union {",
                          "sphere {",
                          "box {",
                          "cylinder {",
                          "cone {",
                          " open",
                          "triangle {",
                          "smooth_triangle {",
                          "polygon { 6,",
                          "torus { 0.5, 0.18 sturm",
                          "matrix <",
                          "material { M0 }",
                          "#declare M0 = material"})
        EXPECT_NE(pov.find(s), std::string::npos) << s << "\n" << pov;
    // The chain of differences is one difference: the block minus the sphere and the cylinder.
    EXPECT_EQ(pov.find("difference {", pov.find("difference {") + 1), std::string::npos);
}

TEST(PovExport, MatrixIsPovRaysRowVectorForm) {
    Scene s = everyShape(Projection::Perspective);
    const std::string pov = povText(s);
    // The rotated block: POV-Ray maps x to x m00 + y m10 + z m20 + m30.
    const Primitive& p = s.prims[5];
    ASSERT_TRUE(p.hasXf);
    const std::regex re("box \\{ <-0.5, -0.5, -0.5>, <0.5, 0.5, 0.5> matrix <([^>]+)>");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(pov, m, re));
    std::vector<double> v;
    std::stringstream ss(m[1].str());
    for (std::string item; std::getline(ss, item, ',');) v.push_back(std::stod(item));
    ASSERT_EQ(v.size(), 12u);
    for (const Vec3& q : {Vec3(0.5, -0.5, 0.5), Vec3(-0.3, 0.2, 0.1)}) {
        const Vec3 pov3(q.x * v[0] + q.y * v[3] + q.z * v[6] + v[9],
                        q.x * v[1] + q.y * v[4] + q.z * v[7] + v[10],
                        q.x * v[2] + q.y * v[5] + q.z * v[8] + v[11]);
        const Vec3 ours = p.xf.point(q);
        for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(pov3[a], ours[a]);
    }
}

// POV-Ray 3.7's perspective camera (backend/render/tracepixel.cpp, CreateCameraRay) traces pixel
// (x, y) along direction + x0 right + y0 up, x0 = (x + 0.5) / w - 0.5, y0 = ((h - 1) - (y - 0.5))
// / h - 0.5; orthographic from location + x0 right + y0 up along direction. The vectors written
// give Lancer's primary ray for every pixel.
TEST(PovExport, CameraTracesLancersPrimaryRays) {
    for (Projection proj : {Projection::Perspective, Projection::Orthographic}) {
        Scene s = everyShape(proj);
        const int w = 41, h = 27;
        const std::string pov = povText(s);
        double ks, kd, kr, ku;
        const Vec3 loc = vectorAfter(pov, "location", ks), dir = vectorAfter(pov, "direction", kd);
        Vec3 right = vectorAfter(pov, "right", kr), up = vectorAfter(pov, "up", ku);
        right *= kr * double(w) / double(h);  // "* image_width / image_height"
        up *= ku;
        const PrimaryRays rays(s.camera, w, h);
        for (int y : {0, 5, h - 1})
            for (int x : {0, 17, w - 1}) {
                const double x0 = (x + 0.5) / w - 0.5, y0 = ((h - 1) - (y - 0.5)) / h - 0.5;
                const Ray ours = rays(x, y);
                if (proj == Projection::Perspective) {
                    const Vec3 d = glm::normalize(dir + x0 * right + y0 * up);
                    for (int a = 0; a < 3; ++a) EXPECT_NEAR(d[a], ours.d[a], 1e-12);
                    for (int a = 0; a < 3; ++a) EXPECT_DOUBLE_EQ(loc[a], ours.o[a]);
                } else {
                    const Vec3 o = loc + x0 * right + y0 * up;
                    for (int a = 0; a < 3; ++a) EXPECT_NEAR(o[a], ours.o[a], 1e-12);
                    for (int a = 0; a < 3; ++a) EXPECT_NEAR(dir[a], ours.d[a], 1e-15);
                }
            }
    }
}

TEST(PovExport, DepthVariantEmitsDistanceOnly) {
    PovOptions o;
    o.depth = true;
    const std::string pov = povText(everyShape(Projection::Perspective), o);
    EXPECT_NE(pov.find("emission 1"), std::string::npos);
    EXPECT_NE(pov.find("LancerDepthRange"), std::string::npos);
    EXPECT_EQ(pov.find("material {"), std::string::npos);
    EXPECT_EQ(pov.find("light_source"), std::string::npos);
}

// POV-Ray's own rendering: its depth image against brute force's hits.
TEST(PovExport, PovRaysDepthMatchesBruteForce) {
    if (!PovPeer::available()) GTEST_SKIP() << "povray is not installed";
    const std::string dir =
        (std::filesystem::temp_directory_path() / ("lancer-pov-test-" + std::to_string(::getpid())))
            .string();
    for (Projection proj : {Projection::Perspective, Projection::Orthographic}) {
        Scene s = everyShape(proj);
        RenderOptions ro;
        ro.width = 83;
        ro.height = 55;
        ro.threads = 2;
        ro.shading.bounces = 0;
        auto brute = buildAccelerator(s, BuildParams{});
        Image ref(ro.width, ro.height);
        render(s, *brute, ro, ref);
        size_t hits = 0;
        for (float d : ref.depth) hits += std::isfinite(d);
        ASSERT_GT(hits, ref.depth.size() / 3);
        ASSERT_LT(hits, ref.depth.size());
        PovPeer peer(s, ro, dir, proj == Projection::Perspective ? "persp" : "ortho");
        const PovRun run = peer.render(&ref);
        ASSERT_TRUE(run.failure.empty()) << run.failure;
        ASSERT_TRUE(run.compared);
        EXPECT_EQ(run.error.hitDiff, 0u) << "projection " << int(proj);
        EXPECT_LT(run.error.maxDepthDiff, 2.0 * depthRangeOf(s, s.camera) / 65535.0);
        EXPECT_GT(run.traceMs, -1.0);
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lancer::bench
