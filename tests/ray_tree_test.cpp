// A pixel's ray tree (engine/render/ray_tree.h): recorded by the code that renders, so its counts
// are the renderer's per-pixel counters; its rays are the ones the shading casts, with the right
// kinds and parents; recording is repeatable; and each walk says how it got from one region to
// the next (the exit, then the rope, the index step or the pushed point and the directory cell,
// or the corner pointers).
#include "engine/render/ray_tree.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iostream>
#include <random>
#include <sstream>
#include <thread>

#include "engine/accel/structure_view.h"
#include "engine/render/progressive.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "support/differential.h"
#include "support/hexahedron.h"

namespace lancer {
namespace {

struct Config {
    std::string scene;
    SchemeKind scheme;
    StepMethod step = StepMethod::Exact;
    IrregularFrame frame = IrregularFrame::Projective;
    int bounces = 0;
    std::string name() const {
        std::string s = scene + " " + schemeName(scheme);
        if (scheme == SchemeKind::Regular) s += std::string(" ") + stepName(step);
        if (scheme == SchemeKind::Irregular) s += std::string(" ") + irregularFrameName(frame);
        return s + " bounces " + std::to_string(bounces);
    }
};

BuildParams paramsOf(const Config& c) {
    BuildParams p;
    p.scheme = c.scheme;
    p.regular.step = c.step;
    p.irregular.frame = c.frame;
    return p;
}

std::vector<Config> configs() {
    std::vector<Config> out;
    for (const char* scene : {"builtin:default", "builtin:balls:1", "builtin:lattice:2",
                              "builtin:rings:2", "builtin:drilled:2"})
        for (int bounces : {0, 2}) {
            out.push_back({scene, SchemeKind::Regular, StepMethod::Exact,
                           IrregularFrame::Projective, bounces});
            out.push_back({scene, SchemeKind::Regular, StepMethod::Push, IrregularFrame::Projective,
                           bounces});
            out.push_back({scene, SchemeKind::Irregular, StepMethod::Exact,
                           IrregularFrame::Projective, bounces});
            out.push_back(
                {scene, SchemeKind::Irregular, StepMethod::Exact, IrregularFrame::Camera, bounces});
            out.push_back(
                {scene, SchemeKind::Brute, StepMethod::Exact, IrregularFrame::Projective, bounces});
        }
    return out;
}

/// The counters a ray's events account for, summed over the tree.
RayCounters sumOfRays(const RayTree& t) {
    RayCounters c;
    for (const TracedRay& r : t.rays) c += r.counters;
    return c;
}

// RayCounters::fields() drives +=, -, toString and toJson: each counter, set alone, is summed
// and subtracted by itself, written under its own key, and the text keeps its layout.
TEST(RayTree, CounterFieldsAreSummedAndWrittenOnce) {
    RayCounters base;
    for (const RayCounters::Field& f : RayCounters::fields()) base.*f.member = 100;
    uint64_t n = 0;
    for (const RayCounters::Field& f : RayCounters::fields()) {
        SCOPED_TRACE(f.key);
        RayCounters one;
        one.*f.member = ++n;
        RayCounters sum = base;
        sum += one;
        for (const RayCounters::Field& g : RayCounters::fields())
            EXPECT_EQ(sum.*g.member, g.member == f.member ? 100 + n : 100u) << g.key;
        EXPECT_EQ(sum - one, base);
        const nlohmann::json j = toJson(one);
        EXPECT_EQ(j.size(), RayCounters::fields().size());
        EXPECT_EQ(j.at(f.key).get<uint64_t>(), n);
    }
    RayCounters c;
    n = 0;
    for (const RayCounters::Field& f : RayCounters::fields()) c.*f.member = ++n;
    EXPECT_EQ(c.toString(),
              "rays 1 (2 primary, 3 shadow), prim tests 4, mailbox hits 5, regions 6, pointer "
              "steps 7, walk errors 8, light buffer skips 9");
}

// Every pixel of small images: the tree's counts are the render's per-pixel counters (tests and
// regions, the viewer's heat maps), its colour and depth the render's, and over the image the
// trees' counters add up to the render's totals (mailbox hits included).
TEST(RayTree, CountsEqualTheRendersPerPixelCounters) {
    const int w = 20, h = 14;
    for (const Config& c : configs()) {
        SCOPED_TRACE(c.name());
        Scene scene = loadScene(c.scene);
        auto accel = buildAccelerator(scene, paramsOf(c));
        RenderOptions ro;
        ro.width = w;
        ro.height = h;
        ro.threads = 2;
        ro.shading.bounces = c.bounces;
        Image img(w, h);
        const RenderStats stats = render(scene, *accel, ro, img);
        RayCounters total;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const RayTree t = tracePixel(scene, *accel, ro.shading, scene.camera, x, y, w, h);
                const size_t i = img.index(x, y);
                ASSERT_EQ(t.counters.primTests, img.primTests[i]) << x << " " << y;
                ASSERT_EQ(t.counters.regionVisits, img.regionVisits[i]) << x << " " << y;
                ASSERT_EQ(glm::vec3(t.color), img.color[i]) << x << " " << y;
                const TracedRay& p = t.rays.front();
                ASSERT_EQ(p.hit.prim, img.hitPrim[i]);
                if (p.hit.valid()) {
                    ASSERT_EQ(float(p.hit.t), img.depth[i]);
                }
                // The events account for every count the walks made.
                ASSERT_EQ(sumOfRays(t), t.counters) << t.toString(&scene);
                ASSERT_EQ(t.counters.rays, t.rays.size());
                total += t.counters;
            }
        EXPECT_EQ(total, stats.counters);
    }
}

// The viewer's heat maps read the progressive renderer's per-pixel counters: once its passes
// have finished, every pixel's tests and regions are those of the pixel's ray tree (both
// schemes, secondary rays included), as `lancer trace` counts them.
TEST(RayTree, CountsEqualTheViewersProgressiveCounters) {
    const int w = 24, h = 16;
    for (const Config& c : configs()) {
        if (c.scene != "builtin:default" || c.bounces == 0) continue;
        SCOPED_TRACE(c.name());
        auto scene = std::make_shared<const Scene>(loadScene(c.scene));
        std::shared_ptr<const Accelerator> accel = buildAccelerator(*scene, paramsOf(c));
        RenderOptions ro;
        ro.width = w;
        ro.height = h;
        ro.threads = 2;
        ro.shading.bounces = c.bounces;
        ProgressiveRenderer pr;
        pr.start({scene, accel, ro});
        const auto start = std::chrono::steady_clock::now();
        while (!pr.finished()) {
            ASSERT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(60));
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
        Image shown;
        uint64_t version = 0;
        ASSERT_TRUE(pr.snapshot(version, shown));
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const RayTree t = tracePixel(*scene, *accel, ro.shading, scene->camera, x, y, w, h);
                const size_t i = shown.index(x, y);
                ASSERT_EQ(t.counters.primTests, shown.primTests[i]) << x << " " << y;
                ASSERT_EQ(t.counters.regionVisits, shown.regionVisits[i]) << x << " " << y;
            }
    }
}

