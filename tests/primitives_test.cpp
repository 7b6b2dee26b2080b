// Each primitive against analytic answers: hits, misses, tangents, origins inside, axis rays,
// and affine transforms (non-uniform scale included, with correctly transformed normals).
#include <gtest/gtest.h>

#include "engine/model/csg.h"
#include "engine/scene/builtin_scenes.h"
#include "engine/scene/scene.h"
#include "tests/support/differential.h"
#include "tests/support/shape_spans.h"

namespace lancer {
namespace {

using Result = test::ShapeSpans;
Result spans(const Shape& shape, const Ray& r) { return test::spansOf(shape, r); }
Result spans(const Primitive& p, const Ray& r) {
    Result res;
    res.n = p.spans(r, 7, res.s);
    return res;
}

constexpr double kTol = 1e-12;

TEST(Sphere, HitFromOutside) {
    Result r = spans(Sphere{{0, 0, 0}, 2.0}, {{0, 0, -10}, {0, 0, 1}});
    ASSERT_EQ(r.n, 1);
    EXPECT_NEAR(r.s[0].in.t, 8.0, kTol);
    EXPECT_NEAR(r.s[0].out.t, 12.0, kTol);
    EXPECT_EQ(r.s[0].in.prim, 7u);
}

TEST(Sphere, MissAndTangent) {
    EXPECT_EQ(spans(Sphere{{0, 0, 0}, 1.0}, {{0, 1.5, -5}, {0, 0, 1}}).n, 0);
    // Exactly tangent: a zero-length contact is not a span of the solid.
    EXPECT_EQ(spans(Sphere{{0, 0, 0}, 1.0}, {{0, 1.0, -5}, {0, 0, 1}}).n, 0);
    // Just inside the tangent: a short span.
    Result r = spans(Sphere{{0, 0, 0}, 1.0}, {{0, 1.0 - 1e-6, -5}, {0, 0, 1}});
    ASSERT_EQ(r.n, 1);
    EXPECT_NEAR(r.s[0].out.t - r.s[0].in.t, 2.0 * std::sqrt(1.0 - (1.0 - 1e-6) * (1.0 - 1e-6)),
                1e-9);
}

TEST(Sphere, OriginInsideGivesNegativeEntry) {
    Result r = spans(Sphere{{1, 1, 1}, 1.0}, {{1, 1, 1}, {1, 0, 0}});
    ASSERT_EQ(r.n, 1);
    EXPECT_NEAR(r.s[0].in.t, -1.0, kTol);
    EXPECT_NEAR(r.s[0].out.t, 1.0, kTol);
}

TEST(Sphere, FarFromOriginKeepsPrecision) {
    // A unit sphere 1e7 away hit by a ray from 1e7 + 100: robust discriminant keeps ~1e-8.
    Vec3 c(1e7, 1e7, 1e7);
    Result r = spans(Sphere{c, 1.0}, {c + Vec3(0.5, 0, -100), {0, 0, 1}});
    ASSERT_EQ(r.n, 1);
    double half = std::sqrt(1.0 - 0.25);
    EXPECT_NEAR(r.s[0].in.t, 100.0 - half, 1e-8);
    EXPECT_NEAR(r.s[0].out.t, 100.0 + half, 1e-8);
}

TEST(Block, FacesAndParts) {
    Block b{{-1, -2, -3}, {1, 2, 3}};
    Result r = spans(b, {{-5, 0, 0}, {1, 0, 0}});
    ASSERT_EQ(r.n, 1);
    EXPECT_EQ(r.s[0].in.t, 4.0);
    EXPECT_EQ(r.s[0].out.t, 6.0);
    EXPECT_EQ(r.s[0].in.part, 0);   // -x face
    EXPECT_EQ(r.s[0].out.part, 1);  // +x face
    EXPECT_EQ(shapeNormal(b, {-1, 0, 0}, r.s[0].in.part), Vec3(-1, 0, 0));
    Result down = spans(b, {{0, 0, 10}, {0, 0, -1}});
    ASSERT_EQ(down.n, 1);
    EXPECT_EQ(down.s[0].in.part, 5);  // enters through +z
    EXPECT_EQ(down.s[0].in.t, 7.0);
}

TEST(Block, AxisParallelRaysOutsideTheSlabMiss) {
    Block b{{0, 0, 0}, {1, 1, 1}};
    EXPECT_EQ(spans(b, {{2, 0.5, -5}, {0, 0, 1}}).n, 0);
    EXPECT_EQ(spans(b, {{0.5, 0.5, -5}, {0, 0, 1}}).n, 1);
    // Along an edge of the closed box: inside the closed slabs, so a span.
    Result edge = spans(b, {{1, 1, -5}, {0, 0, 1}});
    ASSERT_EQ(edge.n, 1);
    EXPECT_EQ(edge.s[0].in.t, 5.0);
}

TEST(Block, DiagonalThroughCorner) {
    Result r = spans(Block{{0, 0, 0}, {1, 1, 1}}, {{-1, -1, -1}, {1, 1, 1}});
    ASSERT_EQ(r.n, 1);
    EXPECT_EQ(r.s[0].in.t, 1.0);
    EXPECT_EQ(r.s[0].out.t, 2.0);
}

TEST(Cylinder, SideCapsAndAxis) {
    Cone cyl{1.0, 1.0, 2.0, false};
    Result side = spans(cyl, {{-5, 0, 1}, {1, 0, 0}});
    ASSERT_EQ(side.n, 1);
    EXPECT_NEAR(side.s[0].in.t, 4.0, kTol);
    EXPECT_NEAR(side.s[0].out.t, 6.0, kTol);
    EXPECT_EQ(side.s[0].in.part, 0);
    // Along the axis: through both caps (the quadric is degenerate along z).
    Result axis = spans(cyl, {{0.5, 0, -3}, {0, 0, 1}});
    ASSERT_EQ(axis.n, 1);
    EXPECT_NEAR(axis.s[0].in.t, 3.0, kTol);
    EXPECT_NEAR(axis.s[0].out.t, 5.0, kTol);
    EXPECT_EQ(axis.s[0].in.part, 1);
    EXPECT_EQ(axis.s[0].out.part, 2);
    EXPECT_EQ(shapeNormal(cyl, {0.5, 0, 0}, 1), Vec3(0, 0, -1));
    // Parallel to the axis but outside: a miss.
    EXPECT_EQ(spans(cyl, {{1.5, 0, -3}, {0, 0, 1}}).n, 0);
    // Slanted: enters the side, leaves through the top cap.
    Result slant = spans(cyl, {{-2, 0, 0}, glm::normalize(Vec3(1, 0, 1))});
    ASSERT_EQ(slant.n, 1);
    EXPECT_NEAR(slant.s[0].in.t, std::sqrt(2.0), 1e-12);
    EXPECT_NEAR(slant.s[0].out.t, 2.0 * std::sqrt(2.0), 1e-12);
    EXPECT_EQ(slant.s[0].out.part, 2);
}

TEST(Cone, ApexAndTruncated) {
    // r1 = 1 at z = 0, apex at z = 1: radius 0.5 at z = 0.5.
    Cone cone{1.0, 0.0, 1.0, false};
    Result r = spans(cone, {{-3, 0, 0.5}, {1, 0, 0}});
    ASSERT_EQ(r.n, 1);
    EXPECT_NEAR(r.s[0].in.t, 2.5, kTol);
    EXPECT_NEAR(r.s[0].out.t, 3.5, kTol);
    // Side normal of a 45° cone points outward and up.
    Vec3 n = shapeNormal(cone, {0.5, 0, 0.5}, 0);
    EXPECT_NEAR(n.x, std::sqrt(0.5), 1e-12);
    EXPECT_NEAR(n.z, std::sqrt(0.5), 1e-12);
    // Above the apex: the other nappe must not count.
    EXPECT_EQ(spans(cone, {{-3, 0, 1.5}, {1, 0, 0}}).n, 0);
    // Truncated cone (OpenSCAD r1 = 2, r2 = 1, h = 2): radius 1.5 at z = 1.
    Result t = spans(Cone{2.0, 1.0, 2.0, false}, {{-5, 0, 1}, {1, 0, 0}});
    ASSERT_EQ(t.n, 1);
    EXPECT_NEAR(t.s[0].in.t, 3.5, kTol);
    EXPECT_NEAR(t.s[0].out.t, 6.5, kTol);
    // Down the axis through the apex and the base.
    Result ax = spans(cone, {{0, 0, 5}, {0, 0, -1}});
    ASSERT_EQ(ax.n, 1);
    EXPECT_NEAR(ax.s[0].in.t, 4.0, kTol);
    EXPECT_NEAR(ax.s[0].out.t, 5.0, kTol);
}

TEST(OpenCone, SideOnlyNoCaps) {
    Cone open{1.0, 1.0, 2.0, true};
    EXPECT_TRUE(shapeIsSurface(open));
    Result r = spans(open, {{-5, 0, 1}, {1, 0, 0}});
    ASSERT_EQ(r.n, 2);
    EXPECT_NEAR(r.s[0].in.t, 4.0, kTol);
    EXPECT_EQ(r.s[0].in.t, r.s[0].out.t);  // surface hits are zero-length spans
    EXPECT_NEAR(r.s[1].in.t, 6.0, kTol);
    // Down the axis of an open tube: no surface to hit.
    EXPECT_EQ(spans(open, {{0, 0, -5}, {0, 0, 1}}).n, 0);
    // Beyond its height: no hit.
    EXPECT_EQ(spans(open, {{-5, 0, 2.5}, {1, 0, 0}}).n, 0);
}

TEST(Triangle, BothSidesAndEdges) {
    Triangle t;
    t.p[0] = {0, 0, 0}, t.p[1] = {1, 0, 0}, t.p[2] = {0, 1, 0};
    Result front = spans(t, {{0.25, 0.25, 1}, {0, 0, -1}});
    ASSERT_EQ(front.n, 1);
    EXPECT_NEAR(front.s[0].in.t, 1.0, kTol);
    EXPECT_EQ(spans(t, {{0.25, 0.25, -1}, {0, 0, 1}}).n, 1);  // from behind too
    EXPECT_EQ(spans(t, {{0.75, 0.75, 1}, {0, 0, -1}}).n, 0);
    EXPECT_EQ(spans(t, {{0.5, 0.0, 1}, {0, 0, -1}}).n, 1);  // on an edge: closed
    EXPECT_EQ(spans(t, {{0, 0, 1}, {1, 0, 0}}).n, 0);       // parallel to the plane
}

TEST(Triangle, SmoothNormalsInterpolate) {
    Triangle t;
    t.p[0] = {0, 0, 0}, t.p[1] = {1, 0, 0}, t.p[2] = {0, 1, 0};
    t.n[0] = {0, 0, 1}, t.n[1] = glm::normalize(Vec3(1, 0, 1)), t.n[2] = {0, 0, 1};
    t.smooth = true;
    EXPECT_NEAR(glm::length(shapeNormal(t, {0, 0, 0}, 0) - Vec3(0, 0, 1)), 0.0, 1e-12);
    Vec3 mid = shapeNormal(t, {0.5, 0, 0}, 0);
    EXPECT_GT(mid.x, 0.3);
    EXPECT_NEAR(glm::length(mid), 1.0, 1e-12);
}

TEST(Polygon, NonConvexEvenOdd) {
    // An L shape: the notch at (1.5, 1.5) is outside.
    Polygon pg;
    ASSERT_TRUE(
        makePolygon({{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {1, 1, 0}, {1, 2, 0}, {0, 2, 0}}, pg));
    EXPECT_NEAR(std::abs(pg.n.z), 1.0, kTol);
    EXPECT_EQ(spans(pg, {{0.5, 1.5, 3}, {0, 0, -1}}).n, 1);
    EXPECT_EQ(spans(pg, {{1.5, 0.5, 3}, {0, 0, -1}}).n, 1);
    EXPECT_EQ(spans(pg, {{1.5, 1.5, 3}, {0, 0, -1}}).n, 0);
    Polygon degenerate;
    EXPECT_FALSE(makePolygon({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}}, degenerate));
}

TEST(Transform, NonUniformScaleGivesEllipsoidWithCorrectNormals) {
    // Unit sphere scaled by (2, 1, 1), then moved to (10, 0, 0): an ellipsoid x²/4 + y² + z² = 1.
    Primitive p = makePrimitive(Sphere{{0, 0, 0}, 1.0},
                                Transform::translate({10, 0, 0}) * Transform::scale({2, 1, 1}));
    EXPECT_EQ(p.worldBox, (Box3{{8, -1, -1}, {12, 1, 1}}));
    Result r = spans(p, {{0, 0, 0}, {1, 0, 0}});
    ASSERT_EQ(r.n, 1);
    EXPECT_NEAR(r.s[0].in.t, 8.0, kTol);
    EXPECT_NEAR(r.s[0].out.t, 12.0, kTol);
    // Normal at (10 + 2 cos a, sin a, 0) is the gradient (cos a / 2, sin a, 0), normalised.
    double a = 0.7;
    Vec3 q(10 + 2 * std::cos(a), std::sin(a), 0);
    Vec3 expected = glm::normalize(Vec3(std::cos(a) / 2.0, std::sin(a), 0));
    Vec3 got = p.normal(q, 0);
    EXPECT_NEAR(glm::length(got - expected), 0.0, 1e-12);
    // t is the world ray's parameter even though the local ray is not unit length.
    Result diag = spans(p, {{10, -5, 0}, {0, 1, 0}});
    ASSERT_EQ(diag.n, 1);
    EXPECT_NEAR(diag.s[0].in.t, 4.0, kTol);
}

TEST(Transform, RotationAndComposition) {
    Transform t = Transform::translate({1, 2, 3}) * Transform::rotate(90.0, {0, 0, 1});
    Vec3 p = t.point({1, 0, 0});
    EXPECT_NEAR(glm::length(p - Vec3(1, 3, 3)), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(t.toLocal({p, Vec3(0.0)}).o - Vec3(1, 0, 0)), 0.0, 1e-12);
    EXPECT_TRUE(t.isInvertible());
    EXPECT_FALSE(Transform::scale({1, 0, 1}).isInvertible());
    // A rotated cylinder lying along x.
    Primitive cyl = makePrimitive(Cone{0.5, 0.5, 4.0, false}, Transform::rotate(90.0, {0, 1, 0}));
    Result r = spans(cyl, {{2, 0, 5}, {0, 0, -1}});
    ASSERT_EQ(r.n, 1);
    EXPECT_NEAR(r.s[0].in.t, 4.5, 1e-12);
    Vec3 n = cyl.normal({2, 0, 0.5}, r.s[0].in.part);
    EXPECT_NEAR(glm::length(n - Vec3(0, 0, 1)), 0.0, 1e-12);
}

TEST(Box3, ClipLineHandlesZeroDirections) {
    Box3 b{{0, 0, 0}, {1, 1, 1}};
    double t0, t1;
    EXPECT_TRUE(clipLine({{0.5, 0.5, -1}, {0, 0, 1}}, b, t0, t1));
    EXPECT_EQ(t0, 1.0);
    EXPECT_EQ(t1, 2.0);
    EXPECT_FALSE(clipLine({{1.5, 0.5, -1}, {0, 0, 1}}, b, t0, t1));
    EXPECT_TRUE(b.overlaps(Box3{{1, 1, 1}, {2, 2, 2}}));  // touching boxes overlap
    EXPECT_TRUE(overlap(b, Box3{{2, 2, 2}, {3, 3, 3}}).isEmpty());
}

// The walks test spheres from the scene's packed table: the same spans, bit for bit, as the
// primitive's own test, for world spheres (packed) and transformed ones (not packed).
TEST(PackedSpheres, SameSpansAsThePrimitivesBitForBit) {
    test::RandomSceneOptions opt;
    opt.primitives = 40;
    for (bool transforms : {false, true}) {
        opt.transforms = transforms;
        // SPD spheres are in world coordinates; the random scene's are placed by transforms.
        Scene scene = transforms ? test::randomCsgScene(11, opt) : makeBuiltin("balls", 2);
        if (!scene.prepared) scene.prepare();
        ASSERT_EQ(scene.packedSpheres.size(), scene.prims.size());
        int packed = 0;
        for (size_t p = 0; p < scene.prims.size(); ++p) {
            const bool worldSphere =
                std::holds_alternative<Sphere>(scene.prims[p].shape) && !scene.prims[p].hasXf;
            EXPECT_EQ(scene.packedSpheres[p].r >= 0.0, worldSphere) << "primitive " << p;
            packed += worldSphere;
        }
        if (!transforms) {
            EXPECT_GT(packed, 0);
        }
        int hits = 0;
        for (const Ray& ray : test::randomRays(scene, 5, 300)) {
            for (uint32_t p = 0; p < scene.prims.size(); ++p) {
                Span a[2] = {}, b[2] = {};
                const int na = scene.primSpans(p, ray, a, Precision::Double);
                const int nb = scene.prims[p].spans(ray, p, b);
                ASSERT_EQ(na, nb) << "primitive " << p << " ray " << ray.toString();
                for (int k = 0; k < na; ++k) EXPECT_EQ(a[k], b[k]);
                hits += na;
            }
        }
        EXPECT_GT(hits, 100);
    }
}

}  // namespace
}  // namespace lancer
