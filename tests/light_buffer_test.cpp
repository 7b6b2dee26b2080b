// The light buffer (engine/accel/light_buffer.h): nothing meets a shadow ray past the point it
// names, so every accelerated scheme answers each shadow ray as brute force does, on SPD, built-in
// and random CSG scenes, far from the origin too; and it does shorten them.
#include <gtest/gtest.h>

#include "engine/accel/regular/grid_frame.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

std::vector<Vec3> lightPositionsOf(const std::vector<Light>& lights) {
    std::vector<Vec3> out;
    for (const Light& l : lights) out.push_back(l.position);
    return out;
}

struct ShadowRay {
    Ray ray;
    double tmax;
    uint32_t light;
};

/// The tracer's shadow rays from the first hits of `rays` (origin offset off the surface, one per
/// light the surface faces), plus rays from random points of the bounds to each light.
std::vector<ShadowRay> shadowRays(const Scene& s, const std::vector<Ray>& rays, uint64_t seed) {
    auto brute = buildAccelerator(s, BuildParams{});
    Tracer tracer(s, *brute, ShadingOptions{});
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    std::vector<ShadowRay> out;
    auto toLight = [&](const Vec3& from, uint32_t l) {
        const Vec3 L = s.lights[l].position;
        out.push_back({Ray{from, glm::normalize(L - from)}, glm::length(L - from), l});
    };
    for (const Ray& r : rays) {
        Hit hit;
        if (!tracer.nearest(r, 0.0, kInf, ctx, obs, hit)) continue;
        SurfacePoint p = tracer.surface(r, hit);
        const Vec3 above = p.p + tracer.offset(p.p) * p.facing;
        for (uint32_t l = 0; l < s.lights.size(); ++l)
            if (glm::dot(p.facing, s.lights[l].position - p.p) > 0.0) toLight(above, l);
    }
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int k = 0; k < 300; ++k) {
        const Vec3 p = s.bounds.lo + Vec3(u(rng), u(rng), u(rng)) * s.bounds.extent();
        toLight(p, uint32_t(k % s.lights.size()));
    }
    return out;
}

struct Tally {
    size_t rays = 0, blocked = 0, skipped = 0, shortened = 0, segments = 0;
};

/// Checks every shadow ray against brute force: the nearest blocker lies inside one of the light
/// buffer's stretches (so before the last one's end, its free point), and each accelerated
/// scheme answers as brute force does.
Tally checkShadowRays(const std::string& name, const Scene& s, const std::vector<ShadowRay>& rays) {
    auto brute = buildAccelerator(s, BuildParams{});
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    LightBuffer lb(s);
    Tally tally;
    std::vector<std::unique_ptr<Accelerator>> schemes;
    for (StepMethod step : {StepMethod::Exact, StepMethod::Push}) {
        BuildParams p;
        p.scheme = SchemeKind::Regular;
        p.regular.step = step;
        schemes.push_back(buildAccelerator(s, p));
    }
    for (SchemeKind kind : {SchemeKind::Irregular, SchemeKind::Bvh}) {
        BuildParams p;
        p.scheme = kind;
        schemes.push_back(buildAccelerator(s, p));
    }
    size_t failures = 0;
    for (const ShadowRay& sr : rays) {
        ++tally.rays;
        Hit hit;
        ctx.beginRay();
        const bool blocked = brute->intersect(sr.ray, 0.0, sr.tmax, ctx, obs, hit);
        // The stretches the accelerators walk; past the last one nothing can block the ray.
        LightBuffer::Segment seg[LightBuffer::kSlots];
        const int n = lb.shadowSegments(sr.ray.o, sr.ray.d, sr.light, sr.tmax, seg);
        const double free = n < 0 ? kInf : n == 0 ? 0.0 : seg[n - 1].t1;
        double walked = 0.0;
        for (int i = 0; i < n; ++i) walked += seg[i].t1 - seg[i].t0;
        tally.blocked += blocked;
        tally.skipped += n == 0;
        tally.shortened += n > 0 && walked < sr.tmax;
        if (blocked && !(hit.t <= free) && failures++ < 5)
            ADD_FAILURE() << name << ": " << sr.ray.toString() << " toward light " << sr.light
                          << " is blocked at t = " << hit.t << " by p" << hit.prim
                          << ", past the light buffer's free point " << free;
        // The nearest blocker lies in one of them.
        bool inside = n < 0;
        for (int i = 0; i < n; ++i) inside |= seg[i].t0 < hit.t && hit.t <= seg[i].t1;
        tally.segments += n > 0 ? size_t(n) : 0;
        if (blocked && !inside && failures++ < 5)
            ADD_FAILURE() << name << ": " << sr.ray.toString() << " toward light " << sr.light
                          << " is blocked at t = " << hit.t << " by p" << hit.prim
                          << ", outside the light buffer's " << n << " stretches";
        for (const auto& a : schemes) {
            ctx.beginRay();
            const bool got = a->occluded(sr.ray, sr.tmax, sr.light, ctx, obs);
            if (got != blocked && failures++ < 5)
                ADD_FAILURE() << name << " " << schemeName(a->params().scheme) << " "
                              << stepName(a->params().regular.step) << ": " << sr.ray.toString()
                              << " toward light " << sr.light << ": occluded " << got
                              << ", brute force " << blocked;
        }
    }
    EXPECT_EQ(failures, 0u) << name;
    return tally;
}