bool facesLight(const TracedRay& r, const Vec3& light) {
    const Vec3 facing = glm::dot(r.normal, r.direction) < 0.0 ? r.normal : -r.normal;
    // As the tracer computes it, to the last bit.
    const Vec3 L = light - r.point;
    const double dist = glm::length(L);
    return dist > 0.0 && glm::dot(facing, L / dist) > 0.0;
}

// Kinds and parents: the primary ray first; a shadow ray per light the surface faces, from the
// ray whose hit it lights; reflection and refraction rays only from hits on materials that
// reflect or transmit, and only above the bounce limit; children after their parent.
TEST(RayTree, KindsAndParentsFollowTheShading) {
    const int w = 24, h = 16;
    size_t shadows = 0, reflections = 0, refractions = 0;
    for (const Config& c : configs()) {
        if (c.step == StepMethod::Push || c.frame == IrregularFrame::Camera) continue;
        SCOPED_TRACE(c.name());
        Scene scene = loadScene(c.scene);
        auto accel = buildAccelerator(scene, paramsOf(c));
        ShadingOptions sh;
        sh.bounces = c.bounces;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const RayTree t = tracePixel(scene, *accel, sh, scene.camera, x, y, w, h);
                ASSERT_FALSE(t.rays.empty());
                ASSERT_EQ(t.rays[0].kind, RayKind::Primary);
                ASSERT_EQ(t.rays[0].parent, -1);
                for (size_t i = 0; i < t.rays.size(); ++i) {
                    const TracedRay& r = t.rays[i];
                    SCOPED_TRACE(t.toString(&scene));
                    ASSERT_EQ(r.events.front().kind(), WalkEvent::RayBegin);
                    ASSERT_EQ(r.events.back().kind(), WalkEvent::RayEnd);
                    if (i > 0) {
                        ASSERT_GE(r.parent, 0);
                        ASSERT_LT(size_t(r.parent), i);
                        ASSERT_NE(t.rays[size_t(r.parent)].kind, RayKind::Shadow);
                        ASSERT_TRUE(t.rays[size_t(r.parent)].hit.valid());
                    }
                    if (r.kind == RayKind::Shadow) {
                        ASSERT_GE(r.light, 0);
                        ASSERT_EQ(r.depth, t.rays[size_t(r.parent)].depth);
                    } else if (i > 0) {
                        ASSERT_EQ(r.depth, t.rays[size_t(r.parent)].depth + 1);
                        ASSERT_LE(r.depth, c.bounces);
                    }
                    // This ray's children, against what its hit calls for.
                    std::vector<int> lights;
                    int refl = 0, refr = 0;
                    for (const TracedRay& k : t.rays) {
                        if (&k - t.rays.data() <= ptrdiff_t(i) || k.parent != int(i)) continue;
                        if (k.kind == RayKind::Shadow) lights.push_back(k.light);
                        refl += k.kind == RayKind::Reflection;
                        refr += k.kind == RayKind::Refraction;
                    }
                    if (r.kind == RayKind::Shadow || !r.hit.valid()) {
                        ASSERT_TRUE(lights.empty() && refl == 0 && refr == 0);
                        continue;
                    }
                    std::vector<int> expected;
                    for (size_t l = 0; l < scene.lights.size(); ++l)
                        if (facesLight(r, scene.lights[l].position)) expected.push_back(int(l));
                    ASSERT_EQ(lights, expected);
                    const Material& m = scene.materials[size_t(scene.prims[r.hit.prim].material)];
                    const bool deeper = r.depth < c.bounces;
                    ASSERT_EQ(refl, deeper && m.reflect > 0.0 ? 1 : 0);
                    ASSERT_EQ(refr, deeper && m.transmit > 0.0 ? 1 : 0);
                    shadows += lights.size();
                    reflections += size_t(refl);
                    refractions += size_t(refr);
                }
            }
    }
    EXPECT_GT(shadows, 0u);
    EXPECT_GT(reflections, 0u);
    EXPECT_GT(refractions, 0u);
}

// Recording twice gives the same trees, event for event: step k of a playback is stable.
TEST(RayTree, RecordingIsRepeatable) {
    for (const Config& c : configs()) {
        if (c.bounces == 0) continue;
        SCOPED_TRACE(c.name());
        Scene scene = loadScene(c.scene);
        auto accel = buildAccelerator(scene, paramsOf(c));
        ShadingOptions sh;
        sh.bounces = c.bounces;
        for (int k = 0; k < 16; ++k) {
            const int x = (k * 7) % 16, y = (k * 5) % 12;
            const RayTree a = tracePixel(scene, *accel, sh, scene.camera, x, y, 16, 12);
            const RayTree b = tracePixel(scene, *accel, sh, scene.camera, x, y, 16, 12);
            ASSERT_EQ(a.rays.size(), b.rays.size());
            for (size_t i = 0; i < a.rays.size(); ++i) {
                ASSERT_EQ(a.rays[i].events, b.rays[i].events);
                ASSERT_EQ(a.rays[i].regionSteps(), b.rays[i].regionSteps());
            }
            ASSERT_EQ(a.toString(&scene), b.toString(&scene));
        }
    }
}

/// The region the same walk enters after event `i`, or -1 (a light-buffer stretch starts a
/// walk of its own).
int64_t nextRegion(const std::vector<WalkEvent>& ev, size_t i) {
    for (size_t k = i + 1; k < ev.size(); ++k) {
        if (ev[k].kind() == WalkEvent::Stretch) return -1;
        if (const walk::Region* g = ev[k].get<walk::Region>()) return g->region;
    }
    return -1;
}

