// The primitives' tests in single precision (--precision float): each shape's float spans lie
// within single precision's rounding of the double ones, every scheme traces the same hits as
// brute force in float, and float's depth error is what the bench reports (small, not zero).
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <random>

#include "engine/accel/accelerator.h"
#include "engine/model/csg.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "engine/scene/scene.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

/// A shape and where rays aim at it: points well inside (solids) or well inside the face
/// (surfaces), so that no ray grazes it and both precisions must hit.
struct Target {
    std::string name;
    Primitive prim;
    std::function<Vec3(std::mt19937_64&)> point;
    /// A surface's normal: rays within 17 degrees of its plane are not aimed (a plane's t
    /// error grows as 1 / cos of the incidence).
    Vec3 facing{0.0};
};

std::vector<Target> targets() {
    std::uniform_real_distribution<double> u(-1.0, 1.0), w(0.2, 0.8);
    std::vector<Target> out;
    out.push_back({"sphere", makePrimitive(Sphere{{1.5, -0.5, 2.0}, 1.25}, {}),
                   [=](std::mt19937_64& g) mutable {
                       return Vec3(1.5, -0.5, 2.0) + 0.5 * Vec3(u(g), u(g), u(g));
                   }});
    out.push_back({"box", makePrimitive(Block{{-1, -2, 0}, {3, 1, 0.5}}, {}),
                   [=](std::mt19937_64& g) mutable {
                       return Vec3(1.0 + 1.5 * u(g), -0.5 + u(g), 0.25 + 0.2 * u(g));
                   }});
    for (const Cone& c : {Cone{1.0, 0.25, 3.0}, Cone{0.75, 0.75, 2.0}}) {
        out.push_back(
            {c.r1 == c.r2 ? "cylinder" : "cone", makePrimitive(c, {}),
             [=](std::mt19937_64& g) mutable { return Vec3(0.1 * u(g), 0.1 * u(g), c.h * w(g)); }});
    }
    Triangle tri;
    tri.p[0] = {0, 0, 1};
    tri.p[1] = {4, 0.5, 1.5};
    tri.p[2] = {1, 3, 0.5};
    out.push_back({"triangle", makePrimitive(tri, {}),
                   [=](std::mt19937_64& g) mutable {
                       const double a = w(g), b = w(g) * (1.0 - a) * 0.9;
                       return (1.0 - a - b) * tri.p[0] + a * tri.p[1] + b * tri.p[2];
                   },
                   glm::normalize(glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]))});
    Polygon pg;
    EXPECT_TRUE(makePolygon({{-1, -1, 2}, {2, -1, 2.5}, {2, 2, 3}, {-1, 2, 2.5}}, pg));
    out.push_back({"polygon", makePrimitive(pg, {}),
                   [=](std::mt19937_64& g) mutable {
                       const double s = 0.5 * (w(g) + 0.5), t = 0.5 * (w(g) + 0.5);
                       return (1 - s) * (1 - t) * pg.p[0] + s * (1 - t) * pg.p[1] +
                              s * t * pg.p[2] + (1 - s) * t * pg.p[3];
                   },
                   pg.n});
    // A cube cut by a slanted plane: a polytope of seven faces.
    Polytope k;
    for (int a = 0; a < 3; ++a)
        for (double s : {-1.0, 1.0}) {
            glm::dvec4 pl(0.0);
            pl[a] = s;
            pl.w = 1.0;
            k.planes.push_back(pl);
        }
    k.planes.push_back(glm::dvec4(glm::normalize(Vec3(1, 1, 1)), 1.2));
    k.bounds = {Vec3(-1.0), Vec3(1.0)};
    out.push_back({"polytope", makePrimitive(k, {}), [=](std::mt19937_64& g) mutable {
                       return 0.4 * Vec3(u(g), u(g), u(g)) - Vec3(0.3);
                   }});
    // A turned, stretched box far from the origin: the transform in double, the test in float.
    const Transform xf = Transform::translate({1e3, -2e3, 500.0}) *
                         Transform::rotate(33.0, {1, 2, 0.5}) * Transform::scale({2, 0.5, 1});
    out.push_back(
        {"transformed box", makePrimitive(Block{{-1, -1, -1}, {1, 1, 1}}, xf),
         [=](std::mt19937_64& g) mutable { return xf.point(0.5 * Vec3(u(g), u(g), u(g))); }});
    return out;
}