TEST(LightBuffer, SpdScenesShadowRaysAsBruteForceAndShortened) {
    for (const char* f : {"balls1.nff", "gears1.nff", "tetra3.nff", "rings2.nff"}) {
        Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/" + f);
        Tally t = checkShadowRays(f, s, shadowRays(s, test::pixelRays(s, 48, 48), 7));
        std::printf("%s: %zu shadow rays, %zu blocked, %zu answered with no walk, %zu shortened\n",
                    f, t.rays, t.blocked, t.skipped, t.shortened);
        EXPECT_GT(t.blocked, 0u) << f;
        EXPECT_GT(t.skipped, 0u) << f;
        EXPECT_GT(t.shortened, 0u) << f;
        // Balls: the lit floor's shadow rays, most of the unblocked ones, need no walk at all.
        if (std::string(f) == "balls1.nff") {
            EXPECT_GT(t.skipped, (t.rays - t.blocked) / 2);
        }
    }
}

TEST(LightBuffer, RandomCsgScenesShadowRaysAsBruteForce) {
    Tally all;
    for (uint64_t seed = 1; seed <= 12; ++seed) {
        test::RandomSceneOptions opt;
        opt.surfaces = seed % 2 == 0;
        if (seed >= 10) opt.offset = Vec3(3e5, -2e5, 1e5);  // far from the origin
        Scene s = test::randomCsgScene(seed, opt);
        Tally t = checkShadowRays("random " + std::to_string(seed), s,
                                  shadowRays(s, test::randomRays(s, seed, 1500), seed));
        all.rays += t.rays, all.blocked += t.blocked, all.skipped += t.skipped;
        all.shortened += t.shortened;
    }
    EXPECT_GT(all.blocked, 0u);
    EXPECT_GT(all.skipped, 0u);
    EXPECT_GT(all.shortened, 0u);
}

TEST(LightBuffer, BuiltinCsgScenesShadowRaysAsBruteForce) {
    for (const char* spec : {"builtin:default", "builtin:lattice:3", "builtin:drilled:3"}) {
        Scene s = loadScene(spec);
        Tally t = checkShadowRays(spec, s, shadowRays(s, test::pixelRays(s, 40, 40), 3));
        EXPECT_GT(t.rays, 100u) << spec;
    }
}

