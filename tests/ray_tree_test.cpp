// A pixel's ray tree (engine/render/ray_tree.h): recorded by the code that renders, so its counts
// are the renderer's per-pixel counters; its rays are the ones the shading casts, with the right
// kinds and parents; recording is repeatable; and each walk says how it got from one region to
// the next (the exit, then the rope, the index step or the pushed point and the directory cell,
// or the corner pointers).
#include "engine/render/ray_tree.h"

#include <gtest/gtest.h>

#include <sstream>

#include "engine/accel/structure_view.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "support/differential.h"

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
    p.step = c.step;
    p.irregularFrame = c.frame;
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
                    ASSERT_EQ(r.events.front().kind, WalkEvent::RayBegin);
                    ASSERT_EQ(r.events.back().kind, WalkEvent::RayEnd);
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
        if (ev[k].kind == WalkEvent::Stretch) return -1;
        if (ev[k].kind == WalkEvent::Region) return ev[k].a;
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
                        if (e.kind == WalkEvent::Region) current = e.a;
                        if (e.kind == WalkEvent::Stretch) current = -1;
                        if (e.kind != WalkEvent::Exit) continue;
                        ++exits;
                        ASSERT_GE(current, 0);
                        ASSERT_NE(e.ties, 0);
                        ASSERT_TRUE(e.ties >> e.axis & 1);
                        const Vec3 at = ray.at(e.t0);
                        const double tol = 1e-7 * std::max(scene.scale(), glm::length(at));
                        for (int a = 0; a < 3; ++a) ASSERT_NEAR(e.point[a], at[a], tol);
                        const int64_t next = nextRegion(ev, i);
                        if (next < 0) continue;  // out of the structure, or the stretch's end
                        const WalkEvent& how = ev[i + 1];
                        if (c.scheme == SchemeKind::Regular) {
                            if (c.step == StepMethod::Exact && how.kind == WalkEvent::Rope) {
                                ++ropes;
                                ASSERT_EQ(how.a, current);
                                ASSERT_EQ(int64_t(how.b), next);
                                ASSERT_EQ(how.axis / 2, e.axis);
                            } else {
                                ASSERT_EQ(how.kind, c.step == StepMethod::Exact
                                                        ? WalkEvent::IndexStep
                                                        : WalkEvent::Push);
                                (how.kind == WalkEvent::Push ? pushes : steps)++;
                                ASSERT_EQ(ev[i + 2].kind, WalkEvent::Lookup);
                                ASSERT_EQ(int64_t(ev[i + 2].b), next);
                                for (int a = 0; a < 3; ++a) {
                                    if (how.kind == WalkEvent::IndexStep) {
                                        ASSERT_EQ(ev[i + 2].cell[a], how.cell[a]);
                                    }
                                }
                            }
                        } else if (how.kind == WalkEvent::Pointer) {
                            int64_t at = current;
                            size_t k = i + 1;
                            for (; k < ev.size() && ev[k].kind == WalkEvent::Pointer; ++k) {
                                ASSERT_EQ(int64_t(ev[k].a), at);
                                at = ev[k].b;
                                ++pointers;
                            }
                            ASSERT_EQ(ev[k].kind, WalkEvent::Region);
                            ASSERT_EQ(at, next);
                        } else {
                            // Projective zones: the next slab in depth, no pointer.
                            ASSERT_EQ(how.kind, WalkEvent::Region);
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

/// How far `p` lies outside the hexahedron of `c` (corner i + 2j + 4k; faces planar), 0 inside:
/// the largest distance beyond one of its six face planes. A face that has collapsed to a point
/// or a segment (a projective region's apex at the eye) bounds nothing and is skipped.
double outside(const std::array<Vec3, 8>& c, const Vec3& p) {
    Vec3 centre(0.0);
    for (const Vec3& q : c) centre += q / 8.0;
    double worst = 0.0;
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, d = (a + 2) % 3;
        for (int side = 0; side < 2; ++side) {
            // The face's corners in cyclic order, for Newell's normal.
            int idx[4];
            const int bits[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int k = 0; k < 4; ++k)
                idx[k] = (side << a) | (bits[k][0] << b) | (bits[k][1] << d);
            Vec3 n(0.0), fc(0.0);
            for (int k = 0; k < 4; ++k) {
                const Vec3& u = c[size_t(idx[k])];
                const Vec3& v = c[size_t(idx[(k + 1) % 4])];
                n += Vec3((u.y - v.y) * (u.z + v.z), (u.z - v.z) * (u.x + v.x),
                          (u.x - v.x) * (u.y + v.y));
                fc += u / 4.0;
            }
            const double len = glm::length(n);
            if (!(len > 1e-12 * glm::dot(fc - centre, fc - centre) + 1e-300)) continue;
            n /= len;
            const double towards = glm::dot(n, fc - centre);
            const double dist = glm::dot(n, p - fc);
            if (towards > 0.0)
                worst = std::max(worst, dist);
            else if (towards < 0.0)
                worst = std::max(worst, -dist);
            else
                worst = std::max(worst, std::abs(dist));  // a flat region: on its plane
        }
    }
    return worst;
}

/// Check that each region event's corners hold the ray's stretch in it; returns the regions
/// checked. The walks clip a ray to their structure's box grown by a hair (a few 1e-9 of the
/// scene's size), and the last region's stretch runs to that clip: where the ray leaves the
/// structure through an edge or a corner it may already have left the region across the tied
/// interior face, by up to the hair over the ray's slope. So the points checked are those inside
/// the structure's own box.
size_t checkCorners(const StructureView& view, const Ray& ray, const std::vector<WalkEvent>& ev,
                    double scale) {
    size_t n = 0;
    const std::array<Vec3, 8> bounds = view.structureCorners();
    for (const WalkEvent& e : ev) {
        if (e.kind != WalkEvent::Region) continue;
        const std::array<Vec3, 8> c = view.regionCorners(e.a);
        for (double t : {e.t0, 0.5 * (e.t0 + e.t1), e.t1}) {
            const Vec3 p = ray.at(t);
            const double tol = 1e-9 * std::max(scale, glm::length(p));
            if (outside(bounds, p) > tol) continue;
            EXPECT_LE(outside(c, p), tol)
                << ray.toString() << " region " << e.a << " t = " << t << " of [" << e.t0 << ", "
                << e.t1 << "] " << view.toString(e.a);
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
        Scene scene = test::randomCsgScene(seed, opt);
        scene.materials[0].reflect = 0.3;
        scene.materials[0].transmit = 0.5;
        scene.materials[0].ior = 1.4;
        scene.frameCamera(Vec3(0.3, 1.0, -0.4), Vec3(0.0, 0.0, 1.0));
        scene.defaultLights();
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