// Why the next region is the next: between two region events of one walk come the exit (its
// point on the tied planes at its t) and, regular exact, the rope to the next leaf or the index
// step and the directory cell of the next leaf; regular push, the pushed point and its cell;
// irregular (camera frame), a chain of corner pointers from the region left to the next one.
TEST(RayTree, EachStepSaysHowTheNextRegionIsReached) {
    size_t ropes = 0, steps = 0, pushes = 0, pointers = 0, exits = 0;
    for (const Config& c : configs()) {
        if (c.scheme == SchemeKind::Brute || c.bounces == 0) continue;
        SCOPED_TRACE(c.name());
        Scene scene = loadScene(c.scene);
        auto accel = buildAccelerator(scene, paramsOf(c));
        ShadingOptions sh;
        sh.bounces = c.bounces;
        for (int y = 0; y < 12; ++y)
            for (int x = 0; x < 16; ++x) {
                const RayTree t = tracePixel(scene, *accel, sh, scene.camera, x, y, 16, 12);
                for (const TracedRay& r : t.rays) {
                    const std::vector<WalkEvent>& ev = r.events;
                    const Ray ray{r.origin, r.direction};
                    int64_t current = -1;
                    for (size_t i = 0; i < ev.size(); ++i) {
                        const WalkEvent& e = ev[i];
                        SCOPED_TRACE(e.toString());
                        if (const walk::Region* g = e.get<walk::Region>()) current = g->region;
                        if (e.kind() == WalkEvent::Stretch) current = -1;
                        const walk::Exit* x = e.get<walk::Exit>();
                        if (!x) continue;
                        ++exits;
                        ASSERT_GE(current, 0);
                        ASSERT_NE(x->ties, 0);
                        ASSERT_TRUE(x->ties >> x->axis & 1);
                        const Vec3 at = ray.at(x->t);
                        const double tol = 1e-7 * std::max(scene.scale(), glm::length(at));
                        for (int a = 0; a < 3; ++a) ASSERT_NEAR(x->point[a], at[a], tol);
                        const int64_t next = nextRegion(ev, i);
                        if (next < 0) continue;  // out of the structure, or the stretch's end
                        const WalkEvent& how = ev[i + 1];
                        if (c.scheme == SchemeKind::Regular) {
                            if (const walk::Rope* rope = how.get<walk::Rope>();
                                c.step == StepMethod::Exact && rope) {
                                ++ropes;
                                ASSERT_EQ(rope->from, current);
                                ASSERT_EQ(int64_t(rope->to), next);
                                ASSERT_EQ(rope->face / 2, x->axis);
                            } else {
                                ASSERT_EQ(how.kind(), c.step == StepMethod::Exact
                                                          ? WalkEvent::IndexStep
                                                          : WalkEvent::Push);
                                (how.kind() == WalkEvent::Push ? pushes : steps)++;
                                const walk::Lookup* look = ev[i + 2].get<walk::Lookup>();
                                ASSERT_NE(look, nullptr);
                                ASSERT_EQ(int64_t(look->leaf), next);
                                if (const walk::IndexStep* is = how.get<walk::IndexStep>()) {
                                    ASSERT_EQ(look->cell, is->cell);
                                }
                            }
                        } else if (how.kind() == WalkEvent::Pointer) {
                            int64_t at = current;
                            size_t k = i + 1;
                            for (; k < ev.size() && ev[k].kind() == WalkEvent::Pointer; ++k) {
                                const walk::Pointer& p = ev[k].as<walk::Pointer>();
                                ASSERT_EQ(int64_t(p.from), at);
                                at = p.to;
                                ++pointers;
                            }
                            ASSERT_EQ(ev[k].kind(), WalkEvent::Region);
                            ASSERT_EQ(at, next);
                        } else {
                            // Projective zones: the next slab in depth, no pointer.
                            ASSERT_EQ(how.kind(), WalkEvent::Region);
                        }
                    }
                }
            }
    }
    EXPECT_GT(exits, 0u);
    EXPECT_GT(ropes, 0u);
    EXPECT_GT(steps, 0u);
    EXPECT_GT(pushes, 0u);
    EXPECT_GT(pointers, 0u);
}

/// The regular walk clips rays to its box grown by a hair, 1e-9 of the box's largest extent
/// plus its largest corner's distance from the origin (regular_grid.cpp): a ray passing within
/// that hair of the box, and no nearer, walks the border leaf there. 0 for the other schemes.
double clipHair(const StructureView& view) {
    const RegularGrid* g = view.regular();
    if (!g) return 0.0;
    const Vec3 e = g->box().extent();
    return 1e-9 * (std::max({e.x, e.y, e.z}) +
                   std::max(glm::length(g->box().lo), glm::length(g->box().hi)));
}

/// Check that each region event's corners hold the ray's stretch in it (its ends and middle,
/// within 1e-9 of the scene's size, and the regular walk's clip hair); returns the regions
/// checked.
size_t checkCorners(const StructureView& view, const Ray& ray, const std::vector<WalkEvent>& ev,
                    double scale) {
    size_t n = 0;
    const double hair = clipHair(view);
    for (const WalkEvent& e : ev) {
        const walk::Region* g = e.get<walk::Region>();
        if (!g) continue;
        const std::array<Vec3, 8> c = view.regionCorners(g->region);
        for (double t : {g->t0, 0.5 * (g->t0 + g->t1), g->t1}) {
            const Vec3 p = ray.at(t);
            const double tol = 1e-9 * std::max(scale, glm::length(p)) + hair;
            EXPECT_LE(test::outside(c, p), tol)
                << ray.toString() << " region " << g->region << " t = " << t << " of [" << g->t0
                << ", " << g->t1 << "] " << view.toString(g->region);
        }
        ++n;
    }
    return n;
}