// The stretches of a shadow ray cover every box it passes through (between its origin and the
// light), whichever bin its origin falls in: boxes small and large (floors, whose images take
// the whole view and are kept apart from the fine bins), origins on box faces and anywhere.
TEST(LightBuffer, EveryBoxAlongAShadowRayLiesInItsStretches) {
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    size_t checked = 0, walked = 0, none = 0, two = 0;
    for (int scene = 0; scene < 40; ++scene) {
        const double scale = scene % 5 == 4 ? 1e4 : 1.0;
        const Vec3 offset = scene % 7 == 6 ? Vec3(3e5, -2e5, 1e5) : Vec3(0.0);
        std::vector<Box3> boxes;
        Box3 bounds;
        auto add = [&](Vec3 lo, Vec3 hi) {
            boxes.push_back({offset + scale * lo, offset + scale * hi});
            bounds.expand(boxes.back());
        };
        add({-10.0, -10.0, -0.5}, {10.0, 10.0, -0.5});  // a floor: flat, its image the view's
        if (scene % 3 == 0) add({-10.0, -10.0, -1.5}, {-9.0, 10.0, 3.0});  // a wall
        const int count = 1 + scene % 30;
        for (int k = 0; k < count; ++k) {  // an object of small boxes over the floor
            const Vec3 c(u(rng) * 2.0 - 1.0, u(rng) * 2.0 - 1.0, u(rng) * 1.5 - 0.3);
            const Vec3 h(0.01 + 0.3 * u(rng), 0.01 + 0.3 * u(rng),
                         k % 4 == 0 ? 0.0 : 0.01 + 0.3 * u(rng));
            add(c - h, c + h);
        }
        std::vector<Vec3> lights;
        for (int l = 0; l < 4; ++l) {  // beyond the top, or a side
            Vec3 p = bounds.lo + Vec3(u(rng), u(rng), u(rng)) * bounds.extent();
            const int a = l == 0 ? 2 : int(u(rng) * 3.0) % 3;
            p[a] = bounds.hi[a] + (0.01 + u(rng)) * bounds.extent()[a] + scale;
            lights.push_back(p);
        }
        for (int bins : {LightBuffer::kBins, 5}) {
            LightBuffer lb(bounds, boxes, lights, bins);
            ASSERT_EQ(lb.mappedLights(), lights.size());
            for (int k = 0; k < 1500; ++k) {
                // Anywhere in the bounds, on the floor, or on a face of an object's box.
                Vec3 o = bounds.lo + Vec3(u(rng), u(rng), u(rng)) * bounds.extent();
                const Box3& on = boxes[size_t(k) % boxes.size()];
                if (k % 3 == 1) o = on.lo + Vec3(u(rng), u(rng), 1.0) * on.extent();
                const uint32_t light = uint32_t(k) % uint32_t(lights.size());
                const Vec3 L = lights[light];
                const Ray ray{o, glm::normalize(L - o)};
                const double tmax = glm::length(L - o);
                LightBuffer::Segment seg[LightBuffer::kSlots];
                const int n = lb.shadowSegments(ray.o, ray.d, light, tmax, seg);
                ASSERT_GE(n, 0) << "the origin is in the bounds, the light outside";
                none += n == 0;
                two += n == 2;
                walked += n > 0;
                for (int i = 0; i + 1 < n; ++i) ASSERT_LT(seg[i].t1, seg[i + 1].t0);
                for (const Box3& b : boxes) {
                    double ta, tb;
                    if (!clipLine(ray, b, ta, tb)) continue;
                    ta = std::max(ta, 0.0), tb = std::min(tb, tmax);
                    if (!(ta < tb) || tb <= 0.0) continue;
                    ++checked;
                    bool covered = false;
                    for (int i = 0; i < n; ++i) covered |= seg[i].t0 <= ta && tb <= seg[i].t1;
                    ASSERT_TRUE(covered)
                        << "scene " << scene << ", " << bins << " bins: " << ray.toString()
                        << " toward light " << light << " passes through " << b.toString()
                        << " on [" << ta << ", " << tb << "], outside its " << n << " stretches";
                }
            }
        }
    }
    std::printf(
        "%zu boxes on shadow rays checked; %zu rays walked, %zu with two stretches, "
        "%zu with none\n",
        checked, walked, two, none);
    EXPECT_GT(checked, 10000u);
    EXPECT_GT(two, 1000u) << "a floor's stretch apart from the object's";
    EXPECT_GT(none, 1000u);
}