TEST(Precision, FloatSpansLieWithinSinglePrecisionOfTheDoubleOnes) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (Target& tg : targets()) {
        int differing = 0;
        double worst = 0.0;
        for (int i = 0; i < 400;) {
            const Vec3 at = tg.point(rng);
            const Vec3 towards = glm::normalize(Vec3(u(rng), u(rng), u(rng)));
            if (std::abs(glm::dot(towards, tg.facing)) < 0.3 * glm::length(tg.facing)) continue;
            ++i;
            const Vec3 from = at + 20.0 * towards;
            const Ray ray{from, (at - from) * (0.5 + 0.25 * (u(rng) + 1.0))};
            Span d[2], f[2];
            const int nd = tg.prim.spans(ray, 3, d);
            const int nf = tg.prim.spansFloat(ray, 3, f);
            ASSERT_EQ(nd, 1) << tg.name << ": " << ray.toString();
            ASSERT_EQ(nf, nd) << tg.name << ": " << ray.toString();
            // Single precision's rounding (6e-8) of the quantities the test reads: the
            // origin's coordinates and the distance along the ray, many times over.
            const double scale = std::max(
                {std::abs(ray.o.x), std::abs(ray.o.y), std::abs(ray.o.z), glm::length(at - from)});
            const double tol = 2e-5 * scale / glm::length(ray.d);
            for (auto [a, b] : {std::pair{d[0].in, f[0].in}, std::pair{d[0].out, f[0].out}}) {
                EXPECT_NEAR(a.t, b.t, tol) << tg.name << ": " << ray.toString();
                EXPECT_EQ(a.prim, b.prim);
                if (a.t != b.t) ++differing;
                worst = std::max(worst, std::abs(a.t - b.t) / tol);
            }
        }
        // The float path is taken: most of the 800 ends differ in their last bits.
        EXPECT_GT(differing, 400) << tg.name;
        RecordProperty(tg.name, std::to_string(worst));
    }
}

std::vector<std::string> floatScenes() {
    return {"builtin:balls:2", "builtin:drilled:3", "builtin:sponge:2", "builtin:lattice:3"};
}

TEST(Precision, EverySchemeInFloatTracesBruteForceInFloatsHits) {
    for (const std::string& name : floatScenes()) {
        Scene scene = loadScene(name);
        if (!scene.prepared) scene.prepare();
        const std::vector<Ray> rays = test::pixelRays(scene, 40, 40);
        for (const SchemeInfo& info : kSchemeTable) {
            BuildParams p;
            p.scheme = info.kind;
            const auto accel = buildAccelerator(scene, p);
            const auto bad =
                test::compareWithBrute(scene, *accel, rays, 0.0, 0.0, 20, Precision::Float);
            EXPECT_TRUE(bad.empty())
                << name << " " << info.name << ": " << bad.size() << " mismatches, first:\n"
                << (bad.empty() ? "" : bad[0].toString(scene));
        }
    }
}

Image renderIn(const Scene& scene, SchemeKind scheme, Precision precision, int n) {
    BuildParams p;
    p.scheme = scheme;
    const auto accel = buildAccelerator(scene, p);
    RenderOptions ro;
    ro.width = ro.height = n;
    ro.threads = 1;
    ro.shading.precision = precision;
    Image img(n, n);
    render(scene, *accel, ro, img);
    return img;
}

// The whole render: primary rays from the eye buffer's depths, shadow rays in the light
// buffer's stretches, secondaries; every pixel's hit and colour as brute force's in float.
TEST(Precision, EverySchemesFloatImageIsBruteForcesFloatImage) {
    for (const std::string& name : floatScenes()) {
        Scene scene = loadScene(name);
        if (!scene.prepared) scene.prepare();
        const int n = 96;
        const Image ref = renderIn(scene, SchemeKind::Brute, Precision::Float, n);
        for (const SchemeInfo& info : kSchemeTable) {
            const Image img = renderIn(scene, info.kind, Precision::Float, n);
            int hits = 0, colours = 0;
            for (size_t i = 0; i < ref.hitPrim.size(); ++i) {
                hits += ref.hitPrim[i] != img.hitPrim[i] || ref.depth[i] != img.depth[i];
                colours += glm::any(
                    glm::greaterThan(glm::abs(ref.color[i] - img.color[i]), glm::vec3(1e-4f)));
            }
            EXPECT_EQ(hits, 0) << name << " " << info.name;
            EXPECT_EQ(colours, 0) << name << " " << info.name;
        }
    }
}

TEST(Precision, FloatsDepthErrorIsSmallAndNotZero) {
    Scene scene = loadScene("builtin:drilled:3");
    if (!scene.prepared) scene.prepare();
    BuildParams p;
    p.scheme = SchemeKind::Brute;
    const auto brute = buildAccelerator(scene, p);
    TraceContext cd(scene.prims.size(), scene.tree.depth()),
        cf(scene.prims.size(), scene.tree.depth());
    cf.precision = Precision::Float;
    NullObserver obs;
    std::vector<double> rel;
    for (const Ray& r : test::pixelRays(scene, 48, 48)) {
        Hit hd, hf;
        cd.beginRay();
        cf.beginRay();
        const bool fd = brute->intersect(r, 0.0, kInf, cd, obs, hd);
        const bool ff = brute->intersect(r, 0.0, kInf, cf, obs, hf);
        if (!fd || !ff) continue;
        rel.push_back(std::abs(hd.t - hf.t) / hd.t);
    }
    ASSERT_GT(rel.size(), 500u);
    std::sort(rel.begin(), rel.end());
    // Most hits move by a few units of single precision's rounding; a pixel on an edge may see
    // another surface, hence the 99th percentile.
    EXPECT_GT(rel[rel.size() / 2], 1e-9);
    EXPECT_LT(rel[rel.size() * 99 / 100], 1e-5);
}

}  // namespace
}  // namespace lancer