// Every region event's corners (the structure description's, which `lancer trace --json`
// writes) hold the ray's stretch in that region: every ray of random pixels' trees of random
// scenes (primary, shadow, reflected, refracted), and rays from the regions' own corners and
// face centres (origins on region boundaries), for both schemes and both irregular frames.
TEST(RayTree, RegionCornersHoldTheRaysStretch) {
    size_t checked = 0, boundaryRays = 0;
    for (uint64_t seed = 1; seed <= 6; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 10 + int(seed) * 3;
        opt.surfaces = seed % 2 == 0;
        Scene scene = test::randomGlassyCsgScene(seed, opt);
        std::mt19937_64 rng(seed);
        std::uniform_int_distribution<int> px(0, 31);
        for (const Config& c : configs()) {
            if (c.scheme == SchemeKind::Brute || c.scene != "builtin:default" || c.bounces == 0)
                continue;
            SCOPED_TRACE(c.name() + " seed " + std::to_string(seed));
            auto accel = buildAccelerator(scene, paramsOf(c));
            const StructureView view(scene, *accel);
            ShadingOptions sh;
            sh.bounces = 2;
            for (int k = 0; k < 12; ++k) {
                const RayTree t =
                    tracePixel(scene, *accel, sh, scene.camera, px(rng), px(rng), 32, 32);
                for (const TracedRay& r : t.rays)
                    checked +=
                        checkCorners(view, Ray{r.origin, r.direction}, r.events, scene.scale());
            }
            // Rays from the corners and face centres of regions the walks visit.
            std::uniform_int_distribution<size_t> pick(0, view.regionCount() - 1);
            std::normal_distribution<double> gauss;
            TraceContext ctx(scene.prims.size(), scene.tree.depth());
            ctx.useMailboxes = accel->usesMailboxes();
            for (int k = 0; k < 30; ++k) {
                const uint32_t id = uint32_t(pick(rng));
                const RegionInfo info = view.region(id);
                if (info.kind != RegionKind::Leaf && info.kind != RegionKind::Slab) continue;
                const std::array<Vec3, 8> cs = view.regionCorners(id);
                // A corner, and the centre of the low face on the region's first axis.
                const Vec3 origins[2] = {cs[size_t(k % 8)], 0.5 * (cs[0] + cs[6])};
                for (const Vec3& o : origins) {
                    Vec3 d(gauss(rng), gauss(rng), gauss(rng));
                    if (k % 3 == 0) {  // along an axis, in the region's face planes
                        d = Vec3(0.0);
                        d[k % 9 / 3] = k % 2 ? 1.0 : -1.0;
                    }
                    if (glm::length(d) == 0.0) continue;
                    const Ray ray{o, glm::normalize(d)};
                    RecordingObserver obs = test::recordWalk(*accel, ray, ctx);
                    checked += checkCorners(view, ray, obs.events, scene.scale());
                    ++boundaryRays;
                }
            }
        }
    }
    EXPECT_GT(checked, 1000u);
    EXPECT_GT(boundaryRays, 100u);
}

/// Index of the region event the same walk enters after event `i` (a light-buffer stretch
/// starts a walk of its own), or -1.
int64_t nextRegionEvent(const std::vector<WalkEvent>& ev, size_t i) {
    for (size_t k = i + 1; k < ev.size(); ++k) {
        if (ev[k].kind() == WalkEvent::Stretch) return -1;
        if (ev[k].kind() == WalkEvent::Region) return int64_t(k);
    }
    return -1;
}

// The irregular scheme's projective zones tell their walk as the camera-frame walk does: the
// region the walk starts in (Locate: it holds the point, and it is the next region event's),
// and each region left before the ray's interval ends (Exit: the point on the region's
// boundary, at the ray's point of its t, where the region's stretch ends; the next region event
// starts there and holds the point just past it). Every ray of random pixels' trees (primary
// rays walk the projective slabs, secondary rays the camera frame) of random scenes and
// built-in scenes seen by a perspective camera.
TEST(RayTree, ProjectiveWalkTellsItsExitsAndLocates) {
    size_t projectiveExits = 0, projectiveLocates = 0, cameraExits = 0, nearExits = 0, scenes = 0;
    auto check = [&](const Scene& scene, int w, int h, uint64_t seed) {
        ASSERT_EQ(scene.camera.projection, Projection::Perspective);
        BuildParams p;
        p.scheme = SchemeKind::Irregular;
        p.irregular.frame = IrregularFrame::Projective;
        auto accel = buildAccelerator(scene, p);
        const StructureView view(scene, *accel);
        const uint32_t firstProjective = uint32_t(view.irregular()->regions().size());
        if (view.irregular()->projective().zoneCount() == 0) return;  // nothing before the eye
        ++scenes;
        ShadingOptions sh;
        sh.bounces = 2;
        std::mt19937_64 rng(seed);
        std::uniform_int_distribution<int> px(0, w - 1), py(0, h - 1);
        for (int k = 0; k < 40; ++k) {
            const RayTree t = tracePixel(scene, *accel, sh, scene.camera, px(rng), py(rng), w, h);
            for (const TracedRay& r : t.rays) {
                const Ray ray{r.origin, r.direction};
                const std::vector<WalkEvent>& ev = r.events;
                int64_t current = -1;
                for (size_t i = 0; i < ev.size(); ++i) {
                    const WalkEvent& e = ev[i];
                    if (e.kind() == WalkEvent::Region) current = int64_t(i);
                    if (e.kind() == WalkEvent::Stretch) current = -1;
                    if (const walk::Locate* loc = e.get<walk::Locate>()) {
                        SCOPED_TRACE(e.toString() + " of " + r.toString());
                        const double tol = 1e-9 * std::max(scene.scale(), glm::length(loc->point));
                        const int64_t n = nextRegionEvent(ev, i);
                        ASSERT_GE(n, 0);
                        const walk::Region& first = ev[size_t(n)].as<walk::Region>();
                        ASSERT_EQ(first.region, loc->region);
                        EXPECT_LE(test::outside(view.regionCorners(loc->region), loc->point), tol);
                        const Vec3 at = ray.at(first.t0);
                        EXPECT_LE(glm::length(at - loc->point), tol);
                        projectiveLocates += loc->region >= firstProjective;
                        continue;
                    }
                    const walk::Exit* x = e.get<walk::Exit>();
                    if (!x) continue;
                    SCOPED_TRACE(e.toString() + " of " + r.toString());
                    const double tol = 1e-9 * std::max(scene.scale(), glm::length(x->point));
                    const int64_t n = nextRegionEvent(ev, i);
                    ASSERT_GE(current, 0);
                    const walk::Region& left = ev[size_t(current)].as<walk::Region>();
                    const std::array<Vec3, 8> c = view.regionCorners(left.region);
                    EXPECT_LE(test::outside(c, x->point), tol);
                    EXPECT_LE(test::toBoundary(c, x->point), tol);
                    EXPECT_LE(glm::length(ray.at(x->t) - x->point), tol);
                    EXPECT_EQ(left.t1, x->t);
                    if (left.region >= firstProjective) {
                        ++projectiveExits;
                        EXPECT_EQ(x->axis, 2);
                        EXPECT_EQ(x->ties, 4);
                        nearExits += view.region(left.region).kind == RegionKind::NearRegion;
                    } else {
                        ++cameraExits;
                    }
                    if (n < 0) continue;  // out of the structure
                    const walk::Region& next = ev[size_t(n)].as<walk::Region>();
                    EXPECT_EQ(next.t0, x->t);
                    if (left.region >= firstProjective) {
                        EXPECT_EQ(size_t(n), i + 1) << "a projective step follows no pointer";
                    }
                    if (!(next.t1 > next.t0)) continue;  // an edge or corner's zero-length step
                    const double past =
                        x->t + std::min(1e-6 * scene.scale(), 0.5 * (next.t1 - next.t0));
                    const Vec3 q = ray.at(past);
                    EXPECT_LE(test::outside(view.regionCorners(next.region), q),
                              1e-9 * std::max(scene.scale(), glm::length(q)))
                        << view.toString(next.region);
                }
            }
        }
    };
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 10 + int(seed) * 3;
        Scene scene = test::randomGlassyCsgScene(seed, opt);
        SCOPED_TRACE("seed " + std::to_string(seed));
        check(scene, 32, 24, seed);
    }
    for (const char* spec : {"builtin:default", "builtin:balls:1", "builtin:drilled:2"}) {
        SCOPED_TRACE(spec);
        check(loadScene(spec), 64, 48, 7);
    }
    EXPECT_GE(scenes, 5u);
    EXPECT_GT(projectiveExits, 100u);
    EXPECT_GT(projectiveLocates, 50u);
    EXPECT_GT(cameraExits, 100u);
    std::cout << "projective exits " << projectiveExits << " (near region " << nearExits
              << "), locates " << projectiveLocates << "; camera-frame exits " << cameraExits
              << "\n";
}