// A light inside the bounds gets no map: the buffer does not know, and the walk runs whole.
TEST(LightBuffer, LightInsideTheBoundsHasNoMap) {
    Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/balls1.nff");
    ASSERT_GE(s.lights.size(), 1u);
    s.lights[0].position = s.bounds.center();
    LightBuffer lb(s);
    EXPECT_EQ(lb.mappedLights(), s.lights.size() - 1);
    const Vec3 o = s.bounds.lo + 0.25 * s.bounds.extent();
    LightBuffer::Segment seg[LightBuffer::kSlots];
    EXPECT_EQ(lb.shadowSegments(o, glm::normalize(s.lights[0].position - o), 0, 1.0, seg), -1);
    Tally t =
        checkShadowRays("balls1, light 0 inside", s, shadowRays(s, test::pixelRays(s, 24, 24), 5));
    EXPECT_GT(t.skipped, 0u);  // the other lights still have theirs
}

/// Checks primary rays from the eye against brute force: nothing is met before nearFrom(). The
/// boxes cut by their turned ones when `turned` is given. Returns the rays it starts past 0.
size_t checkEyeRays(const std::string& name, const Scene& s, const std::vector<Ray>& rays,
                    const FrameChoice* turned = nullptr) {
    auto brute = buildAccelerator(s, BuildParams{});
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    const LightBuffer eye = LightBuffer::forEye(s, s.camera.from, {}, turned);
    EXPECT_EQ(eye.mappedLights(), 1u) << name << ": the camera should be outside the bounds";
    size_t failures = 0, skipped = 0;
    for (const Ray& r : rays) {
        EXPECT_EQ(r.o, s.camera.from);
        Hit hit;
        ctx.beginRay();
        const double near = eye.nearFrom(r.d, 0);
        skipped += near > 0.0;
        if (brute->intersect(r, 0.0, kInf, ctx, obs, hit) && !(hit.t > near) && failures++ < 5)
            ADD_FAILURE() << name << ": " << r.toString() << " hits p" << hit.prim
                          << " at t = " << hit.t << ", before the eye buffer's " << near;
    }
    EXPECT_EQ(failures, 0u) << name;
    return skipped;
}

TEST(EyeBuffer, NothingIsMetBeforeItsNearPoint) {
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (const char* f : {"balls1.nff", "gears1.nff", "rings2.nff", "tetra3.nff"}) {
        Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/" + f);
        std::vector<Ray> rays = test::pixelRays(s, 64, 64);
        for (int k = 0; k < 2000; ++k)  // any direction, grazing ones too
            rays.push_back({s.camera.from, glm::normalize(Vec3(u(rng), u(rng), u(rng)) + 1e-9)});
        EXPECT_GT(checkEyeRays(f, s, rays), rays.size() / 4) << f;
    }
    for (uint64_t seed = 1; seed <= 8; ++seed) {
        test::RandomSceneOptions opt;
        opt.surfaces = seed % 2 == 0;
        if (seed >= 7) opt.offset = Vec3(3e5, -2e5, 1e5);
        Scene s = test::randomCsgScene(seed, opt);
        if (s.bounds.isEmpty()) continue;  // the random tree came out empty
        s.camera.at = s.bounds.center();
        s.camera.from = s.bounds.center() + 1.5 * s.bounds.extent();  // outside
        EXPECT_GT(checkEyeRays("random " + std::to_string(seed), s, test::pixelRays(s, 48, 48)), 0u)
            << "the eye buffer skipped no stretch of any ray of random scene " << seed;
    }
}

