// The torus: its polynomial solver (sign-change roots through the derivative's roots), its spans
// against analytic answers (through the hole, along the axis, tangent and grazing rays, far
// origins, huge tori, thin and horn tori), against the distance to its centre circle sampled
// along random rays, and every scheme against brute force on random CSG scenes with tori.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "engine/accel/accelerator.h"
#include "engine/model/csg.h"
#include "engine/model/quartic.h"
#include "engine/scene/scene.h"
#include "tests/support/differential.h"
#include "tests/support/shape_spans.h"

namespace lancer {
namespace {

/// The coefficients (lowest first) of the monic polynomial with the given roots.
std::vector<double> fromRoots(std::initializer_list<double> roots) {
    std::vector<double> c{1.0};
    for (double r : roots) {
        std::vector<double> next(c.size() + 1, 0.0);
        for (size_t i = 0; i < c.size(); ++i) next[i + 1] += c[i], next[i] -= r * c[i];
        c = next;
    }
    return c;
}

TEST(Quartic, FindsFourSimpleRootsSorted) {
    const std::vector<double> c = fromRoots({0.75, -0.5, 0.1, -0.9});
    double r[4];
    ASSERT_EQ(poly::signChangeRoots(c.data(), 4, -1.0, 1.0, r), 4);
    const double want[4] = {-0.9, -0.5, 0.1, 0.75};
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(r[i], want[i], 1e-15);
    // Only the roots inside the interval.
    ASSERT_EQ(poly::signChangeRoots(c.data(), 4, -0.6, 0.5, r), 2);
    EXPECT_NEAR(r[0], -0.5, 1e-15);
    EXPECT_NEAR(r[1], 0.1, 1e-15);
}

TEST(Quartic, CloseRootsAreSeparatedAndDoubleRootsDoNotCross) {
    // Two roots 2e-6 apart (a nearly grazing ray): both found, each to far below their gap.
    const std::vector<double> close = fromRoots({0.3 - 1e-6, 0.3 + 1e-6, -0.7, 0.8});
    double r[4];
    ASSERT_EQ(poly::signChangeRoots(close.data(), 4, -1.0, 1.0, r), 4);
    EXPECT_NEAR(r[1], 0.3 - 1e-6, 1e-11);
    EXPECT_NEAR(r[2], 0.3 + 1e-6, 1e-11);
    // ((x - 0.3)^2 + 1e-12) times the rest: a miss by a hair, the pair is gone, the others stay.
    std::vector<double> miss = fromRoots({0.3, 0.3, -0.7, 0.8});
    const std::vector<double> lift = fromRoots({-0.7, 0.8});
    for (size_t i = 0; i < lift.size(); ++i) miss[i] += 1e-12 * lift[i];
    ASSERT_EQ(poly::signChangeRoots(miss.data(), 4, -1.0, 1.0, r), 2);
    EXPECT_NEAR(r[0], -0.7, 1e-12);
    EXPECT_NEAR(r[1], 0.8, 1e-12);
    // A root exactly at a critical point of p (x^2 (x - 1)(x + 1): zero touched from below)
    // splits the span there into two that meet, by the convention that zero counts as outside.
    const std::vector<double> touch = fromRoots({0.0, 0.0, 1.0, -1.0});
    const int n = poly::signChangeRoots(touch.data(), 4, -2.0, 2.0, r);
    ASSERT_EQ(n, 4);
    EXPECT_DOUBLE_EQ(r[0], -1.0);
    EXPECT_EQ(r[1], 0.0);
    EXPECT_EQ(r[2], 0.0);
    EXPECT_DOUBLE_EQ(r[3], 1.0);
}

using Result = test::ShapeSpans;
Result spans(const Torus& t, const Ray& r) { return test::spansOf(t, r, 5); }

/// Signed distance from p to the surface of the torus (R, r) about z.
double distance(const Torus& t, const Vec3& p) {
    return std::hypot(std::hypot(p.x, p.y) - t.R, p.z) - t.r;
}

constexpr double kTol = 1e-12;

TEST(TorusSpans, AlongXThroughTheCentreCrossesTheTubeTwice) {
    const Result r = spans(Torus{2.0, 0.5}, {{-10, 0, 0}, {1, 0, 0}});
    ASSERT_EQ(r.n, 2);
    EXPECT_NEAR(r.s[0].in.t, 7.5, kTol);
    EXPECT_NEAR(r.s[0].out.t, 8.5, kTol);
    EXPECT_NEAR(r.s[1].in.t, 11.5, kTol);
    EXPECT_NEAR(r.s[1].out.t, 12.5, kTol);
    EXPECT_EQ(r.s[1].out.prim, 5u);
    // A direction of length 4: t in units of it.
    const Result q = spans(Torus{2.0, 0.5}, {{-10, 0, 0}, {4, 0, 0}});
    ASSERT_EQ(q.n, 2);
    EXPECT_NEAR(q.s[1].out.t, 12.5 / 4.0, kTol);
}

TEST(TorusSpans, AxisAlignedRaysThroughTheHoleAndAlongTheAxis) {
    const Torus t{2.0, 0.5};
    // Along the axis, and parallel to it inside the hole: nothing.
    EXPECT_EQ(spans(t, {{0, 0, -10}, {0, 0, 1}}).n, 0);
    EXPECT_EQ(spans(t, {{0.7, -0.4, 10}, {0, 0, -1}}).n, 0);
    // Parallel to the axis through the tube's centre circle: z from -r to r.
    Result r = spans(t, {{0, 2, -10}, {0, 0, 1}});
    ASSERT_EQ(r.n, 1);
    EXPECT_NEAR(r.s[0].in.t, 9.5, kTol);
    EXPECT_NEAR(r.s[0].out.t, 10.5, kTol);
    // Along y at x = 0.5 across the hole: inside where 1.5 <= |(0.5, y)| <= 2.5.
    r = spans(t, {{0.5, -10, 0}, {0, 1, 0}});
    ASSERT_EQ(r.n, 2);
    EXPECT_NEAR(r.s[0].in.t, 10.0 - std::sqrt(6.0), kTol);
    EXPECT_NEAR(r.s[0].out.t, 10.0 - std::sqrt(2.0), kTol);
    EXPECT_NEAR(r.s[1].in.t, 10.0 + std::sqrt(2.0), kTol);
    EXPECT_NEAR(r.s[1].out.t, 10.0 + std::sqrt(6.0), kTol);
    // The horn torus (R = r) has no hole: along its axis it is touched at the centre only.
    EXPECT_EQ(spans(Torus{1.0, 1.0}, {{0, 0, -10}, {0, 0, 1}}).n, 0);
    r = spans(Torus{1.0, 1.0}, {{-10, 0, 0}, {1, 0, 0}});
    ASSERT_GE(r.n, 1);
    EXPECT_NEAR(r.s[0].in.t, 8.0, kTol);
    EXPECT_NEAR(r.s[r.n - 1].out.t, 12.0, kTol);
}

TEST(TorusSpans, TangentAndGrazingRays) {
    const Torus t{2.0, 0.5};
    // Tangent on top of the tube, and on the outer equator: no span.
    EXPECT_EQ(spans(t, {{-10, 2, 0.5}, {1, 0, 0}}).n, 0);
    EXPECT_EQ(spans(t, {{-10, 2.5, 0}, {1, 0, 0}}).n, 0);
    EXPECT_EQ(spans(t, {{-10, 2, 0.5 + 1e-9}, {1, 0, 0}}).n, 0);
    // Just under the top: one short span, |x| <= sqrt((R + sqrt(r^2 - z^2))^2 - y^2).
    for (double eps : {1e-3, 1e-6, 1e-9}) {
        const double z = 0.5 - eps,
                     half = std::sqrt(std::pow(2.0 + std::sqrt(0.25 - z * z), 2) - 4);
        const Result r = spans(t, {{-10, 2, z}, {1, 0, 0}});
        ASSERT_EQ(r.n, 1) << eps;
        EXPECT_NEAR(r.s[0].in.t, 10.0 - half, 1e-9) << eps;
        EXPECT_NEAR(r.s[0].out.t, 10.0 + half, 1e-9) << eps;
        // Just inside the outer equator: |x| <= sqrt(2.5^2 - y^2).
        const double y = 2.5 - eps, w = std::sqrt(6.25 - y * y);
        const Result o = spans(t, {{-10, y, 0}, {1, 0, 0}});
        ASSERT_EQ(o.n, 1) << eps;
        EXPECT_NEAR(o.s[0].in.t, 10.0 - w, 1e-9) << eps;
        EXPECT_NEAR(o.s[0].out.t, 10.0 + w, 1e-9) << eps;
    }
    // Tangent to the inner equator from the hole's side: inside the tube all along, the
    // touching point at most splits the span in two that meet. Just inside the hole, a gap of
    // 2 sqrt(1.5^2 - y^2) (1.1e-4 at 1e-9 from the wall) between two spans.
    for (double y : {1.5, 1.5 + 1e-9, 1.5 - 1e-9, 1.5 - 1e-6}) {
        const Result r = spans(t, {{-10, y, 0}, {1, 0, 0}});
        ASSERT_GE(r.n, 1) << y;
        const double w = std::sqrt(6.25 - y * y),
                     gap = 2.0 * std::sqrt(std::max(0.0, 2.25 - y * y));
        EXPECT_NEAR(r.s[0].in.t, 10.0 - w, 1e-9) << y;
        EXPECT_NEAR(r.s[r.n - 1].out.t, 10.0 + w, 1e-9) << y;
        if (gap > 0.0) {
            ASSERT_EQ(r.n, 2) << y;
        }
        if (r.n == 2) {
            EXPECT_NEAR(r.s[1].in.t - r.s[0].out.t, gap, 1e-8) << y;
        }
    }
}

// A line through a point of the tube, from `far` away: the aimed point lies in a span, every
// span end lies on the surface, and the ends are the near origin's shifted by the distance.
void expectFarOriginHolds(const Torus& t, double far, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int i = 0; i < 200; ++i) {
        const double a = 3.14159 * u(rng), b = 3.14159 * u(rng), c = 0.9 * t.r * std::abs(u(rng));
        const Vec3 at((t.R + c * std::cos(b)) * std::cos(a), (t.R + c * std::cos(b)) * std::sin(a),
                      c * std::sin(b));
        const Vec3 dir = glm::normalize(Vec3(u(rng), u(rng), u(rng)));
        const Result near = spans(t, {at - 3.0 * (t.R + t.r) * dir, dir});
        const Result r = spans(t, {at - far * dir, dir});
        ASSERT_EQ(r.n, near.n) << far << " ray " << i;
        bool holds = false;
        for (int k = 0; k < r.n; ++k) {
            holds = holds || (r.s[k].in.t <= far && far <= r.s[k].out.t);
            for (const Boundary& e : {r.s[k].in, r.s[k].out}) {
                EXPECT_NEAR(distance(t, at + (e.t - far) * dir), 0.0, 2e-15 * far) << far;
            }
            const double shift = far - 3.0 * (t.R + t.r);
            EXPECT_NEAR(r.s[k].in.t, near.s[k].in.t + shift, 2e-15 * far);
            EXPECT_NEAR(r.s[k].out.t, near.s[k].out.t + shift, 2e-15 * far);
        }
        EXPECT_TRUE(holds) << far << " ray " << i;
    }
}

TEST(TorusSpans, FarOriginsKeepPrecision) {
    for (double far : {1e4, 1e6}) expectFarOriginHolds(Torus{2.0, 0.5}, far, 3);
    // Tori of size 1e4 and 1e6, seen from ten times as far.
    expectFarOriginHolds(Torus{1e4, 2.5e3}, 1e5, 4);
    expectFarOriginHolds(Torus{1e6, 1e5}, 1e7, 5);
}

// Random lines through random tori (ring, thin, horn): every span end lies on the surface, and
// 1000 points along each line are inside exactly where the distance to the centre circle says.
TEST(TorusSpans, AgreeWithTheDistanceAlongRandomLines) {
    std::mt19937_64 rng(17);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (const Torus& t : {Torus{2.0, 0.5}, Torus{1.0, 0.01}, Torus{1.0, 1.0}, Torus{3.0, 2.9}}) {
        const double B = t.R + t.r;
        int checked = 0;
        for (int i = 0; i < 400; ++i) {
            const Vec3 o = 2.0 * B * Vec3(u(rng), u(rng), u(rng));
            // Half the lines through a point of the tube, half through the bounding box.
            const double a = 3.14159 * u(rng), b = 3.14159 * u(rng), c = t.r * std::abs(u(rng));
            const Vec3 aim = i % 2 ? Vec3(B * u(rng), B * u(rng), t.r * u(rng))
                                   : Vec3((t.R + c * std::cos(b)) * std::cos(a),
                                          (t.R + c * std::cos(b)) * std::sin(a), c * std::sin(b));
            const Ray ray{o, (aim - o) * (0.5 + std::abs(u(rng)))};
            const Result r = spans(t, ray);
            for (int k = 0; k < r.n; ++k) {
                EXPECT_LT(r.s[k].in.t, r.s[k].out.t);
                if (k) {
                    EXPECT_LE(r.s[k - 1].out.t, r.s[k].in.t);
                }
                for (const Boundary& e : {r.s[k].in, r.s[k].out})
                    EXPECT_NEAR(distance(t, ray.at(e.t)), 0.0, 1e-12 * B);
            }
            for (int j = 0; j <= 1000; ++j) {
                const double tt = -1.0 + 4.0 * j / 1000.0;
                const double dist = distance(t, ray.at(tt));
                if (std::abs(dist) < 1e-9 * B) continue;  // on the surface: either answer
                bool in = false;
                for (int k = 0; k < r.n; ++k) in = in || (r.s[k].in.t < tt && tt < r.s[k].out.t);
                ASSERT_EQ(in, dist < 0.0)
                    << "R " << t.R << " r " << t.r << " " << ray.toString() << " t " << tt;
                checked += dist < 0.0;
            }
        }
        EXPECT_GT(checked, 500) << t.R << " " << t.r;  // the lines do cross the tube
    }
}

TEST(TorusSpans, FloatTestStaysNearTheDoubleOne) {
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Torus t{2.0, 0.6};
    int compared = 0;
    for (int i = 0; i < 500; ++i) {
        // Aimed at the tube's centre circle, well inside: no grazing.
        const double a = 3.14159 * u(rng);
        const Vec3 at(t.R * std::cos(a), t.R * std::sin(a), 0.0);
        const Vec3 o = at + 10.0 * glm::normalize(Vec3(u(rng), u(rng), u(rng)));
        const Ray ray{o, at - o};
        Span d[2], f[2];
        const int nd = shapeSpans(t, ray, 1, d);
        const int nf = shapeSpans(t, RayF{glm::vec3(ray.o), glm::vec3(ray.d)}, 1, f);
        // A line may graze the far side of the tube; compare where both agree on the count.
        if (nd != nf) continue;
        ++compared;
        for (int k = 0; k < nd; ++k) {
            EXPECT_NEAR(d[k].in.t, f[k].in.t, 2e-5);
            EXPECT_NEAR(d[k].out.t, f[k].out.t, 2e-5);
        }
    }
    EXPECT_GT(compared, 480);
}

TEST(TorusShape, NormalsBoundsAndName) {
    const Torus t{2.0, 0.5};
    const Shape s = t;
    EXPECT_NEAR(glm::length(shapeNormal(s, {2.5, 0, 0}, 0) - Vec3(1, 0, 0)), 0.0, kTol);
    EXPECT_NEAR(glm::length(shapeNormal(s, {-1.5, 0, 0}, 0) - Vec3(1, 0, 0)), 0.0, kTol);
    EXPECT_NEAR(glm::length(shapeNormal(s, {0, 2, 0.5}, 0) - Vec3(0, 0, 1)), 0.0, kTol);
    const Vec3 q(1.2, -1.6, 0.3);  // rho = 2: straight up-and-out of the centre circle
    EXPECT_NEAR(glm::length(shapeNormal(s, q, 0) - glm::normalize(q - Vec3(1.2, -1.6, 0.0))), 0.0,
                kTol);
    const Box3 b = shapeBounds(s);
    EXPECT_EQ(b.lo, Vec3(-2.5, -2.5, -0.5));
    EXPECT_EQ(b.hi, Vec3(2.5, 2.5, 0.5));
    EXPECT_STREQ(shapeName(s), "torus");
    EXPECT_FALSE(shapeIsSurface(s));
}

TEST(TorusShape, TransformedTorusHitsWhereTheWorldSaysAndItsNormalFacesOut) {
    // Turned to stand on its side (axis along y) and moved: a ray along x through its centre.
    const Transform xf = Transform::translate({5, 1, -2}) * Transform::rotate(90.0, {1, 0, 0});
    const Primitive p = makePrimitive(Torus{2.0, 0.5}, xf);
    Span s[2];
    ASSERT_EQ(p.spans({{-5, 1, -2}, {1, 0, 0}}, 0, s), 2);
    EXPECT_NEAR(s[0].in.t, 7.5, 1e-12);
    EXPECT_NEAR(s[1].out.t, 12.5, 1e-12);
    EXPECT_NEAR(glm::length(p.normal({2.5, 1, -2}, 0) - Vec3(-1, 0, 0)), 0.0, 1e-12);
    // Its world box holds it: x and z from -2.5 to 2.5 around the centre, y within 0.5.
    EXPECT_NEAR(p.worldBox.lo.y, 0.5, 1e-12);
    EXPECT_NEAR(p.worldBox.hi.x, 7.5, 1e-12);
}

// Every scheme gives brute force's hit on every pixel (and secondary rays from the hits, random
// rays, far-offset scenes) of random CSG trees with tori among their solids.
TEST(TorusCsg, EverySchemeGivesBruteForcesHitOnRandomScenesWithTori) {
    size_t total = 0;
    int tori = 0;
    for (uint64_t seed = 1; seed <= 10; ++seed) {
        test::RandomSceneOptions opt;
        opt.tori = true;
        opt.transforms = seed % 2 == 0;
        opt.primitives = 8 + int(seed % 3) * 5;
        opt.groups = seed % 4 == 1 ? 3 : 1;
        if (seed % 5 == 0) opt.offset = Vec3(1e6, -1e6, 5e5);
        Scene scene = test::randomCsgScene(seed, opt);
        if (scene.bounds.isEmpty()) continue;
        for (const Primitive& p : scene.prims) tori += std::holds_alternative<Torus>(p.shape);
        std::vector<Ray> rays = test::pixelRays(scene, 40, 40);
        const std::vector<Ray> rnd = test::randomRays(scene, seed, 600);
        rays.insert(rays.end(), rnd.begin(), rnd.end());
        for (const SchemeInfo& info : kSchemeTable) {
            BuildParams p;
            p.scheme = info.kind;
            const auto accel = buildAccelerator(scene, p);
            const std::string what = "seed " + std::to_string(seed) + " " + info.name;
            test::expectSame(scene, *accel, rays, what);
            test::expectSame(scene, *accel, test::secondaryRays(scene, rays, seed),
                             what + " secondary", 1e-9 * scene.scale());
        }
        total += rays.size();
    }
    EXPECT_GT(tori, 15);
    EXPECT_GE(total, 15000u);
}

}  // namespace
}  // namespace lancer