// Rays grazing the structure's border, for both schemes (regular exact and push, irregular
// camera frame and projective): from the border's corners, edge midpoints, face centres and
// the border corners of the regions there (origins on region boundaries), along the border's
// edges and faces, and tilted 1e-7 into or out of its faces. Every region's corners hold the
// ray's stretch in it (regular leaves, and the camera frame's slabs, the border's sliver slabs
// about 1e-9 of the coordinates deep included: see test::facePlanes). The regular stretches told
// start where the ray enters the structure's box and the last ends where the ray leaves its region,
// so a ray leaving the grid through an edge or a corner no longer runs on into the next leaf
// outside the box (a ray passing within the regular walk's clip hair of the box, and no nearer,
// stays within that hair of the border leaf it walks). No walk ends in an error, and the hits are
// brute force's.
TEST(RayTree, GrazingRaysAtTheStructureBorder) {
    size_t checked = 0, cameraChecked = 0, rays = 0;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 12 + int(seed) * 3;
        opt.surfaces = seed % 2 == 0;
        Scene scene = seed == 4 ? loadScene("builtin:default") : test::randomCsgScene(seed, opt);
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> unit(0.0, 1.0);
        for (const Config& c : configs()) {
            // Rays off the eye walk the camera frame: the projective build adds nothing here.
            if (c.scheme == SchemeKind::Brute || c.scene != "builtin:default" || c.bounces == 0 ||
                (c.scheme == SchemeKind::Irregular && c.frame == IrregularFrame::Projective))
                continue;
            SCOPED_TRACE(c.name() + " seed " + std::to_string(seed));
            auto accel = buildAccelerator(scene, paramsOf(c));
            const StructureView view(scene, *accel);
            const std::array<Vec3, 8> B = view.structureCorners();
            // Origins: the border's corners, edge midpoints and face centres, and the corners
            // on the border of the regions holding the face centres.
            struct Start {
                Vec3 o;
                int axis, side;  // a face of the border it lies on
            };
            std::vector<Start> starts;
            for (int a = 0; a < 3; ++a)
                for (int side = 0; side < 2; ++side) {
                    const int b = (a + 1) % 3, d = (a + 2) % 3;
                    const auto corner = [&](int i, int j) {
                        return B[size_t((side << a) | (i << b) | (j << d))];
                    };
                    const Vec3 centre =
                        0.25 * (corner(0, 0) + corner(1, 0) + corner(0, 1) + corner(1, 1));
                    starts.push_back({centre, a, side});
                    starts.push_back({corner(0, 0), a, side});
                    starts.push_back({corner(1, 1), a, side});
                    starts.push_back({0.5 * (corner(0, 0) + corner(1, 0)), a, side});
                    starts.push_back({0.5 * (corner(0, 1) + corner(1, 1)), a, side});
                    if (c.scheme == SchemeKind::Regular ||
                        (c.scheme == SchemeKind::Irregular && view.irregular())) {
                        const uint32_t id = view.regionAt(centre);
                        const std::array<Vec3, 8> rc = view.regionCorners(id);
                        for (int k = 0; k < 8; ++k)
                            if ((k >> a & 1) == side) starts.push_back({rc[size_t(k)], a, side});
                    }
                }
            std::vector<Ray> all;
            TraceContext ctx(scene.prims.size(), scene.tree.depth());
            ctx.useMailboxes = accel->usesMailboxes();
            for (const Start& st : starts) {
                const int a = st.axis, b = (a + 1) % 3, d = (a + 2) % 3;
                // The face's two edge directions and its outward normal, in the world.
                const Vec3 e1 = glm::normalize(B[size_t(1 << b)] - B[0]);
                const Vec3 e2 = glm::normalize(B[size_t(1 << d)] - B[0]);
                const Vec3 out = glm::normalize(B[size_t(1 << a)] - B[0]) * (st.side ? 1.0 : -1.0);
                std::vector<Vec3> dirs = {e1, -e1, e2, -e2};
                for (int k = 0; k < 4; ++k) {
                    const double th = 2.0 * M_PI * unit(rng);
                    const Vec3 along = std::cos(th) * e1 + std::sin(th) * e2;
                    dirs.push_back(along);
                    dirs.push_back(glm::normalize(along + 1e-7 * out));
                    dirs.push_back(glm::normalize(along - 1e-7 * out));
                }
                for (const Vec3& dir : dirs) {
                    // From the point, and from outside the box toward it along the face.
                    for (const Ray& ray :
                         {Ray{st.o, dir}, Ray{st.o - 2.0 * scene.scale() * dir, dir}}) {
                        RecordingObserver obs = test::recordWalk(*accel, ray, ctx);
                        const size_t n = checkCorners(view, ray, obs.events, scene.scale());
                        checked += n;
                        if (c.scheme == SchemeKind::Irregular) cameraChecked += n;
                        for (const WalkEvent& e : obs.events)
                            EXPECT_NE(e.kind(), WalkEvent::Error)
                                << e.toString() << " " << ray.toString();
                        all.push_back(ray);
                        ++rays;
                    }
                }
            }
            const std::vector<test::RayMismatch> bad = test::compareWithBrute(scene, *accel, all);
            for (const test::RayMismatch& m : bad) ADD_FAILURE() << m.toString(scene);
        }
    }
    EXPECT_GT(rays, 1000u);
    EXPECT_GT(checked, rays / 2);
    EXPECT_GT(cameraChecked, rays / 4);
}

