// The inspector's geometry: frusta and image planes where the camera's rays go, the GL
// depth the GL matrix writes, the level range and slice slab filters, and picking.
#include "app/viewer/inspector/inspector_geometry.h"

#include <gtest/gtest.h>

#include <glm/vec4.hpp>
#include <random>

#include "app/viewer/colormap.h"
#include "app/viewer/gl/transforms.h"

namespace lancer::viewer::inspector {
namespace {

Camera perspective() {
    Camera c;
    c.from = {1.5, -10.0, 4.5};
    c.at = {0.0, 0.5, -0.2};
    c.up = {0.0, 0.0, 1.0};
    c.fov = 38.0;
    return c;
}

Camera orthographic() {
    Camera c = perspective();
    c.projection = Projection::Orthographic;
    c.orthoHeight = 7.0;
    return c;
}

void expectNear(const Vec3& a, const Vec3& b, double tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(InspectorGeometry, ImagePointsLieOnThePrimaryRays) {
    for (const Camera& cam : {perspective(), orthographic()}) {
        const int w = 64, h = 48;
        Vec3 f, r, u;
        cam.basis(f, r, u);
        for (auto [x, y] : {std::pair{0, 0}, {63, 47}, {10, 30}}) {
            Ray ray = cam.primaryRay(x, y, w, h);
            const double depth = 3.5;
            Vec3 p = imagePoint(cam, w, h, x + 0.5, y + 0.5, depth);
            // On the ray, at that depth along F.
            const double t = glm::dot(p - ray.o, ray.d);
            expectNear(ray.at(t), p, 1e-9);
            EXPECT_NEAR(
                cameraDepth(cam, p),
                cam.projection == Projection::Perspective ? depth : depth + cameraDepth(cam, ray.o),
                1e-9);
            std::optional<glm::dvec2> back = gl::ImageProjector(cam, w, h).toImage(p);
            ASSERT_TRUE(back);
            EXPECT_NEAR(back->x, x + 0.5, 1e-9);
            EXPECT_NEAR(back->y, y + 0.5, 1e-9);
        }
    }
}

TEST(InspectorGeometry, FrustumCornersBoundTheImage) {
    const int w = 80, h = 40;
    const Camera cam = perspective();
    Corners c = frustumCorners(cam, w, h, 1.0, 20.0);
    // Near corners at depth 1, far at 20; corner 0 bottom left, 3 top right.
    for (int i = 0; i < 8; ++i)
        EXPECT_NEAR(cameraDepth(cam, c[size_t(i)]), i & 4 ? 20.0 : 1.0, 1e-9);
    const gl::ImageProjector proj(cam, w, h);
    std::optional<glm::dvec2> bl = proj.toImage(c[0]), tr = proj.toImage(c[7]);
    ASSERT_TRUE(bl && tr);
    EXPECT_NEAR(bl->x, 0.0, 1e-9);
    EXPECT_NEAR(bl->y, h, 1e-9);
    EXPECT_NEAR(tr->x, w, 1e-9);
    EXPECT_NEAR(tr->y, 0.0, 1e-9);
    // The far face is 20 times the near one (perspective); an orthographic one is a box.
    EXPECT_NEAR(glm::length(c[7] - c[4]), 20.0 * glm::length(c[3] - c[0]), 1e-9);
    Corners o = frustumCorners(orthographic(), w, h, 0.0, 5.0);
    EXPECT_NEAR(glm::length(o[7] - o[4]), glm::length(o[3] - o[0]), 1e-9);
    EXPECT_NEAR(glm::length(o[2] - o[0]), 7.0, 1e-9);   // the ortho height
    EXPECT_NEAR(glm::length(o[1] - o[0]), 14.0, 1e-9);  // twice as wide

    std::array<Vec3, 4> plane = imagePlane(cam, w, h);
    const double focus = glm::length(cam.at - cam.from);
    for (const Vec3& p : plane) EXPECT_NEAR(cameraDepth(cam, p), focus, 1e-9);
    // Its centre is `at`, and its height is the field of view's at that distance.
    expectNear(0.5 * (plane[0] + plane[2]), cam.at, 1e-9);
    EXPECT_NEAR(glm::length(plane[3] - plane[0]), 2.0 * focus * std::tan(glm::radians(19.0)), 1e-9);
}

TEST(InspectorGeometry, WindowDepthIsTheDepthTheGlMatrixWrites) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coord(-3.0, 3.0);
    const int w = 300, h = 200;
    for (const Camera& cam : {perspective(), orthographic()}) {
        const Box3 b{Vec3(-3.0), Vec3(3.0)};
        double near, far;
        depthRange(cam, b, near, far);
        const glm::mat4 m = gl::worldToClip(cam, w, h, near, far);
        const gl::ImageProjector proj(cam, w, h);
        for (int i = 0; i < 50; ++i) {
            Vec3 p{coord(rng), coord(rng), coord(rng)};
            glm::vec4 clip = m * glm::vec4(glm::vec3(p), 1.0f);
            std::optional<glm::dvec2> e = proj.toImage(p);
            ASSERT_TRUE(e);
            const double x = (clip.x / clip.w + 1.0) * 0.5 * w;
            const double y = (1.0 - clip.y / clip.w) * 0.5 * h;  // GL's y goes up
            EXPECT_NEAR(x, e->x, 1e-3);
            EXPECT_NEAR(y, e->y, 1e-3);
            const double wd = 0.5 * (clip.z / clip.w + 1.0);
            EXPECT_NEAR(wd, windowDepth(cam, near, far, proj.depth(p)), 1e-4);
            EXPECT_GT(wd, 0.0);
            EXPECT_LT(wd, 1.0);
        }
    }
}

TEST(InspectorGeometry, FrameBoxShowsTheWholeBox) {
    const Box3 b{Vec3(-1.0, 2.0, 0.0), Vec3(5.0, 3.0, 1.0)};
    for (Vec3 fwd : {Vec3(1.0, 1.0, -0.5), Vec3(0.0, 0.0, -1.0)}) {
        for (int w : {100, 40, 250}) {  // square, narrow, wide
            Camera c = frameBox(b, fwd, 40.0, w / 100.0);
            ASSERT_TRUE(c.validate().empty());
            for (const Vec3& p : boxCorners(b)) {
                std::optional<glm::dvec2> q = gl::ImageProjector(c, w, 100).toImage(p);
                ASSERT_TRUE(q);
                EXPECT_GE(q->x, 0.0);
                EXPECT_LE(q->x, double(w));
                EXPECT_GE(q->y, 0.0);
                EXPECT_LE(q->y, 100.0);
            }
        }
    }
}

TEST(InspectorGeometry, LevelRangeAndSlabKeepWhatTheySay) {
    EXPECT_TRUE(inLevelRange(3, 3, 5));
    EXPECT_TRUE(inLevelRange(5, 3, 5));
    EXPECT_FALSE(inLevelRange(2, 3, 5));
    EXPECT_FALSE(inLevelRange(6, 3, 5));
    Slab s;
    s.on = true;
    s.axis = 1;
    s.lo = 1.0;
    s.hi = 1.5;
    auto cell = [](double y0, double y1) {
        return boxCorners(Box3{Vec3(0.0, y0, 0.0), Vec3(1.0, y1, 1.0)});
    };
    EXPECT_TRUE(s.keeps(cell(0.0, 2.0)));    // holds the slab
    EXPECT_TRUE(s.keeps(cell(1.2, 1.3)));    // inside it
    EXPECT_TRUE(s.keeps(cell(0.0, 1.0)));    // touches it
    EXPECT_TRUE(s.keeps(cell(1.4, 3.0)));    // crosses its top
    EXPECT_FALSE(s.keeps(cell(0.0, 0.99)));  // below
    EXPECT_FALSE(s.keeps(cell(1.51, 2.0)));  // above
    s.on = false;
    EXPECT_TRUE(s.keeps(cell(5.0, 6.0)));
}

TEST(InspectorGeometry, RegionColoursFollowTheValueOnTheFixedScales) {
    // By primitives: brighter with the count on the fixed log scale, clamped at its top, never
    // black; the same count gives the same colour whatever else the structure holds.
    glm::vec3 a = regionColor(1.0, ColorBy::Prims), b = regionColor(30.0, ColorBy::Prims),
              c = regionColor(1000.0, ColorBy::Prims);
    auto lum = [](glm::vec3 v) { return v.x + v.y + v.z; };
    EXPECT_GT(lum(a), 0.1f);
    EXPECT_LT(lum(a), lum(b));
    EXPECT_LT(lum(b), lum(c));
    EXPECT_EQ(regionColor(5000.0, ColorBy::Prims), c);
    EXPECT_EQ(regionColor(30.0, ColorBy::Prims), countColor(30.0));
    // By level: the overlays' palette, indexed by the absolute level.
    for (int level : {0, 3, 7, 23, 30})
        EXPECT_EQ(regionColor(double(level), ColorBy::Level), levelColor(level)) << level;
    EXPECT_NE(regionColor(3.0, ColorBy::Level), regionColor(4.0, ColorBy::Level));
}

TEST(InspectorGeometry, RayEntersBoxesAndFrusta) {
    const Corners box = boxCorners(Box3{Vec3(1.0, -1.0, -1.0), Vec3(3.0, 1.0, 1.0)});
    std::optional<double> t = rayEnters(Ray{Vec3(0.0), Vec3(1.0, 0.0, 0.0)}, box);
    ASSERT_TRUE(t);
    EXPECT_NEAR(*t, 1.0, 1e-12);
    EXPECT_FALSE(rayEnters(Ray{Vec3(0.0), Vec3(-1.0, 0.0, 0.0)}, box));
    EXPECT_FALSE(rayEnters(Ray{Vec3(0.0, 2.0, 0.0), Vec3(1.0, 0.0, 0.0)}, box));
    t = rayEnters(Ray{Vec3(2.0, 0.0, 0.0), Vec3(0.0, 0.0, 1.0)}, box);  // from inside
    ASSERT_TRUE(t);
    EXPECT_EQ(*t, 0.0);
    // A frustum (a perspective camera's, depths 2 to 8): its own rays enter it at depth 2.
    const Camera cam = perspective();
    const Corners fr = frustumCorners(cam, 40, 30, 2.0, 8.0);
    Ray ray = cam.primaryRay(5, 20, 40, 30);
    t = rayEnters(ray, fr);
    ASSERT_TRUE(t);
    EXPECT_NEAR(cameraDepth(cam, ray.at(*t)), 2.0, 1e-9);
    // A ray that passes beside it misses.
    EXPECT_FALSE(rayEnters(Ray{cam.from, -ray.d}, fr));
}

TEST(InspectorGeometry, PickTakesTheNearestDrawnRegion) {
    std::vector<RegionView> regions(3);
    regions[0].corners = boxCorners(Box3{Vec3(4.0, -1.0, -1.0), Vec3(5.0, 1.0, 1.0)});
    regions[1].corners = boxCorners(Box3{Vec3(2.0, -1.0, -1.0), Vec3(3.0, 1.0, 1.0)});
    regions[2].corners = boxCorners(Box3{Vec3(2.0, 5.0, -1.0), Vec3(3.0, 6.0, 1.0)});
    const Ray ray{Vec3(0.0), Vec3(1.0, 0.0, 0.0)};
    EXPECT_EQ(pickRegion(ray, regions), 1);
    EXPECT_EQ(pickRegion(ray, regions, {0, 2}), 0);  // the nearer one is not drawn
    EXPECT_EQ(pickRegion(ray, regions, {2}), -1);
    // Inside two at once: the smaller.
    regions[2].corners = boxCorners(Box3{Vec3(-1.0), Vec3(1.0)});
    regions[0].corners = boxCorners(Box3{Vec3(-9.0), Vec3(9.0)});
    EXPECT_EQ(pickRegion(ray, regions), 2);
}

}  // namespace
}  // namespace lancer::viewer::inspector