// In a turned scene the boxes along the turned frame cut each box's image and depths: the eye
// buffer then starts far more primary rays past the eye, or rules them out (+inf), and the
// lights' buffers leave more shadow rays unwalked, and still nothing is met before (any
// direction, grazing ones too, origins anywhere).
TEST(EyeBuffer, TurnedBoxesRuleOutMoreRaysAndMissNothing) {
    std::mt19937_64 rng(19);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<std::pair<std::string, Scene>> scenes;
    scenes.emplace_back("builtin:sponge:2", loadScene("builtin:sponge:2"));
    for (uint64_t seed = 1; seed <= 4; ++seed)
        scenes.emplace_back("turned bars " + std::to_string(seed), test::turnedBars(seed * 11, 20));
    for (auto& [name, s] : scenes)
        if (s.lights.empty()) s.defaultLights();
    for (auto& [name, s] : scenes) {
        const FrameChoice turned = chooseGridFrame(s);
        ASSERT_TRUE(turned.frame.turned) << name;
        std::vector<Ray> rays = test::pixelRays(s, 64, 64);
        for (int k = 0; k < 1000; ++k)
            rays.push_back({s.camera.from, glm::normalize(Vec3(u(rng), u(rng), u(rng)) + 1e-9)});
        checkEyeRays(name, s, rays);
        checkEyeRays(name + ", turned boxes", s, rays, &turned);
        // Rays the buffer rules out (nothing in their direction): more with the turned boxes.
        // (Ray by ray the two may differ either way: the bins cover the small boxes' images,
        // which the turned boxes shrink.)
        const LightBuffer a = LightBuffer::forEye(s, s.camera.from);
        const LightBuffer b = LightBuffer::forEye(s, s.camera.from, {}, &turned);
        size_t outA = 0, outB = 0;
        for (const Ray& r : rays) {
            outA += a.nearFrom(r.d, 0) == kInf;
            outB += b.nearFrom(r.d, 0) == kInf;
        }
        EXPECT_GT(outB, outA) << name;
        std::printf("%s: %zu rays, ruled out %zu (world boxes) and %zu (turned boxes)\n",
                    name.c_str(), rays.size(), outA, outB);
        // Shadow rays: each scheme as brute force, the turned boxes' buffer (LightBuffer(s)
        // chooses the frame) leaving at least as many rays unwalked as the world boxes'.
        const std::vector<ShadowRay> shadows = shadowRays(s, test::pixelRays(s, 40, 40), 9);
        const Tally t = checkShadowRays(name, s, shadows);
        const LightBuffer worldOnly(s.bounds, s.minBox, lightPositionsOf(s.lights));
        size_t skippedWorld = 0;
        for (const ShadowRay& sr : shadows) {
            LightBuffer::Segment seg[LightBuffer::kSlots];
            skippedWorld +=
                worldOnly.shadowSegments(sr.ray.o, sr.ray.d, sr.light, sr.tmax, seg) == 0;
        }
        EXPECT_GE(t.skipped, skippedWorld) << name;
        EXPECT_GT(t.blocked, 0u) << name;
    }
}

// Whole renders with every bounce, lights and eye buffers on: brute force's image, bit for bit.
TEST(LightBuffer, RegularRendersEqualBruteForce) {
    uint64_t skips = 0;
    for (const char* f : {"balls1.nff", "gears1.nff", "rings2.nff", "tetra3.nff"}) {
        Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/" + f);
        RenderOptions opt;
        opt.width = opt.height = 48;
        opt.threads = 2;
        BuildParams reg;
        reg.scheme = SchemeKind::Regular;
        auto a = buildAccelerator(s, reg), b = buildAccelerator(s, BuildParams{});
        Image ia(48, 48), ib(48, 48);
        RenderStats sa = render(s, *a, opt, ia), sb = render(s, *b, opt, ib);
        EXPECT_EQ(ia.color, ib.color) << f;
        EXPECT_EQ(ia.depth, ib.depth) << f;
        EXPECT_EQ(ia.hitPrim, ib.hitPrim) << f;
        skips += sa.counters.lightBufferSkips;
        EXPECT_EQ(sb.counters.lightBufferSkips, 0u) << f;
    }
    EXPECT_GT(skips, 0u);
}