// Rays entering the camera frame's structure exactly at a region's corner, perspective and
// orthographic cameras, on the scene where a ray entering at the structure's corner read 2e-8 off
// its sliver slab (a random scene, scale 3.6) and on builtin:default, with the default 2D stop and
// none. Every region, the slivers among them (the border slabs and zones about 1e-9 of the
// coordinates thin: the padding of the structure's box beyond the primitives' boxes). From each
// region's corners: toward the region's centre, along its three edges (grazing its faces) and along
// the primary ray through the corner (from the eye, or along the view axis), each from the corner
// itself and from 2 x scale before it. Every region's corners hold the ray's stretch in it, no walk
// ends in an error, and the hits are brute force's. The check is sharp on the slivers: a point 5
// tolerances beyond a face at a sliver's corner reads 5 tolerances out within 1% (Newell's normals
// read 2e-8 to 5e-8 off there), and the corner itself reads out by no more than 1e-13 x scale.
TEST(RayTree, RaysEnteringAtACameraFrameRegionCorner) {
    size_t rays = 0, slivers[3] = {}, sliverStretches = 0;
    for (int ortho = 0; ortho < 2; ++ortho)
        for (int which = 0; which < 4; ++which) {
            // The default stop (--max-objects 4), and no stop: more zones, slivers across the
            // screen axes as well as in depth.
            const int maxObjects = which < 2 ? 4 : 0;
            test::RandomSceneOptions opt;
            opt.primitives = 15;
            Scene scene =
                which % 2 == 0 ? test::randomCsgScene(1, opt) : loadScene("builtin:default");
            if (ortho) test::makeOrthographic(scene);
            SCOPED_TRACE(std::string(which % 2 == 0 ? "random scene 1" : "builtin:default") +
                         (ortho ? " orthographic" : " perspective") + " --max-objects " +
                         std::to_string(maxObjects));
            BuildParams params;
            params.scheme = SchemeKind::Irregular;
            params.irregular.frame = IrregularFrame::Camera;
            params.irregular.maxObjects = maxObjects;
            auto accel = buildAccelerator(scene, params);
            const StructureView view(scene, *accel);
            const IrregularSubdivision* s = view.irregular();
            ASSERT_NE(s, nullptr);
            const CameraFrame& f = s->frame();
            const double scale = scene.scale();
            TraceContext ctx(scene.prims.size(), scene.tree.depth());
            ctx.useMailboxes = accel->usesMailboxes();
            std::vector<Ray> all;
            for (uint32_t id = 0; id < s->regions().size(); ++id) {
                const Box3 b = s->regionBox(id);
                const Vec3 e = b.extent();
                const bool sliver = std::min({e.x, e.y, e.z}) < 1e-6 * scale;
                const std::array<Vec3, 8> c = view.regionCorners(id);
                if (sliver) {
                    for (int a = 0; a < 3; ++a) slivers[a] += e[a] < 1e-6 * scale;
                    SCOPED_TRACE(view.toString(id));
                    for (int k = 0; k < 8; ++k) {
                        const Vec3 q{(k & 1) ? b.hi.x : b.lo.x, (k & 2) ? b.hi.y : b.lo.y,
                                     (k & 4) ? b.hi.z : b.lo.z};
                        const double tol = 1e-9 * std::max(scale, glm::length(c[size_t(k)]));
                        EXPECT_LE(test::outside(c, c[size_t(k)]), 1e-13 * scale);
                        for (int a = 0; a < 3; ++a) {
                            Vec3 beyond = q;
                            beyond[a] += (k >> a & 1) ? 5.0 * tol : -5.0 * tol;
                            EXPECT_NEAR(test::outside(c, f.toWorld(beyond)), 5.0 * tol, 0.05 * tol)
                                << "corner " << k << " axis " << a;
                        }
                    }
                }
                const Vec3 centre = f.toWorld(b.center());
                for (int k = 0; k < 8; ++k) {
                    const Vec3 at = c[size_t(k)];
                    std::vector<Vec3> dirs = {glm::normalize(centre - at)};
                    for (int a = 0; a < 3; ++a) {
                        const Vec3 edge = c[size_t(k ^ (1 << a))] - at;
                        if (glm::length(edge) > 0.0) dirs.push_back(glm::normalize(edge));
                    }
                    const Vec3 primary = ortho ? f.z : glm::normalize(at - scene.camera.from);
                    std::vector<Ray> through;
                    for (const Vec3& d : dirs) {
                        through.push_back({at, d});
                        through.push_back({at - 2.0 * scale * d, d});
                    }
                    through.push_back({at, primary});
                    through.push_back(
                        {ortho ? at - 2.0 * scale * primary : scene.camera.from, primary});
                    for (const Ray& ray : through) {
                        RecordingObserver obs = test::recordWalk(*accel, ray, ctx);
                        checkCorners(view, ray, obs.events, scale);
                        for (const WalkEvent& ev : obs.events) {
                            EXPECT_NE(ev.kind(), WalkEvent::Error)
                                << ev.toString() << " " << ray.toString();
                            const walk::Region* g = ev.get<walk::Region>();
                            if (!g || !(g->t1 > g->t0)) continue;
                            const Vec3 x = s->regionBox(g->region).extent();
                            sliverStretches += std::min({x.x, x.y, x.z}) < 1e-6 * scale;
                        }
                        all.push_back(ray);
                    }
                }
            }
            rays += all.size();
            const std::vector<test::RayMismatch> bad = test::compareWithBrute(scene, *accel, all);
            for (const test::RayMismatch& m : bad) ADD_FAILURE() << m.toString(scene);
        }
    for (int a = 0; a < 3; ++a) EXPECT_GT(slivers[a], 3u) << "axis " << a;
    EXPECT_GT(sliverStretches, 1000u);
    EXPECT_GT(rays, 10000u);
    std::cout << rays << " rays; sliver regions thin in x " << slivers[0] << ", y " << slivers[1]
              << ", depth " << slivers[2] << "; " << sliverStretches << " stretches in them\n";
}

/// The reasons of a ray's steps, checked against its events: one per step; step k names step
/// k + 1's region last, after "-> "; the last step names none and tells how the ray ends.
void checkReasons(const StructureView& view, const TracedRay& r, const Scene& scene) {
    const std::vector<size_t> steps = r.regionSteps();
    const std::vector<StepReason> why = explainSteps(r, view, &scene);
    ASSERT_EQ(why.size(), steps.size());
    for (size_t k = 0; k < why.size(); ++k) {
        const std::string& text = why[k].text;
        SCOPED_TRACE("step " + std::to_string(k) + ": " + text);
        ASSERT_FALSE(text.empty());
        ASSERT_EQ(text.find('\n'), std::string::npos);
        const size_t arrow = text.rfind("-> ");
        if (k + 1 < steps.size()) {
            const uint32_t next = r.events[steps[k + 1]].as<walk::Region>().region;
            ASSERT_EQ(why[k].next, int64_t(next));
            ASSERT_NE(arrow, std::string::npos);
            const std::string name = regionName(view, next);
            ASSERT_EQ(text.compare(arrow + 3, name.size(), name), 0);
        } else {
            ASSERT_EQ(why[k].next, -1);
            ASSERT_EQ(arrow, std::string::npos);
            if (r.kind == RayKind::Shadow && r.occluded) {
                ASSERT_NE(text.find("blocked by p" + std::to_string(r.hit.prim)),
                          std::string::npos);
            } else if (r.kind != RayKind::Shadow && r.hit.valid()) {
                ASSERT_NE(text.find("hit p" + std::to_string(r.hit.prim)), std::string::npos);
            }
        }
    }
}

// For random scenes and the built-in ones, every ray of random pixels' trees (all kinds, both
// schemes, both step methods, both irregular frames): the region each step's reason names as
// the next is the region of the next step, and the last step's tells the hit or the blocker.
TEST(RayTree, StepReasonNamesTheNextStepsRegion) {
    size_t reasons = 0;
    for (const Config& c : configs()) {
        if (c.bounces == 0) continue;
        SCOPED_TRACE(c.name());
        Scene scene = loadScene(c.scene);
        auto accel = buildAccelerator(scene, paramsOf(c));
        const StructureView view(scene, *accel);
        ShadingOptions sh;
        sh.bounces = c.bounces;
        for (int k = 0; k < 24; ++k) {
            const RayTree t =
                tracePixel(scene, *accel, sh, scene.camera, (k * 7) % 16, (k * 5) % 12, 16, 12);
            for (const TracedRay& r : t.rays) {
                checkReasons(view, r, scene);
                reasons += r.regionSteps().size();
            }
        }
    }
    for (uint64_t seed = 1; seed <= 3; ++seed) {
        Scene scene = test::randomGlassyCsgScene(seed);
        for (const Config& c : configs()) {
            if (c.scene != "builtin:default" || c.bounces == 0) continue;
            auto accel = buildAccelerator(scene, paramsOf(c));
            const StructureView view(scene, *accel);
            ShadingOptions sh;
            sh.bounces = 2;
            for (int k = 0; k < 24; ++k) {
                const RayTree t = tracePixel(scene, *accel, sh, scene.camera, (k * 11) % 32,
                                             (k * 13) % 32, 32, 32);
                for (const TracedRay& r : t.rays) checkReasons(view, r, scene);
            }
        }
    }
    EXPECT_GT(reasons, 1000u);
}

/// Two boxes: A at the origin, B and C beyond x = 2, B above, C below. With max-objects 1 the
/// regular grid's low-x half holds A and its high-x half splits between C and B, so the low
/// half's +x face has two leaves across it.
Scene twoBoxes() {
    Scene s;
    s.prims.push_back(makePrimitive(Block{{0, 0, 0}, {1, 1, 1}}, Transform()));
    s.prims.push_back(makePrimitive(Block{{2, 2, 0}, {3, 3, 1}}, Transform()));
    s.prims.push_back(makePrimitive(Block{{2, 0, 0}, {3, 1, 1}}, Transform()));
    s.tree.root = s.tree.balanced(Op::Union, {s.tree.leaf(0), s.tree.leaf(1), s.tree.leaf(2)});
    s.prepare();
    s.frameCamera(Vec3(0.3, 0.4, -1.0), Vec3(0.0, 1.0, 0.0));
    s.defaultLights();
    return s;
}