// Rendering with and without the buffer: the same image, fewer regions visited with it.
TEST(LightBuffer, SameImageFewerRegionVisits) {
    Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/balls1.nff");
    RenderOptions opt;
    opt.width = opt.height = 64;
    opt.threads = 2;
    BuildParams with;
    with.scheme = SchemeKind::Regular;
    BuildParams without = with;
    without.lightBuffer = false;
    auto a = buildAccelerator(s, with), b = buildAccelerator(s, without);
    Image ia(64, 64), ib(64, 64);
    RenderStats sa = render(s, *a, opt, ia), sb = render(s, *b, opt, ib);
    EXPECT_EQ(ia.color, ib.color);
    EXPECT_EQ(sa.counters.shadowRays, sb.counters.shadowRays);
    EXPECT_GT(sa.counters.lightBufferSkips, sa.counters.shadowRays / 4);
    EXPECT_EQ(sb.counters.lightBufferSkips, 0u);
    EXPECT_LT(sa.counters.regionVisits, sb.counters.regionVisits);
    EXPECT_TRUE(a->info().extra.contains("light_buffer_bytes"));
    EXPECT_FALSE(b->info().extra.contains("light_buffer_bytes"));
}

// The eye buffer built with the structure for the scene's camera is the one every render from
// that eye reads (not rebuilt per frame), and answers as one built on demand; a camera moved
// elsewhere gets its own. Renders from both cameras equal brute force's.
TEST(EyeBuffer, TheSceneCameraOneIsBuiltWithTheStructure) {
    Scene s = loadScene(std::string(LANCER_SPD_DIR) + "/balls1.nff");
    BuildParams reg;
    reg.scheme = SchemeKind::Regular;
    auto a = buildAccelerator(s, reg), brute = buildAccelerator(s, BuildParams{});
    ASSERT_TRUE(a->info().extra.contains("eye_buffer_bytes"));
    const auto kept = a->eyeBuffer(s, s.camera);
    EXPECT_EQ(kept.get(), a->eyeBuffer(s, s.camera).get());
    EXPECT_EQ(kept->mappedLights(), 1u);
    const LightBuffer fresh = Accelerator::makeEyeBuffer(s, s.camera, reg);
    for (const Ray& r : test::pixelRays(s, 32, 32))
        EXPECT_EQ(kept->nearFrom(r.d, 0), fresh.nearFrom(r.d, 0));
    Camera moved = s.camera;
    moved.from += 0.25 * s.bounds.extent();
    const auto other = a->eyeBuffer(s, moved);
    EXPECT_NE(other.get(), kept.get());
    EXPECT_EQ(other->mappedLights(), 1u);
    // Brute force and --no-light-buffer have none.
    EXPECT_EQ(brute->eyeBuffer(s, s.camera)->mappedLights(), 0u);
    EXPECT_FALSE(brute->info().extra.contains("eye_buffer_bytes"));
    for (const Camera& cam : {s.camera, moved}) {
        RenderOptions opt;
        opt.width = opt.height = 40;
        opt.camera = cam;
        Image ia(40, 40), ib(40, 40);
        render(s, *a, opt, ia);
        render(s, *brute, opt, ib);
        EXPECT_EQ(ia.color, ib.color);
        EXPECT_EQ(ia.hitPrim, ib.hitPrim);
    }
}

}  // namespace
}  // namespace lancer