// A hand-built scene and a known ray: the ray from (0.5, 2.5, 0.5) along +x leaves the leaf of
// A's half through its +x face at x = 1.5 (t = 1): with the exact step, the index step +x to
// the directory cell of the point (1.5, 2.5, 0.5) on the high side, whose leaf is B's; with the
// push step, the pushed point's cell; then it hits B at t = 1.5 inside that leaf.
TEST(RayTree, StepReasonsOfAKnownRayNameTheFaceCellAndNextLeaf) {
    const Scene scene = twoBoxes();
    const Ray ray{{0.5, 2.5, 0.5}, {1.0, 0.0, 0.0}};
    for (StepMethod step : {StepMethod::Exact, StepMethod::Push}) {
        SCOPED_TRACE(stepName(step));
        BuildParams p;
        p.scheme = SchemeKind::Regular;
        p.regular.maxObjects = 1;
        p.regular.step = step;
        p.regular.delta = 1e-3;  // 0.003 on the box's 3 units along x
        p.regular.splitAxes = SplitAxes::Cycle;
        auto accel = buildAccelerator(scene, p);
        const StructureView view(scene, *accel);
        const RegularGrid& g = *view.regular();
        ASSERT_EQ(g.regionCount(), 3u) << "A's half, B's and C's quarters";
        const uint32_t from = g.leafAt({0.5, 2.5, 0.5}), to = g.leafAt({2.5, 2.5, 0.5});
        ASSERT_NE(from, to);
        TraceContext ctx(scene.prims.size(), scene.tree.depth());
        ctx.useMailboxes = true;
        RecordingObserver obs = test::recordWalk(*accel, ray, ctx);
        TracedRay r;
        r.origin = ray.o;
        r.direction = ray.d;
        r.events = obs.events;
        NullObserver none;
        ASSERT_TRUE(accel->intersect(ray, 0.0, kInf, ctx, none, r.hit));
        ASSERT_EQ(r.hit.prim, 1u);
        ASSERT_EQ(r.hit.t, 1.5);
        const std::vector<StepReason> why = explainSteps(r, view, &scene);
        ASSERT_EQ(why.size(), 2u);
        const std::string& s0 = why[0].text;
        SCOPED_TRACE(s0 + " | " + why[1].text);
        EXPECT_EQ(s0.rfind("the walk starts at (0.5, 2.5, 0.5): directory cell (0, 1, 0) of leaf " +
                               std::to_string(from) + "; ",
                           0),
                  0u);
        EXPECT_NE(s0.find("left leaf " + std::to_string(from) +
                          " through its +x face at t = 1 (point (1.5, 2.5, 0.5))"),
                  std::string::npos);
        if (step == StepMethod::Exact) {
            EXPECT_NE(s0.find("; exact index step +x to directory cell (1, 1, 0) -> leaf " +
                              std::to_string(to)),
                      std::string::npos);
        } else {
            EXPECT_NE(s0.find("; pushed by delta 0.003 across +x face to (1.503, 2.5, 0.5): "
                              "directory cell (1, 1, 0) -> leaf " +
                              std::to_string(to)),
                      std::string::npos);
        }
        EXPECT_EQ(why[0].next, int64_t(to));
        EXPECT_EQ(why[1].next, -1);
        EXPECT_EQ(why[1].text.rfind("hit p1 ", 0), 0u);
        EXPECT_NE(why[1].text.find(" at t = 1.5 inside this region"), std::string::npos);
    }
    // The irregular scheme (camera frame) along the camera's forward axis through A: out of
    // each slab through its far depth plane, to the next slab of the same zone.
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.irregular.frame = IrregularFrame::Camera;
    auto accel = buildAccelerator(scene, p);
    const StructureView view(scene, *accel);
    Vec3 F, R, U;
    scene.camera.basis(F, R, U);
    const Ray ray2{Vec3(0.5) - 10.0 * F, F};
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    ctx.useMailboxes = true;
    RecordingObserver obs = test::recordWalk(*accel, ray2, ctx);
    TracedRay r;
    r.origin = ray2.o;
    r.direction = ray2.d;
    r.events = obs.events;
    NullObserver none;
    ASSERT_TRUE(accel->intersect(ray2, 0.0, kInf, ctx, none, r.hit));
    ASSERT_EQ(r.hit.prim, 0u);
    const std::vector<StepReason> why = explainSteps(r, view, &scene);
    ASSERT_GE(why.size(), 2u);
    for (size_t k = 0; k + 1 < why.size(); ++k) {
        SCOPED_TRACE(why[k].text);
        const RegionInfo a = view.region(r.events[r.regionSteps()[k]].as<walk::Region>().region);
        const RegionInfo b = view.region(uint32_t(why[k].next));
        if (a.zone == b.zone) {
            EXPECT_NE(why[k].text.find("through its far depth plane"), std::string::npos);
            EXPECT_NE(why[k].text.find("the next slab of the same zone"), std::string::npos);
            EXPECT_EQ(b.slab, a.slab + 1);
        } else {
            EXPECT_NE(why[k].text.find("crossed into zone " + std::to_string(b.zone)),
                      std::string::npos);
        }
    }
}

// The values print themselves: every event kind, the hit, the counters, a ray, the tree.
TEST(RayTree, ValuesPrintThemselves) {
    Scene scene = loadScene("builtin:default");
    BuildParams p;
    p.scheme = SchemeKind::Regular;
    auto accel = buildAccelerator(scene, p);
    ShadingOptions sh;
    sh.bounces = 2;
    const RayTree t = tracePixel(scene, *accel, sh, scene.camera, 256, 256, 512, 512);
    std::ostringstream os;
    os << t.rays[0].hit << " | " << t.counters << " | " << t.rays[0] << " | "
       << t.rays[0].events[0];
    const std::string s = os.str();
    EXPECT_NE(s.find("on p"), std::string::npos) << s;
    EXPECT_NE(s.find("prim tests "), std::string::npos) << s;
    EXPECT_NE(s.find("primary from ("), std::string::npos) << s;
    EXPECT_NE(s.find("primary ray begins at"), std::string::npos) << s;
    EXPECT_EQ(Hit{}.toString(), "no hit");
    const std::string tree = t.toString(&scene);
    EXPECT_EQ(tree.rfind("pixel (256, 256) of 512x512: rays ", 0), 0u) << tree;
    EXPECT_NE(tree.find("\n#0 primary"), std::string::npos) << tree;
    EXPECT_NE(tree.find("\n  #1 shadow of #0 to light 0"), std::string::npos) << tree;
    EXPECT_NE(tree.find("\n  region "), std::string::npos) << tree;
    EXPECT_NE(tree.find("\n    test p"), std::string::npos) << tree;
    // One line per event, none empty.
    for (const TracedRay& r : t.rays)
        for (const WalkEvent& e : r.events) {
            const std::string line = e.toString(&scene);
            EXPECT_FALSE(line.empty());
            EXPECT_EQ(line.find('\n'), std::string::npos) << line;
        }
}

}  // namespace
}  // namespace lancer
