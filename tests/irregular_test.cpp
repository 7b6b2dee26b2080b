// The irregular subdivision (report, section 2): same hits as brute force for every kind of ray,
// walks by corner pointers that reach the region holding any point, pointers that land where
// they should, and refused parameters.
#include "engine/accel/irregular/irregular.h"

#include <gtest/gtest.h>

#include <bit>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "engine/accel/build_guard.h"
#include "engine/accel/irregular/depth_slabs.h"
#include "engine/accel/irregular/primitive_hulls.h"
#include "engine/accel/irregular/screen_bsp.h"
#include "engine/accel/regular/grid_frame.h"
#include "engine/model/csg.h"
#include "engine/model/restriction.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

using test::expectSame;
using test::secondaryRays;

const IrregularSubdivision& irregularOf(const Accelerator& a) {
    return std::get<IrregularSubdivision>(a.impl());
}

std::unique_ptr<Accelerator> buildIrregular(const Scene& scene,
                                            BspHeuristic h = BspHeuristic::Balanced,
                                            int maxObjects = 0,
                                            IrregularFrame frame = IrregularFrame::Projective) {
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.irregular.frame = frame;
    p.irregular.heuristic = h;
    p.irregular.maxObjects = maxObjects;
    return buildAccelerator(scene, p);
}

/// World points at the corners, edge midpoints and face centres of some regions.
std::vector<Vec3> regionPoints(const IrregularSubdivision& s, size_t maxRegions, uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::vector<Vec3> pts;
    const size_t regions = s.regions().size();
    for (size_t k = 0; k < maxRegions && regions > 0; ++k) {
        const Box3 b = s.regionBox(uint32_t(rng() % regions));
        for (int i = 0; i < 27; i += 2) {  // corners, edge midpoints, face centres, centre
            Vec3 c;
            for (int a = 0, j = i; a < 3; ++a, j /= 3)
                c[a] = j % 3 == 0 ? b.lo[a] : (j % 3 == 1 ? 0.5 * (b.lo[a] + b.hi[a]) : b.hi[a]);
            pts.push_back(s.frame().toWorld(c));
        }
    }
    return pts;
}

/// Rays along the camera frame's axes through the given world points, both ways.
std::vector<Ray> cameraAxisRays(const IrregularSubdivision& s, const std::vector<Vec3>& pts,
                                double reach) {
    std::vector<Ray> rays;
    const Vec3 axes[3] = {s.frame().x, s.frame().y, s.frame().z};
    for (size_t i = 0; i < pts.size(); ++i) {
        const Vec3& d = axes[i % 3];
        double sgn = (i / 3) % 2 ? 1.0 : -1.0;
        rays.push_back({pts[i] - sgn * reach * d, sgn * d});
        rays.push_back({pts[i], sgn * d});  // starting on a region boundary
    }
    return rays;
}

/// Rays from the eye through the corners, edge midpoints and centres of projective zones, and
/// random ones: they run along zone borders, where (u, v) ties.
std::vector<Ray> eyeRaysOnZoneCorners(const Scene& scene, const IrregularSubdivision& s,
                                      size_t maxZones, uint64_t seed) {
    std::vector<Ray> rays;
    const ScreenBsp& z = s.projective().screen();
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (size_t k = 0; k < maxZones && z.zoneCount() > 0; ++k) {
        uint32_t i = uint32_t(rng() % z.zoneCount());
        for (int j = 0; j < 9; ++j) {
            double a = j % 3 == 0
                           ? z.zoneLo[i].x
                           : (j % 3 == 1 ? 0.5 * (z.zoneLo[i].x + z.zoneHi[i].x) : z.zoneHi[i].x);
            double b = j / 3 == 0
                           ? z.zoneLo[i].y
                           : (j / 3 == 1 ? 0.5 * (z.zoneLo[i].y + z.zoneHi[i].y) : z.zoneHi[i].y);
            Vec3 d = a * s.frame().x + b * s.frame().y + s.frame().z;
            rays.push_back({scene.camera.from, glm::normalize(d)});
        }
        Vec3 d = u(rng) * s.frame().x + u(rng) * s.frame().y + (1.0 + u(rng)) * s.frame().z;
        if (glm::dot(d, d) > 0.0) rays.push_back({scene.camera.from, glm::normalize(d)});
    }
    return rays;
}

/// A random camera: outside or inside the scene, perspective or orthographic.
void randomCamera(Scene& scene, std::mt19937_64& rng) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    Vec3 c = scene.bounds.center(), e = scene.bounds.extent();
    double far = (rng() % 3) ? 2.0 : 0.3;  // a third of the cameras stand inside the bounds
    scene.camera.from = c + far * e * Vec3(u(rng), u(rng), u(rng));
    scene.camera.at = c + 0.2 * e * Vec3(u(rng), u(rng), u(rng));
    scene.camera.up = glm::normalize(Vec3(u(rng), u(rng), u(rng)));
    scene.camera.projection = rng() % 2 ? Projection::Orthographic : Projection::Perspective;
    scene.camera.orthoHeight = glm::length(e);
}

// Every pixel of every SPD scene, perspective and orthographic, against brute force; primary
// rays walk the given structure, secondary rays the camera-frame one.
void spdPixelForPixel(IrregularFrame frame) {
    std::vector<std::filesystem::path> files;
    for (const auto& e : std::filesystem::directory_iterator(LANCER_SPD_DIR))
        if (e.path().extension() == ".nff") files.push_back(e.path());
    ASSERT_GE(files.size(), 10u);
    std::sort(files.begin(), files.end());
    for (const auto& path : files) {
        Scene scene = loadScene(path.string());
        int n = path.filename() == "balls4.nff" ? 24 : 40;
        for (int ortho = 0; ortho < 2; ++ortho) {
            if (ortho) test::makeOrthographic(scene);
            auto accel = buildIrregular(scene, BspHeuristic::Balanced, 0, frame);
            std::string what = path.filename().string() +
                               (ortho ? " orthographic " : " perspective ") +
                               irregularFrameName(frame);
            std::vector<Ray> rays = test::pixelRays(scene, n, n);
            expectSame(scene, *accel, rays, what);
            if (frame == IrregularFrame::Camera) {  // the same structure either way
                std::vector<Ray> sec = secondaryRays(scene, rays, 7);
                expectSame(scene, *accel, sec, what + " secondary", 1e-9 * scene.scale());
            }
        }
    }
}

TEST(Irregular, SpdScenesPixelForPixelCameraFrame) { spdPixelForPixel(IrregularFrame::Camera); }
TEST(Irregular, SpdScenesPixelForPixelProjective) { spdPixelForPixel(IrregularFrame::Projective); }

TEST(Irregular, BuiltinCsgScenesPixelForPixel) {
    for (const char* spec : {"builtin:default", "builtin:drilled:4", "builtin:lattice:4"}) {
        Scene scene = loadScene(spec);
        for (int ortho = 0; ortho < 2; ++ortho) {
            if (ortho) test::makeOrthographic(scene);
            for (BspHeuristic h :
                 {BspHeuristic::First, BspHeuristic::Balanced, BspHeuristic::FewestCuts}) {
                // Primary rays on the projective zones with one heuristic in two.
                IrregularFrame f = h == BspHeuristic::Balanced ? IrregularFrame::Camera
                                                               : IrregularFrame::Projective;
                auto accel = buildIrregular(scene, h, 0, f);
                std::string what = std::string(spec) +
                                   (ortho ? " orthographic " : " perspective ") + heuristicName(h) +
                                   " " + irregularFrameName(f);
                test::expectSamePixelsAndSecondaries(scene, *accel, 48, 3, what);
            }
        }
    }
}

// 20 random scenes x (3000 random + region-corner + camera-axis rays): over 10^5 rays.
TEST(Irregular, RandomScenesAndHardRays) {
    size_t total = 0;
    for (uint64_t seed = 1; seed <= 20; ++seed) {
        test::RandomSceneOptions opt;
        opt.transforms = seed % 2 == 0;
        opt.surfaces = seed % 3 == 0;
        opt.primitives = 8 + int(seed % 4) * 6;
        if (seed % 5 == 0) opt.offset = Vec3(1e6, -1e6, 5e5);
        Scene scene = test::randomCsgScene(seed, opt);
        if (scene.bounds.isEmpty()) continue;
        std::mt19937_64 rng(seed * 977);
        randomCamera(scene, rng);
        BspHeuristic h = BspHeuristic(seed % 3);
        auto accel = buildIrregular(scene, h, seed % 4 == 0 ? 2 : 0);
        const IrregularSubdivision& irr = irregularOf(*accel);
        std::string what = "seed " + std::to_string(seed) + " " + heuristicName(h);

        std::vector<Ray> rays = test::randomRays(scene, seed, 3000);
        std::vector<Vec3> pts = regionPoints(irr, 60, seed);
        std::vector<Ray> corner = test::raysThroughPoints(pts, scene.bounds, seed);
        rays.insert(rays.end(), corner.begin(), corner.end());
        std::vector<Ray> axis = cameraAxisRays(irr, pts, 2.0 * glm::length(scene.bounds.extent()));
        rays.insert(rays.end(), axis.begin(), axis.end());
        std::vector<Ray> pix = test::pixelRays(scene, 16, 16);
        rays.insert(rays.end(), pix.begin(), pix.end());
        std::vector<Ray> eye = eyeRaysOnZoneCorners(scene, irr, 200, seed);
        rays.insert(rays.end(), eye.begin(), eye.end());
        expectSame(scene, *accel, rays, what);
        // Secondary rays that start on region boundaries, with a tmin as the tracer uses.
        std::vector<Ray> onBoundary;
        for (size_t i = 0; i < corner.size(); i += 4) onBoundary.push_back(corner[i + 1]);
        expectSame(scene, *accel, onBoundary, what + " tmin", 1e-9 * scene.scale());
        total += rays.size() + onBoundary.size();

        EXPECT_EQ(test::traceCounters(scene, *accel, rays).walkErrors, 0u) << what;
    }
    EXPECT_GE(total, 100000u);
}

// For random points: the region reached by pointers from a random region is the one a search
// over all regions finds; every pointer lands on a region touching its corner.
TEST(Irregular, WalkReachesTheRegionHoldingAPoint) {
    std::vector<Scene> scenes;
    for (uint64_t seed = 31; seed <= 36; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 16;
        opt.surfaces = seed % 2 == 0;
        scenes.push_back(test::randomCsgScene(seed, opt));
        if (scenes.back().bounds.isEmpty()) {
            scenes.pop_back();
            continue;
        }
        std::mt19937_64 rng(seed);
        randomCamera(scenes.back(), rng);
    }
    scenes.push_back(loadScene(std::string(LANCER_SPD_DIR) + "/gears1.nff"));
    std::mt19937_64 rng(5);
    for (const Scene& scene : scenes) {
        auto accel = buildIrregular(scene);
        const IrregularSubdivision& s = irregularOf(*accel);
        const auto& R = s.regions();
        ASSERT_FALSE(R.empty());
        std::vector<Vec3> pts;
        std::uniform_real_distribution<double> u(0.0, 1.0);
        const Box3& B = s.bounds();
        for (int i = 0; i < 300; ++i)
            pts.push_back(B.lo + Vec3(u(rng), u(rng), u(rng)) * B.extent());
        // Corners, edge midpoints and face centres of regions, exactly (camera coordinates).
        for (int i = 0; i < 200; ++i) {
            const Box3 b = s.regionBox(uint32_t(rng() % R.size()));
            Vec3 c;
            for (int a = 0; a < 3; ++a) {
                int k = int(rng() % 3);
                c[a] = k == 0 ? b.lo[a] : (k == 1 ? b.hi[a] : 0.5 * (b.lo[a] + b.hi[a]));
            }
            pts.push_back(c);
        }
        for (Vec3 p : pts) {
            p = glm::clamp(p, B.lo, B.hi);  // corners mapped to the world and back may round out
            uint32_t from = uint32_t(rng() % R.size());
            Vec3 d = p - s.regionBox(from).center();
            int64_t got = s.walkTo(from, p);
            ASSERT_GE(got, 0) << "walk error from region " << from << " to " << toString(p);
            std::vector<uint32_t> holding;
            for (uint32_t r = 0; r < R.size(); ++r)
                if (s.holds(r, p, d)) holding.push_back(r);
            ASSERT_FALSE(holding.empty()) << toString(p);
            if (holding.size() == 1)
                EXPECT_EQ(uint32_t(got), holding[0])
                    << "point " << toString(p) << " from " << from << " dir " << toString(d)
                    << "\n  got " << s.regionBox(uint32_t(got)).toString() << "\n  want "
                    << s.regionBox(holding[0]).toString() << "\n  bounds " << B.toString();
            else
                EXPECT_TRUE(s.holds(uint32_t(got), p, d)) << toString(p);
        }
        // Pointers: hi[a] holds the point just beyond the high corner across face a, just inside
        // on the other axes; lo[a] likewise at the low corner.
        for (uint32_t r = 0; r < R.size(); ++r) {
            for (int a = 0; a < 3; ++a) {
                for (int high = 0; high < 2; ++high) {
                    int32_t n = s.pointer(r, a, high);
                    Vec3 c = high ? s.regionBox(r).hi : s.regionBox(r).lo;
                    bool border = high ? c[a] == B.hi[a] : c[a] == B.lo[a];
                    if (border) {
                        EXPECT_EQ(n, -1);
                        continue;
                    }
                    ASSERT_GE(n, 0) << "region " << r << " axis " << a;
                    const Box3 nb = s.regionBox(uint32_t(n));
                    EXPECT_TRUE(nb.contains(c))
                        << "pointer " << r << " -> " << n << " misses its corner";
                    EXPECT_EQ(high ? nb.lo[a] : nb.hi[a], c[a]) << "not across the face";
                    for (int b = 0; b < 3; ++b) {
                        if (b == a) continue;
                        if (high)
                            EXPECT_LT(nb.lo[b], c[b]);  // holds the point just below the corner
                        else
                            EXPECT_GT(nb.hi[b], c[b]);
                    }
                }
            }
        }
    }
}

// Zones tile the structure's screen rectangle; slabs tile each zone's depth; every primitive
// touching a region is listed in it.
TEST(Irregular, RegionsTileTheBoundsAndListTheirPrimitives) {
    Scene scene = loadScene("builtin:drilled:4");
    auto accel = buildIrregular(scene);
    const IrregularSubdivision& s = irregularOf(*accel);
    const Box3& B = s.bounds();
    double volume = 0.0;
    for (uint32_t r = 0; r < s.regions().size(); ++r) {
        const Box3 b = s.regionBox(r);
        Vec3 e = b.extent();
        EXPECT_GT(e.x, 0.0);
        EXPECT_GT(e.y, 0.0);
        EXPECT_GT(e.z, 0.0);
        volume += e.x * e.y * e.z;
        auto prims = s.primitives(r);
        for (uint32_t p : scene.livePrimitives()) {
            bool listed = std::find(prims.begin(), prims.end(), p) != prims.end();
            // A primitive whose minimized box holds a point inside the region must be listed
            // (the zones narrow each box to the depths it takes over them: primitive_hulls.h).
            bool inside = false;
            for (int i = 0; i < 125 && !inside; ++i) {
                Vec3 c;
                for (int a = 0, j = i; a < 3; ++a, j /= 5)
                    c[a] = b.lo[a] + (0.1 + 0.2 * (j % 5)) * (b.hi[a] - b.lo[a]);
                inside = scene.minBox[p].contains(s.frame().toWorld(c));
            }
            if (inside) {
                EXPECT_TRUE(listed) << "p" << p << " missing from region " << r;
            }
        }
    }
    Vec3 e = B.extent();
    EXPECT_NEAR(volume, e.x * e.y * e.z, 1e-9 * e.x * e.y * e.z);
    const nlohmann::json& x = accel->info().extra;
    EXPECT_GT(x["zones"].get<size_t>(), 1u);
    EXPECT_EQ(x["zones"].get<size_t>(), s.screen().zoneCount());
    size_t lightRegions = 0;
    for (const ProjectiveZones& lz : s.lights()) lightRegions += lz.regionCount();
    EXPECT_EQ(accel->info().regions,
              s.regions().size() + s.projective().regionCount() + lightRegions);
    EXPECT_GT(s.projective().regionCount(), 0u);
    EXPECT_TRUE(accel->usesMailboxes());
}

// Issue 29's memory bar: on balls4 the irregular scheme (camera frame, the eye's and the
// lights' projective structures) takes at most four times the regular scheme's memory. The
// camera frame's regions keep their depth range and screen pointers alone (region.h): with the
// full box and six pointers a region took 88 bytes and balls4 4.7 times the regular scheme's.
TEST(Irregular, Balls4TakesAtMostFourTimesTheRegularSchemesMemory) {
    Scene scene = loadScene(std::string(LANCER_SPD_DIR) + "/balls4.nff");
    scene.width = scene.height = 128;
    BuildParams p;  // each scheme's defaults, as `lancer render` builds it
    p.scheme = SchemeKind::Irregular;
    auto irregular = buildAccelerator(scene, p);
    p.scheme = SchemeKind::Regular;
    auto regular = buildAccelerator(scene, p);
    const IrregularSubdivision& s = irregularOf(*irregular);
    ASSERT_GT(s.regions().size(), 50'000u);
    EXPECT_LE(irregular->info().memoryBytes, 4 * regular->info().memoryBytes)
        << s.regions().size() << " camera-frame regions";
    // Each region's box is its zone's rectangle times its depth range, and its depth pointers
    // are the slabs beside it in its zone's column.
    for (uint32_t z = 0; z < s.screen().zoneCount(); ++z) {
        const uint32_t first = s.zoneFirstRegion()[z], last = s.zoneFirstRegion()[z + 1];
        for (uint32_t r = first; r < last; ++r) {
            EXPECT_EQ(s.regions()[r].zone, z);
            EXPECT_EQ(s.pointer(r, 2, false), r > first ? int32_t(r - 1) : -1);
            EXPECT_EQ(s.pointer(r, 2, true), r + 1 < last ? int32_t(r + 1) : -1);
        }
    }
}

/// `check(scene, structure)` on balls2 (union-only, a shared floor, lights outside its bounds)
/// and builtin:drilled:4 (CSG), each built with the default knobs.
template <class Check>
void onBalls2AndDrilled4(Check check) {
    for (const std::string& spec :
         {std::string(LANCER_SPD_DIR) + "/balls2.nff", std::string("builtin:drilled:4")}) {
        SCOPED_TRACE(spec);
        Scene scene = loadScene(spec);
        auto accel = buildIrregular(scene);
        check(scene, irregularOf(*accel));
    }
}

// The camera-frame walk reads a region's zone rectangle from one 32-byte record and its list's
// length and entries from one place (region.h): every zone's record is the screen BSP's
// rectangle, and every region's list read from its `first` is the list its `list` names, its own
// primitives (sorted, none shared, each with a camera-frame box that meets the region's box)
// then the shared ones; in a union-only scene with shared primitives (balls2's floor) and in a
// CSG scene (every list sorted, none shared).
TEST(Irregular, RegionRecordsReadTheirZoneAndListInOnePlace) {
    onBalls2AndDrilled4([](const Scene& scene, const IrregularSubdivision& s) {
        if (scene.tree.unionOnly()) {
            EXPECT_FALSE(s.shared().empty());
        }
        for (uint32_t z = 0; z < s.screen().zoneCount(); ++z) {
            EXPECT_EQ(s.zoneRect(z).lo, s.screen().zoneLo[z]);
            EXPECT_EQ(s.zoneRect(z).hi, s.screen().zoneHi[z]);
            EXPECT_EQ(reinterpret_cast<uintptr_t>(&s.zoneRect(z)) % 32, 0u);
        }
        const auto shared = s.shared();
        const double pad = 1e-6 * scene.scale();
        size_t listed = 0;
        for (uint32_t r = 0; r < s.regions().size(); ++r) {
            const auto held = s.heldPrimitives(r), named = s.list(s.regions()[r].list);
            ASSERT_TRUE(std::equal(held.begin(), held.end(), named.begin(), named.end())) << r;
            ASSERT_GE(held.size(), shared.size());
            EXPECT_TRUE(std::equal(shared.begin(), shared.end(), held.end() - shared.size()));
            const auto own = s.primitives(r);
            EXPECT_TRUE(std::is_sorted(own.begin(), own.end()));
            const Box3 box = s.regionBox(r);
            for (uint32_t p : own) {
                EXPECT_EQ(std::find(shared.begin(), shared.end(), p), shared.end());
                const Box3 b = s.frame().box(scene.minBox[p]);
                for (int a = 0; a < 3; ++a) {
                    EXPECT_LE(b.lo[a], box.hi[a] + pad) << r << " " << p;
                    EXPECT_GE(b.hi[a], box.lo[a] - pad) << r << " " << p;
                }
            }
            listed += !own.empty();
        }
        EXPECT_GT(listed, 0u);
    });
}

// A projective slab's record (the eye's structure and each light's) holds where it starts in
// depth, where its list lies and, in a union-only scene, its list's length, in 16 bytes aligned
// to 16, so the walk reads all three from one cache line and leaves a slab whose pending check
// fails without reading its list's line; in a CSG scene it holds the slab's tree there.
TEST(Irregular, ProjectiveSlabRecordsHoldDepthListAndLengthInOneLine) {
    onBalls2AndDrilled4([](const Scene&, const IrregularSubdivision& s) {
        std::vector<const ProjectiveZones*> structures{&s.projective()};
        for (const ProjectiveZones& l : s.lights()) structures.push_back(&l);
        size_t slabs = 0, lights = 0;
        for (const ProjectiveZones* pz : structures) {
            if (pz->zoneCount() == 0) continue;
            lights += pz->inward();
            const std::span<const uint32_t> lists = pz->lists();
            const uint32_t n = pz->zoneFirst().back();
            for (uint32_t i = 0; i < n; ++i, ++slabs) {
                const ProjectiveZones::Slab& r = pz->slab(i);
                const uintptr_t at = reinterpret_cast<uintptr_t>(&r);
                ASSERT_EQ(at % 16, 0u) << i;
                ASSERT_EQ(at / 64, (at + sizeof r - 1) / 64) << i;
                EXPECT_EQ(r.lo, pz->slabLo(i));
                ASSERT_LT(r.head, lists.size());
                const std::span<const uint32_t> prims = pz->slabPrimitives(i);
                EXPECT_EQ(prims.data(), lists.data() + r.head + 1) << i;
                EXPECT_EQ(prims.size(), lists[r.head]) << i;
                if (pz->unionOnly()) {
                    EXPECT_EQ(r.rootOrLength, int32_t(lists[r.head])) << i;
                    EXPECT_EQ(pz->slabRoot(i), -1) << i;
                } else {
                    EXPECT_EQ(pz->slabRoot(i), r.rootOrLength) << i;
                    if (prims.empty()) {
                        EXPECT_LT(r.rootOrLength, 0) << i;
                    }
                }
            }
        }
        EXPECT_GT(slabs, 0u);
        EXPECT_GT(lights, 0u);
    });
}

// headedLists lays each list out after its length and before the common tail, at its head:
// the empty list too (its length is the tail's), and the last head is the array's size.
TEST(Irregular, HeadedListsKeepEachListAfterItsLength) {
    const std::vector<uint32_t> first = {0, 0, 2, 5}, prims = {7, 9, 1, 2, 3};
    const std::vector<uint32_t> tail = {4};
    std::vector<uint32_t> heads;
    EXPECT_EQ(headedLists(first, prims, tail, heads),
              (std::vector<uint32_t>{1, 4, 3, 7, 9, 4, 4, 1, 2, 3, 4}));
    EXPECT_EQ(heads, (std::vector<uint32_t>{0, 2, 6, 11}));
    EXPECT_EQ(headedLists(first, prims, {}, heads),
              (std::vector<uint32_t>{0, 2, 7, 9, 3, 1, 2, 3}));
    EXPECT_EQ(heads, (std::vector<uint32_t>{0, 1, 4, 8}));
}

/// What a screen BSP costs a ray through the screen rectangle by its own estimate: the
/// rectangles of the zone it lands in, zones weighted by their share of the area (`mean`); and
/// the most any one zone adds to it (`worst`).
struct ZoneCost {
    double mean = 0.0, worst = 0.0;
};
ZoneCost zoneCost(const ScreenBsp& bsp, glm::dvec2 lo, glm::dvec2 hi) {
    const double area = (hi.x - lo.x) * (hi.y - lo.y);
    ZoneCost c;
    for (size_t z = 0; z < bsp.zoneCount(); ++z) {
        const glm::dvec2 e = bsp.zoneHi[z] - bsp.zoneLo[z];
        const double part = e.x * e.y / area * double(bsp.zoneFirst[z + 1] - bsp.zoneFirst[z]);
        c.mean += part;
        c.worst = std::max(c.worst, part);
    }
    return c;
}

/// Screen BSP parameters of the count model (stepCost 4), stopping at `stopObjects`, charging
/// 64 bytes a zone and 40 a reference.
ScreenBspParams countModelParams(int stopObjects) {
    ScreenBspParams p;
    p.heuristic = BspHeuristic::Balanced;
    p.stopObjects = stopObjects;
    p.stepCost = 4.0;
    p.zoneBytes = 64;
    p.refBytes = 40;
    return p;
}

// A screen BSP stopped by its byte limit has spent it across the whole screen: its cells are
// split in order of the cost estimate's gain, so no zone is left much coarser than the others.
// Stopped at a fifth of its unbounded bytes, this scene's BSP has 386 zones (3,488 unbounded)
// and costs 76 tests a ray by the estimate (23.7 unbounded), no zone adding more than 2.9.
// Split depth first, the first cells were split to the end and the cells still waiting at the
// limit (half the screen, a quarter, ..) became zones: 473 zones, 1,314 tests a ray, one zone
// adding 939.
TEST(Irregular, ScreenBspStoppedByItsBudgetSpendsItEvenly) {
    Scene scene = loadScene("builtin:lattice:12");
    auto accel = buildIrregular(scene);
    const IrregularSubdivision& s = irregularOf(*accel);
    std::vector<Box3> rect(scene.prims.size());
    const std::vector<uint32_t> live = scene.livePrimitives();
    for (uint32_t p : live) rect[p] = s.frame().box(scene.minBox[p]);
    const glm::dvec2 lo(s.bounds().lo), hi(s.bounds().hi);
    ScreenBspParams p = countModelParams(4);
    const ScreenBsp free = ScreenBsp::build(rect, live, lo, hi, p);
    ASSERT_FALSE(free.stopped);
    const ZoneCost full = zoneCost(free, lo, hi);
    p.maxBytes = (free.zoneCount() * p.zoneBytes + free.zonePrims.size() * p.refBytes) / 5;
    const ScreenBsp bsp = ScreenBsp::build(rect, live, lo, hi, p);
    ASSERT_TRUE(bsp.stopped);
    EXPECT_LT(bsp.zoneCount(), free.zoneCount() / 2);
    const ZoneCost c = zoneCost(bsp, lo, hi);
    std::printf(
        "unbounded: %zu zones, %.2f tests a ray (worst zone %.2f); stopped: %zu zones, "
        "%.2f (worst zone %.2f)\n",
        free.zoneCount(), full.mean, full.worst, bsp.zoneCount(), c.mean, c.worst);
    EXPECT_LT(c.mean, 5.0 * full.mean);
    EXPECT_LT(c.worst, 0.1 * c.mean);
    // Stopped or not, the zones tile the rectangle and list every rectangle over them.
    double area = 0.0;
    for (size_t z = 0; z < bsp.zoneCount(); ++z) {
        const glm::dvec2 e = bsp.zoneHi[z] - bsp.zoneLo[z];
        area += e.x * e.y;
        for (uint32_t q : live) {
            const Box3& r = rect[q];
            const bool over = r.lo.x < bsp.zoneHi[z].x && bsp.zoneLo[z].x < r.hi.x &&
                              r.lo.y < bsp.zoneHi[z].y && bsp.zoneLo[z].y < r.hi.y;
            const auto first = bsp.zonePrims.begin() + bsp.zoneFirst[z];
            const auto last = bsp.zonePrims.begin() + bsp.zoneFirst[z + 1];
            if (over) {
                EXPECT_NE(std::find(first, last, q), last) << "zone " << z << " misses " << q;
            }
        }
    }
    EXPECT_NEAR(area, (hi.x - lo.x) * (hi.y - lo.y), 1e-9 * (hi.x - lo.x) * (hi.y - lo.y));
}

/// A scene's camera-frame rectangles, hulls and stop shares for the screen BSP, and a walk model
/// of the build's charges with `rays` rays over the rectangle.
struct BspInputs {
    Scene scene;
    std::vector<uint32_t> live;
    PrimitiveHulls hulls;
    std::vector<Box3> rect;
    glm::dvec2 lo, hi;
    std::vector<float> stops;
    ZoneWalkModel walk;
};

BspInputs bspInputs(const char* name, double rays) {
    BspInputs in{loadScene(name), {}, {}, {}, {}, {}, {}, {}};
    const Scene& scene = in.scene;
    const FrameChoice turned = chooseGridFrame(scene);
    const CameraFrame frame = CameraFrame::of(scene.camera);
    in.live = scene.livePrimitives();
    in.hulls = PrimitiveHulls::make(scene, frame, turned, in.live, 1e-9 * scene.scale());
    in.rect.resize(scene.prims.size());
    for (uint32_t p : in.live) in.rect[p] = frame.box(scene.minBox[p]);
    const Box3 cam = frame.box(scene.bounds);
    in.lo = glm::dvec2(cam.lo);
    in.hi = glm::dvec2(cam.hi);
    in.stops = stopShares(scene, frame);
    in.walk.visit = in.walk.test = 250.0;
    in.walk.level = 12.0;
    in.walk.fill = 0.5;
    in.walk.zone = 500.0;
    in.walk.ref = 1000.0;
    in.walk.raysPerArea = rays / ((in.hi.x - in.lo.x) * (in.hi.y - in.lo.y));
    return in;
}

/// The screen BSP's parameters for the walk model over `in`: its hulls' outlines and depth
/// ranges along the camera frame's depth, its stop shares, cells stopping at one primitive.
ScreenBspParams walkModelParams(const BspInputs& in) {
    ScreenBspParams p = countModelParams(1);
    p.hulls = &in.hulls;
    p.column = ZoneColumn::Parallel;
    p.walk = &in.walk;
    p.stops = &in.stops;
    return p;
}

// A waiting cell keeps, in its references' top bits, the sides of its split that the cost
// estimate found each primitive on, and the split sorts them by those bits: every zone lists
// exactly the primitives whose rectangle's interior and hull outline meet it, in the order of
// `live`, none with a side bit left, whether the BSP ran to its end, stopped on its byte limit
// (the cells waiting then become zones with their bits cleared), or followed the walk model.
TEST(Irregular, ScreenBspZonesListWhatMeetsThemAfterTheSplitsSideBits) {
    size_t zones = 0, stopped = 0;
    for (const char* name : {"builtin:sponge:2", "builtin:balls:3"}) {
        const BspInputs in = bspInputs(name, 4096.0);
        const std::vector<uint32_t>& live = in.live;
        const std::vector<Box3>& rect = in.rect;
        const glm::dvec2 lo = in.lo, hi = in.hi;
        size_t freeBytes = 0;  // what the unbounded build's zones cost
        for (int mode = 0; mode < 3; ++mode) {
            ScreenBspParams p = countModelParams(1);
            p.hulls = &in.hulls;
            p.column = ZoneColumn::Parallel;
            if (mode == 1) p.maxBytes = freeBytes / 5;
            if (mode == 2) {
                p.walk = &in.walk;
                p.stops = &in.stops;
            }
            const ScreenBsp bsp = ScreenBsp::build(rect, live, lo, hi, p);
            if (mode == 0)
                freeBytes = bsp.zoneCount() * p.zoneBytes + bsp.zonePrims.size() * p.refBytes;
            stopped += bsp.stopped;
            zones += bsp.zoneCount();
            for (size_t z = 0; z < bsp.zoneCount(); ++z) {
                const glm::dvec2 zl = bsp.zoneLo[z], zh = bsp.zoneHi[z];
                std::vector<uint32_t> want;
                for (uint32_t q : live) {
                    const Box3& r = rect[q];
                    if (r.lo.x < zh.x && zl.x < r.hi.x && r.lo.y < zh.y && zl.y < r.hi.y &&
                        in.hulls.touches(q, ZoneColumn::Parallel, zl, zh))
                        want.push_back(q);
                }
                const std::vector<uint32_t> got(bsp.zonePrims.begin() + bsp.zoneFirst[z],
                                                bsp.zonePrims.begin() + bsp.zoneFirst[z + 1]);
                ASSERT_EQ(got, want) << name << " mode " << mode << " zone " << z;
            }
        }
    }
    EXPECT_GT(zones, 300u);
    EXPECT_EQ(stopped, 2u);  // the byte limit stopped each scene's second build
}

// Cells keep their segments presorted from cell to cell (by axis and line, and by each end
// along the other axis), each split filtering its orders into its children's, the cut pieces'
// new ends moved to the end of the lower piece's order and the start of the upper one's. At
// every presorted cell the orders read what a fresh sort of the cell's segments gives
// (checkOrders throws otherwise), and the BSP is the one built sorting every cell: the same
// lines, zones, lists and counts, with the count model and the walk model, both heuristics that
// score lines, without a byte limit, with one that leaves the orders out of some cells (an
// eighth of it for them), and with one that stops the BSP.
TEST(Irregular, ScreenBspPresortedSegmentsSplitAsAFreshSortAndBuildTheSameBsp) {
    size_t checked = 0;
    for (const char* name : {"builtin:balls:3", "builtin:sponge:2", "builtin:drilled:3"}) {
        const BspInputs in = bspInputs(name, 65536.0);
        const std::vector<uint32_t>& live = in.live;
        const std::vector<Box3>& rect = in.rect;
        const glm::dvec2 lo = in.lo, hi = in.hi;
        size_t freeBytes = 0;  // what the walk model's unbounded zones cost
        for (int mode = 0; mode < 6; ++mode) {
            ScreenBspParams p = countModelParams(mode == 1 ? 0 : 4);
            if (mode == 2) p.heuristic = BspHeuristic::FewestCuts;
            if (mode >= 3) {
                p.hulls = &in.hulls;
                p.column = ZoneColumn::Parallel;
                p.walk = &in.walk;
                p.stops = &in.stops;
                p.stopObjects = 1;
            }
            // The unbounded BSP's bytes (the orders then fit in an eighth of them only while
            // the cells waiting are few), then a fifth of them, which stops it.
            if (mode == 4) p.maxBytes = freeBytes;
            if (mode == 5) p.maxBytes = freeBytes / 5;
            p.presorted = false;
            const ScreenBsp want = ScreenBsp::build(rect, live, lo, hi, p);
            p.presorted = true;
            p.checkOrders = true;
            const ScreenBsp got = ScreenBsp::build(rect, live, lo, hi, p);
            const std::string what = std::string(name) + " mode " + std::to_string(mode);
            if (mode == 3)
                freeBytes = got.zoneCount() * p.zoneBytes + got.zonePrims.size() * p.refBytes;
            ASSERT_EQ(got.nodes.size(), want.nodes.size()) << what;
            for (size_t n = 0; n < got.nodes.size(); ++n) {
                ASSERT_EQ(got.nodes[n].axis, want.nodes[n].axis) << what << " node " << n;
                ASSERT_EQ(got.nodes[n].value, want.nodes[n].value) << what << " node " << n;
                ASSERT_EQ(got.nodes[n].child[0], want.nodes[n].child[0]) << what << " node " << n;
                ASSERT_EQ(got.nodes[n].child[1], want.nodes[n].child[1]) << what << " node " << n;
            }
            EXPECT_EQ(got.root, want.root) << what;
            EXPECT_EQ(got.zoneLo, want.zoneLo) << what;
            EXPECT_EQ(got.zoneHi, want.zoneHi) << what;
            EXPECT_EQ(got.zoneFirst, want.zoneFirst) << what;
            EXPECT_EQ(got.zonePrims, want.zonePrims) << what;
            EXPECT_EQ(got.cuts, want.cuts) << what;
            EXPECT_EQ(got.costStops, want.costStops) << what;
            EXPECT_EQ(got.limitStops, want.limitStops) << what;
            EXPECT_EQ(got.stopped, want.stopped) << what;
            if (mode != 4) {
                EXPECT_EQ(got.stopped, mode == 5) << what;
            }
            checked += got.nodes.size();
        }
    }
    EXPECT_GT(checked, 1000u);
}

// Two sorts of the build made once or lighter, each giving what the sort it replaces gave:
// - the walk model sorts each cell's depth events by a key of their depth and index, with the
//   comparison std::sort of the events themselves takes: the keys' permutation is that sort's,
//   ties (boxes sharing a depth, a range's middle at another's end) in the same order, so every
//   cost is the same sum bit for bit (checkOrders throws otherwise; a stable sort of the keys
//   breaks it), in cells of up to 64 primitives with the hulls' ranges and in larger ones with
//   their boxes';
// - the depth slabs keep the cuts each zone's check of the limits sorts (while they take at most
//   an eighth of the byte limit) and cut the zone at them: the slabs are those of a build that
//   sorts every zone's cuts once, without that check (no limit), region for region and list for
//   list, on the zones of that BSP narrowed by the hulls.
// Scenes of blocks on a grid (sponge:2, lattice:4, drilled:3) and of spheres (balls:3).
TEST(Irregular, WalkCostsAndSlabsFromTheKeptSortsAreTheFreshSorts) {
    size_t zones = 0, regions = 0;
    for (const char* name :
         {"builtin:sponge:2", "builtin:lattice:4", "builtin:balls:3", "builtin:drilled:3"}) {
        const BspInputs in = bspInputs(name, 65536.0);
        ScreenBspParams p = walkModelParams(in);
        ScreenBsp bsp = ScreenBsp::build(in.rect, in.live, in.lo, in.hi, p);
        EXPECT_GT(bsp.costStops, 0u) << name;  // the walk model decided
        zones += bsp.zoneCount();
        p.checkOrders = true;
        EXPECT_NO_THROW(ScreenBsp::build(in.rect, in.live, in.lo, in.hi, p)) << name;
        const CameraFrame frame = CameraFrame::of(in.scene.camera);
        const Box3 cam = frame.box(in.scene.bounds);
        const double pad = 1e-9 * in.scene.scale();
        const std::vector<glm::dvec2> depth =
            narrowZones(bsp, in.hulls, ZoneColumn::Parallel, in.rect, cam.lo.z, cam.hi.z, pad);
        const DepthSlabs want = buildDepthSlabs(in.scene, bsp, depth, cam.lo.z, cam.hi.z);
        const DepthSlabs got = buildDepthSlabs(in.scene, bsp, depth, cam.lo.z, cam.hi.z, nullptr, 0,
                                               std::numeric_limits<size_t>::max() / 2);
        ASSERT_EQ(got.regions.size(), want.regions.size()) << name;
        for (size_t r = 0; r < got.regions.size(); ++r) {
            const IrregularRegion &a = got.regions[r], &b = want.regions[r];
            ASSERT_EQ(a.zone, b.zone) << name << " region " << r;
            ASSERT_EQ(a.zlo, b.zlo) << name << " region " << r;
            ASSERT_EQ(a.zhi, b.zhi) << name << " region " << r;
            ASSERT_EQ(a.list, b.list) << name << " region " << r;
            ASSERT_EQ(a.root, b.root) << name << " region " << r;
        }
        EXPECT_EQ(got.zoneFirstRegion, want.zoneFirstRegion) << name;
        EXPECT_EQ(got.listFirst, want.listFirst) << name;
        EXPECT_EQ(got.listPrims, want.listPrims) << name;
        EXPECT_EQ(got.slabs, want.slabs) << name;
        EXPECT_EQ(got.mergedZones + got.coarseZones, 0u) << name;
        EXPECT_GT(want.slabs, 2 * bsp.zoneCount()) << name;  // zones cut in depth
        regions += got.regions.size();
    }
    EXPECT_GT(zones, 300u);
    EXPECT_GT(regions, 1000u);
}

// The walk reported to the observer: regions in ray order with contiguous intervals, the
// corner pointers followed between them, mailbox hits for primitives shared by regions.
TEST(Irregular, ObserverSeesRegionsPointersAndMailboxes) {
    Scene scene = loadScene("builtin:lattice:4");
    auto accel = buildIrregular(scene, BspHeuristic::Balanced, 0, IrregularFrame::Camera);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    ctx.useMailboxes = accel->usesMailboxes();
    uint64_t pointers = 0, mailbox = 0;
    for (const Ray& ray : test::pixelRays(scene, 12, 12)) {
        uint64_t before = ctx.counters.pointerSteps;
        RecordingObserver obs = test::recordWalk(*accel, ray, ctx);
        double last = -kInf;
        int regions = 0;
        uint64_t seen = 0;
        for (const WalkEvent& e : obs.events) {
            if (const walk::Region* g = e.get<walk::Region>()) {
                if (regions > 0) {
                    EXPECT_EQ(g->t0, last) << "intervals not contiguous";
                }
                EXPECT_LE(g->t0, g->t1);
                last = g->t1;
                ++regions;
            } else if (const walk::Pointer* p = e.get<walk::Pointer>()) {
                ++seen;
                EXPECT_GE(p->corner, 0);
            } else if (e.kind() == WalkEvent::MailboxHit) {
                ++mailbox;
            }
        }
        EXPECT_EQ(seen, ctx.counters.pointerSteps - before);
        pointers += seen;
    }
    EXPECT_GT(pointers, 0u);
    EXPECT_GT(mailbox, 0u);
    EXPECT_EQ(ctx.counters.walkErrors, 0u);
}

// A union-only scene's regions keep their primitive lists and no restricted tree: every root is
// -1 and the pools are empty, in both frames; the walk merges the listed primitives' spans
// (hitInLeaf) and finds brute force's hits ray for ray, primary and secondary, and the observer
// is told every region visit and primitive test the counters count. A CSG scene keeps its trees.
TEST(Irregular, UnionOnlyRegionsKeepListsNotTrees) {
    Scene scene = loadScene(std::string(LANCER_SPD_DIR) + "/balls2.nff");
    ASSERT_TRUE(scene.tree.unionOnly());
    auto accel = buildIrregular(scene);
    const IrregularSubdivision& s = irregularOf(*accel);
    EXPECT_TRUE(s.unionOnly());
    EXPECT_TRUE(s.projective().unionOnly());
    EXPECT_TRUE(s.treePool().nodes.empty());
    EXPECT_TRUE(s.projective().treePool().nodes.empty());
    EXPECT_EQ(accel->info().extra["distinct_trees"].get<size_t>(), 0u);
    size_t listed = 0;
    for (uint32_t r = 0; r < s.regions().size(); ++r) {
        EXPECT_EQ(s.regions()[r].root, -1);
        listed += s.primitives(r).empty() ? 0 : 1;
    }
    EXPECT_GT(listed, 0u);
    for (uint32_t i = 0; i < s.projective().zoneFirst().back(); ++i)
        EXPECT_EQ(s.projective().slabRoot(i), -1);
    EXPECT_TRUE(s.projective().hasNearRegion());  // the eye stands among the balls' boxes
    EXPECT_EQ(s.projective().nearRoot(), -1);
    std::vector<Ray> rays = test::pixelRays(scene, 40, 40);
    expectSame(scene, *accel, rays, "balls2 union-only");
    expectSame(scene, *accel, secondaryRays(scene, rays, 3), "balls2 union-only secondary",
               1e-9 * scene.scale());
    test::makeOrthographic(scene);
    auto ortho = buildIrregular(scene);
    expectSame(scene, *ortho, test::pixelRays(scene, 40, 40), "balls2 union-only orthographic");

    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    ctx.useMailboxes = accel->usesMailboxes();
    uint64_t tests = 0;
    for (const Ray& ray : test::pixelRays(scene, 12, 12)) {
        const RayCounters before = ctx.counters;
        RecordingObserver obs = test::recordWalk(*ortho, ray, ctx);
        uint64_t regions = 0, prims = 0;
        for (const WalkEvent& e : obs.events) {
            regions += e.kind() == WalkEvent::Region;
            prims += e.kind() == WalkEvent::PrimTest;
        }
        EXPECT_EQ(regions, ctx.counters.regionVisits - before.regionVisits);
        EXPECT_EQ(prims, ctx.counters.primTests - before.primTests);
        tests += prims;
    }
    EXPECT_GT(tests, 0u);

    Scene csg = loadScene("builtin:drilled:4");
    ASSERT_FALSE(csg.tree.unionOnly());
    auto withTrees = buildIrregular(csg);
    const IrregularSubdivision& t = irregularOf(*withTrees);
    EXPECT_FALSE(t.unionOnly());
    EXPECT_FALSE(t.treePool().nodes.empty());
    EXPECT_TRUE(std::any_of(t.regions().begin(), t.regions().end(),
                            [](const IrregularRegion& r) { return r.root >= 0; }));
    EXPECT_GT(withTrees->info().extra["distinct_trees"].get<size_t>(), 0u);
}

// In a union-only scene a primitive whose camera-frame box covers a large share of the
// structure's screen rectangle (balls2's floor, a ball that holds the others) is in no
// camera-frame list: every camera-frame region merges it, fetched once a walk. Every ray is
// walked in the camera frame here (--irregular-frame camera). The hits are brute force's for
// rays that meet the floor behind the balls (from above them) and in front of them (from under
// the floor), along it, from the hits of the pixels' rays, and for rays that start inside the
// large ball and leave it through a small one jutting out of it: the union's stretch ends on the
// small ball, not where the large one ends.
TEST(Irregular, LargePrimitivesOfAUnionAreSharedNotListed) {
    auto listsNone = [](const IrregularSubdivision& s, uint32_t p) {
        for (uint32_t r = 0; r < s.regions().size(); ++r) {
            const auto prims = s.primitives(r);
            if (std::find(prims.begin(), prims.end(), p) != prims.end()) return false;
        }
        return true;
    };
    Scene balls = loadScene(std::string(LANCER_SPD_DIR) + "/balls2.nff");
    ASSERT_TRUE(balls.tree.unionOnly());
    const std::vector<uint32_t> live = balls.livePrimitives();
    const uint32_t floor = *std::max_element(live.begin(), live.end(), [&](uint32_t a, uint32_t b) {
        return balls.minBox[a].extent().x < balls.minBox[b].extent().x;
    });
    auto accel = buildIrregular(balls, BspHeuristic::Balanced, 0, IrregularFrame::Camera);
    const IrregularSubdivision& s = irregularOf(*accel);
    ASSERT_EQ(s.shared().size(), 1u);
    EXPECT_EQ(s.shared()[0], floor);
    EXPECT_EQ(accel->info().extra["shared_primitives"].get<size_t>(), 1u);
    EXPECT_TRUE(listsNone(s, floor));
    std::vector<Ray> rays = test::pixelRays(balls, 40, 40);
    for (const Ray& r : secondaryRays(balls, rays, 5)) rays.push_back(r);
    const Box3& fb = balls.minBox[floor];
    for (uint32_t p : live) {
        if (p == floor) continue;
        const Vec3 c = balls.minBox[p].center();
        rays.push_back({c + Vec3(0, 0, 3), {0, 0, -1}});           // the ball, then the floor
        rays.push_back({Vec3(c.x, c.y, fb.lo.z - 3), {0, 0, 1}});  // the floor, then the ball
        rays.push_back({c + Vec3(0.3, 0.2, 2), glm::normalize(Vec3(0.2, -0.1, -1))});
        rays.push_back({Vec3(c.x, c.y, fb.center().z), glm::normalize(Vec3(1, 0.3, 0))});
    }
    expectSame(balls, *accel, rays, "balls2, the floor shared");
    // Past the box of the listed primitives (occupied()) the walk goes on only toward a boundary
    // of a shared primitive: rays going up from the balls, away from the floor, enter no region
    // beyond it, though the structure reaches far beyond it.
    TraceContext ctx(balls.prims.size(), balls.tree.depth());
    ctx.useMailboxes = accel->usesMailboxes();
    size_t beyond = 0;
    for (uint32_t p : live) {
        if (p == floor) continue;
        const Ray up{balls.minBox[p].center(), {0, 0, 1}};
        const Ray rc = s.frame().ray(up);
        double o0, o1, b0, b1;
        ASSERT_TRUE(clipLine(rc, s.occupied(), o0, o1));
        ASSERT_TRUE(clipLine(rc, s.bounds(), b0, b1));
        beyond += b1 > o1 + 0.5;
        for (const WalkEvent& e : test::recordWalk(*accel, up, ctx).events)
            if (const walk::Region* r = e.get<walk::Region>()) {
                EXPECT_LE(r->t0, o1) << "p" << p << ": region " << r->region;
            }
    }
    EXPECT_GT(beyond, live.size() / 2);

    const std::string nested = R"({
      "camera": {"from": [30, -40, 25], "at": [0, 0, 0], "up": [0, 0, 1], "fov": 40},
      "scene": {"union": [
        {"sphere": {"radius": 10}},
        {"sphere": {"radius": 1.5}, "transform": [{"translate": [10, 0, 0]}]},
        {"sphere": {"radius": 1}, "transform": [{"translate": [0, 0, 10.5]}]},
        {"sphere": {"radius": 1}, "transform": [{"translate": [-4, 3, 2]}]},
        {"sphere": {"radius": 2}, "transform": [{"translate": [0, -11, 0]}]}
      ]}})";
    Scene ball = readJsonScene(SourceText("nested.json", nested));
    ASSERT_TRUE(ball.tree.unionOnly());
    auto big = buildIrregular(ball, BspHeuristic::Balanced, 0, IrregularFrame::Camera);
    const IrregularSubdivision& t = irregularOf(*big);
    ASSERT_EQ(t.shared().size(), 1u);
    EXPECT_GT(ball.minBox[t.shared()[0]].extent().x, 19.0);
    EXPECT_TRUE(listsNone(t, t.shared()[0]));
    std::vector<Ray> inside = test::pixelRays(ball, 32, 32);
    std::mt19937_64 rng(29);
    std::normal_distribution<double> g;
    for (int i = 0; i < 400; ++i) {
        const Vec3 o(0.5 * g(rng), 0.5 * g(rng), 0.5 * g(rng));
        inside.push_back({o, glm::normalize(Vec3(g(rng), g(rng), g(rng)))});
    }
    for (const Vec3& at : {Vec3(10, 0, 0), Vec3(0, 0, 10.5), Vec3(0, -11, 0)})
        for (int i = 0; i < 30; ++i)
            inside.push_back({Vec3(0.0), glm::normalize(at + Vec3(g(rng), g(rng), g(rng)) * 0.3)});
    expectSame(ball, *big, inside, "a ball holding others, shared");
}

/// A union-only cloud of overlapping spheres around an eye inside one of them, written as an NFF
/// file: every primary ray starts inside the union, and so do rays from the spheres' centres.
Scene overlappingSpheres(uint64_t seed, int count) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> c(-2.0, 2.0), r(0.2, 0.7);
    const std::string path = ::testing::TempDir() + "/overlapping" + std::to_string(seed) + ".nff";
    {
        std::ofstream f(path);
        f << "v\nfrom 0.1 0.2 0.3\nat 3 2.5 2\nup 0 0 1\nangle 50\nhither 0.01\n"
          << "resolution 64 64\nl 5 4 6\nf 1 0.8 0.6 0.5 0.5 3 0 1\n";
        f << "s 0.1 0.2 0.3 0.6\n";  // holds the eye
        for (int i = 1; i < count; ++i)
            f << "s " << c(rng) << ' ' << c(rng) << ' ' << c(rng) << ' ' << r(rng) << '\n';
    }
    Scene scene = loadScene(path);
    std::filesystem::remove(path);
    return scene;
}

// A union-only scene's walks without an observer (hitInIrregularRegion with NullObserver, whose
// regions skip the merge when no boundary of theirs lies in the window) against the walks an
// observer sees (shown every region's merged spans) and brute force, ray for ray, in both frames
// and with and without mailboxes: primary rays from an eye inside a sphere (the near region,
// then depth slabs), rays from the spheres' centres (the camera-frame walk, starting inside the
// union, where a region's hit is the end of a merged stretch), secondary rays off the hits, and
// an orthographic view. The two give the same hit (t, primitive, part, side) and the same tests,
// mailbox hits, region visits and pointer steps, and the observer is told every visit, test and
// mailbox hit the counters count.
TEST(Irregular, UnionOnlyWalkEqualsObservedWalkAndBruteForce) {
    Scene scene = overlappingSpheres(41, 240);
    ASSERT_TRUE(scene.tree.unionOnly());
    std::mt19937_64 rng(5);
    std::normal_distribution<double> n;
    std::vector<Ray> fromInside;
    for (uint32_t p = 0; p < scene.prims.size(); p += 3) {
        const Vec3 o = scene.minBox[p].center();
        for (int k = 0; k < 3; ++k)
            fromInside.push_back({o, glm::normalize(Vec3(n(rng), n(rng), n(rng)))});
    }
    const std::vector<Ray> primary = test::pixelRays(scene, 32, 32);
    const std::vector<Ray> secondary = secondaryRays(scene, primary, 9);
    const double offset = 1e-9 * scene.scale();
    Scene ortho = scene;
    test::makeOrthographic(ortho);
    ortho.prepare();
    const std::vector<Ray> orthoRays = test::pixelRays(ortho, 24, 24);

    size_t merged = 0, compared = 0;
    auto check = [&](const Scene& sc, const Accelerator& accel, const std::vector<Ray>& rays,
                     double tmin, bool mailboxes, const std::string& what) {
        expectSame(sc, accel, rays, what, tmin);
        TraceContext fast(sc.prims.size(), sc.tree.depth()), seen(sc.prims.size(), sc.tree.depth());
        fast.useMailboxes = seen.useMailboxes = mailboxes;
        NullObserver none;
        for (const Ray& ray : rays) {
            const RayCounters a = fast.counters, b = seen.counters;
            Hit hf, ho;
            fast.beginRay();
            seen.beginRay();
            RecordingObserver obs;
            const bool ff = accel.intersect(ray, tmin, kInf, fast, none, hf);
            const bool fo = accel.intersect(ray, tmin, kInf, seen, obs, ho);
            ASSERT_EQ(ff, fo) << what;
            if (ff) {
                ASSERT_EQ(hf.t, ho.t) << what;
                ASSERT_EQ(hf.prim, ho.prim) << what;
                ASSERT_EQ(hf.part, ho.part) << what;
                ASSERT_EQ(hf.flip, ho.flip) << what;
            }
            ASSERT_EQ(fast.counters.primTests - a.primTests, seen.counters.primTests - b.primTests)
                << what;
            ASSERT_EQ(fast.counters.mailboxHits - a.mailboxHits,
                      seen.counters.mailboxHits - b.mailboxHits)
                << what;
            ASSERT_EQ(fast.counters.regionVisits - a.regionVisits,
                      seen.counters.regionVisits - b.regionVisits)
                << what;
            ASSERT_EQ(fast.counters.pointerSteps - a.pointerSteps,
                      seen.counters.pointerSteps - b.pointerSteps)
                << what;
            uint64_t regions = 0, tests = 0, mailboxHits = 0;
            for (const WalkEvent& e : obs.events) {
                regions += e.kind() == WalkEvent::Region;
                tests += e.kind() == WalkEvent::PrimTest;
                mailboxHits += e.kind() == WalkEvent::MailboxHit;
            }
            ASSERT_EQ(regions, seen.counters.regionVisits - b.regionVisits) << what;
            ASSERT_EQ(tests, seen.counters.primTests - b.primTests) << what;
            ASSERT_EQ(mailboxHits, seen.counters.mailboxHits - b.mailboxHits) << what;
            // A ray starting inside the union: its hit ends the merged stretch it starts in.
            if (ff) {
                bool inside = false;
                for (uint32_t p = 0; p < sc.prims.size() && !inside; ++p) {
                    Span sp[2];
                    const int k = sc.primSpans(p, ray, sp, Precision::Double);
                    for (int j = 0; j < k; ++j) inside |= sp[j].in.t < tmin && sp[j].out.t > tmin;
                }
                merged += inside;
            }
            ++compared;
        }
    };
    for (IrregularFrame frame : {IrregularFrame::Projective, IrregularFrame::Camera}) {
        auto accel = buildIrregular(scene, BspHeuristic::Balanced, 4, frame);
        const IrregularSubdivision& s = irregularOf(*accel);
        ASSERT_TRUE(s.unionOnly());
        if (frame == IrregularFrame::Projective) {
            ASSERT_TRUE(s.projective().unionOnly());
            EXPECT_TRUE(s.projective().hasNearRegion());  // the eye's sphere
        }
        const std::string name = irregularFrameName(frame);
        for (bool mailboxes : {true, false}) {
            const std::string m = mailboxes ? "" : " no mailbox";
            check(scene, *accel, primary, 0.0, mailboxes, name + " primary" + m);
            check(scene, *accel, fromInside, 0.0, mailboxes, name + " from inside" + m);
            check(scene, *accel, secondary, offset, mailboxes, name + " secondary" + m);
        }
    }
    auto orthoAccel = buildIrregular(ortho);
    check(ortho, *orthoAccel, orthoRays, 0.0, true, "orthographic");
    EXPECT_GT(merged, 500u);
    EXPECT_GT(compared, 10000u);
}

// A union-only region's hit without an active observer (hitInLeaf with no tree: the irregular
// scheme's regions in a union-only scene) against the merge it stands for: random spheres (with
// duplicates: ties), random rays, lists, windows [t0, t1] and tmin (before, inside and after
// spans, on their ends). The same hit (t, primitive, part, side) as flatUnion then firstBoundary
// over the listed primitives' spans in list order, or none; and the spans are merged only when
// the ray starts the window inside a stretch of their union: a hit that starts a span inside the
// window leaves ctx.result as it was.
TEST(Irregular, UnionOnlyRegionMergesOnlyInsideAStretch) {
    std::mt19937_64 rng(29);
    std::uniform_real_distribution<double> u(-4.0, 4.0), radius(0.3, 1.5);
    Scene s;
    std::vector<int> leaves;
    for (int i = 0; i < 24; ++i) {
        Sphere sp{Vec3(u(rng), u(rng), u(rng)), radius(rng)};
        if (i % 6 == 5) sp = std::get<Sphere>(s.prims.back().shape);  // a duplicate: ties
        s.prims.push_back(makePrimitive(sp, Transform{}));
        leaves.push_back(s.tree.leaf(uint32_t(s.prims.size() - 1)));
    }
    s.tree.root = s.tree.balanced(Op::Union, leaves);
    s.prepare();
    ASSERT_TRUE(s.tree.unionOnly());
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    const Span sentinel{{-1e9, 999, 0, false}, {-1e9 + 1, 999, 1, false}};
    size_t unmerged = 0, merged = 0;
    for (int trial = 0; trial < 20000; ++trial) {
        const Ray ray{Vec3(u(rng), u(rng), u(rng)) * 2.0,
                      glm::normalize(Vec3(u(rng), u(rng), u(rng)) + 1e-9)};
        std::vector<uint32_t> keys;
        for (uint32_t p = 0; p < s.prims.size(); ++p)
            if (rng() % 3 == 0) keys.push_back(p);
        std::shuffle(keys.begin(), keys.end(), rng);
        SpanList listed, want;
        std::vector<double> ends;
        for (uint32_t p : keys) {
            Span sp[2];
            const int n = s.primSpans(p, ray, sp, Precision::Double);
            for (int k = 0; k < n; ++k) {
                listed.push_back(sp[k]);
                ends.push_back(sp[k].in.t);
                ends.push_back(sp[k].out.t);
            }
        }
        flatUnion(listed, want);
        auto pick = [&] {
            return !ends.empty() && rng() % 3 == 0 ? ends[rng() % ends.size()] : 3.0 * u(rng);
        };
        double t0 = pick(), t1 = pick();
        const double tmin = rng() % 2 ? pick() : -kInf;
        if (t0 > t1) std::swap(t0, t1);
        const Boundary* b = firstBoundary(want, tmin, t0, t1);
        ctx.beginRay();
        ctx.beginLeafWalk();
        ctx.result.assign(1, sentinel);
        Hit hit;
        const bool got = hitInLeaf(s, nullptr, -1, keys.data(), uint32_t(keys.size()), ray, tmin,
                                   t0, t1, ctx, obs, hit);
        ASSERT_EQ(got, b != nullptr) << "trial " << trial;
        if (!b) continue;
        ASSERT_EQ(hit.t, b->t) << "trial " << trial;
        ASSERT_EQ(hit.prim, b->prim) << "trial " << trial;
        ASSERT_EQ(hit.part, b->part) << "trial " << trial;
        ASSERT_EQ(hit.flip, b->flip) << "trial " << trial;
        if (ctx.result.size() == 1 && ctx.result[0].in.prim == 999) {
            ++unmerged;
            // Not merged: the hit starts a span inside the window.
            ASSERT_TRUE(std::any_of(listed.begin(), listed.end(),
                                    [&](const Span& sp) {
                                        return sp.in.t == hit.t && sp.in.prim == hit.prim &&
                                               hit.t >= t0;
                                    }))
                << "trial " << trial;
        } else {
            ++merged;
        }
    }
    EXPECT_GT(unmerged, 400u);
    EXPECT_GT(merged, 200u);  // windows starting inside a stretch: the merge's way
}

// Primary rays on the projective zones: regions in depth order with contiguous intervals, no
// corner pointer, the near region first when the eye stands among the boxes.
TEST(Irregular, ProjectiveWalkIsADepthRun) {
    Scene scene = loadScene(std::string(LANCER_SPD_DIR) + "/balls2.nff");
    auto accel = buildIrregular(scene);
    const IrregularSubdivision& s = irregularOf(*accel);
    ASSERT_GT(s.projective().zoneCount(), 1u);
    EXPECT_TRUE(s.projective().hasNearRegion());  // the floor reaches behind the eye
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    ctx.useMailboxes = accel->usesMailboxes();
    uint64_t visits = 0;
    for (const Ray& ray : test::pixelRays(scene, 16, 16)) {
        RecordingObserver obs = test::recordWalk(*accel, ray, ctx);
        double last = 0.0;
        for (const WalkEvent& e : obs.events) {
            EXPECT_NE(e.kind(), WalkEvent::Pointer);
            const walk::Region* g = e.get<walk::Region>();
            if (!g) continue;
            EXPECT_EQ(g->t0, last) << "intervals not contiguous";
            EXPECT_LE(g->t0, g->t1);
            EXPECT_GE(g->region, s.regions().size());  // ids after the camera-frame regions
            EXPECT_LT(g->region, accel->info().regions);
            last = g->t1;
            ++visits;
        }
    }
    EXPECT_EQ(visits, ctx.counters.regionVisits);
    EXPECT_EQ(ctx.counters.pointerSteps, 0u);
    EXPECT_EQ(ctx.counters.walkErrors, 0u);
}

// The sparse restriction used for thousands of slabs builds the same tree as restrictTree.
// builtin:sponge (OpenSCAD's example024, every bar turned off the world's axes): zones list the
// bars whose turned box's outline meets them, slabs cut at the depths those boxes take over the
// zone, so zones and slabs list few bars. Every pixel and secondary ray hits as brute force, in
// both frames, with a fifteenth of brute force's tests or fewer (the world boxes alone made 26
// per ray against its 61, the turned boxes' camera-frame boxes about a ninth of it).
TEST(IrregularFrame, TurnedSpongeBoundsFollowTheTurn) {
    Scene s = loadScene("builtin:sponge:3");
    const std::vector<Ray> rays = test::pixelRays(s, 64, 64);
    const RayCounters brute = test::traceCounters(s, *buildAccelerator(s, {}), rays);
    for (IrregularFrame frame : {IrregularFrame::Projective, IrregularFrame::Camera}) {
        SCOPED_TRACE(irregularFrameName(frame));
        auto a = buildIrregular(s, BspHeuristic::Balanced, kAutoObjects, frame);
        test::expectSamePixelsAndSecondaries(s, *a, 64, 11, "sponge, irregular");
        const RayCounters c = test::traceCounters(s, *a, rays);
        EXPECT_LT(15 * c.primTests, brute.primTests)
            << c.primTests << " against " << brute.primTests;
    }
}

// Random CSG trees of bars turned by one rotation: the zones narrowed by the turned boxes'
// outlines and depth ranges (primitive_hulls.h) lose no hit, in both frames, on random rays, the
// pixels' rays and secondary rays (tmin > 0).
TEST(IrregularFrame, RandomTurnedSubtreesRayForRay) {
    int turned = 0;
    for (uint64_t seed = 1; seed <= 12; ++seed) {
        Scene s = test::turnedBars(seed * 17 + 3, 24);
        turned += chooseGridFrame(s).frame.turned;
        std::vector<Ray> rays = test::randomRays(s, seed, 3000);
        const std::vector<Ray> pixels = test::pixelRays(s, 32, 32);
        rays.insert(rays.end(), pixels.begin(), pixels.end());
        for (IrregularFrame frame : {IrregularFrame::Projective, IrregularFrame::Camera}) {
            auto a = buildIrregular(s, BspHeuristic::Balanced, kAutoObjects, frame);
            const std::string what = s.name + " " + irregularFrameName(frame);
            expectSame(s, *a, rays, what);
            expectSame(s, *a, rays, what + ", tmin > 0", 1e-3 * s.scale());
        }
    }
    EXPECT_GE(turned, 8);  // most of them are built along the turn
}

// A turned primitive's hull (primitive_hulls.h) in a zone's column, against points sampled in its
// turned box: every sample inside the world box and the column lies in the depth range the hull
// gives, and the outline test never drops a zone such a sample lies in; the ranges are tighter
// than the camera-frame box's (a bar along a diagonal of the view), and outlines drop zones that
// the rectangles would keep, or the test would pass with the whole box.
TEST(PrimitiveHulls, DepthRangesHoldTheSampledPointsAndAreTighter) {
    size_t pairs = 0, tighter = 0, dropped = 0, samples = 0;
    for (uint64_t seed = 1; seed <= 4; ++seed) {
        Scene s = test::turnedBars(seed * 29 + 1, 16);
        const FrameChoice turned = chooseGridFrame(s);
        if (!turned.frame.turned) continue;
        const CameraFrame frame = CameraFrame::of(s.camera);
        const std::vector<uint32_t> live = s.livePrimitives();
        const double pad = 1e-9 * s.scale();
        const PrimitiveHulls hulls = PrimitiveHulls::make(s, frame, turned, live, pad);
        ASSERT_FALSE(hulls.empty());
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> u01(0.0, 1.0);
        for (uint32_t p : live) {
            const Box3& fb = turned.boxes[p];
            if (fb.isEmpty()) continue;
            // Points of the primitive's bound: in its turned box and its world box.
            std::vector<Vec3> pts;
            for (int i = 0; i < 4000; ++i) {
                Vec3 f;
                for (int a = 0; a < 3; ++a) f[a] = fb.lo[a] + u01(rng) * (fb.hi[a] - fb.lo[a]);
                const Vec3 w = turned.frame.toWorld(f);
                if (s.minBox[p].contains(w)) pts.push_back(frame.point(w));
            }
            const Box3 cam = frame.box(s.minBox[p]);
            const glm::dvec2 whole(cam.lo.z, cam.hi.z);
            const double zNear = 1e-3 * s.scale();
            for (ZoneColumn column : {ZoneColumn::Parallel, ZoneColumn::FromEye}) {
                auto screen = [&](const Vec3& c) {
                    return column == ZoneColumn::Parallel ? glm::dvec2(c.x, c.y)
                                                          : glm::dvec2(c.x / c.z, c.y / c.z);
                };
                glm::dvec2 lo(kInf), hi(-kInf);
                for (const Vec3& c : pts) {
                    lo = glm::min(lo, screen(c));
                    hi = glm::max(hi, screen(c));
                }
                // Zones: random rectangles, a fifth of the points' screen rectangle across.
                for (int k = 0; k < 24 && lo.x < hi.x; ++k) {
                    const glm::dvec2 e = 0.2 * (hi - lo);
                    const glm::dvec2 zlo(lo.x - e.x + u01(rng) * (hi.x - lo.x + e.x),
                                         lo.y - e.y + u01(rng) * (hi.y - lo.y + e.y));
                    const glm::dvec2 zhi = zlo + e;
                    const bool touches = hulls.touches(p, column, zlo, zhi);
                    const glm::dvec2 d = hulls.depthIn(p, column, zlo, zhi, zNear, whole);
                    ++pairs;
                    dropped += !touches;
                    tighter += d.x <= d.y && d.y - d.x < 0.6 * (whole.y - whole.x);
                    for (const Vec3& c : pts) {
                        const glm::dvec2 q = screen(c);
                        if (q.x < zlo.x || q.x > zhi.x || q.y < zlo.y || q.y > zhi.y) continue;
                        if (column == ZoneColumn::FromEye && c.z < zNear) continue;
                        ++samples;
                        EXPECT_TRUE(touches) << "p" << p << " dropped from a zone it reaches";
                        EXPECT_GE(c.z, d.x - 1e-9 * s.scale()) << "p" << p;
                        EXPECT_LE(c.z, d.y + 1e-9 * s.scale()) << "p" << p;
                    }
                }
            }
        }
    }
    EXPECT_GT(samples, 10000u);
    EXPECT_GT(tighter, pairs / 4) << tighter << " of " << pairs;
    EXPECT_GT(dropped, pairs / 20) << dropped << " of " << pairs;
}

// In a frame along the world's axes (a light's structure) a primitive with only its world box
// has its outline and depths in closed form: every sampled point of a box that a zone's column
// holds lies within the depth range given and keeps the primitive in the zone, and both ends of
// the range are depths where the column meets the box.
TEST(PrimitiveHulls, AlongTheWorldsAxesTheClosedFormHoldsTheBoxesPoints) {
    Scene s = loadScene("builtin:balls:2");
    const std::vector<uint32_t> live = s.livePrimitives();
    const double pad = 1e-9 * s.scale();
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    size_t samples = 0, pairs = 0, misses = 0;
    for (int axis = 0; axis < 3; ++axis) {
        // The frame of a light beyond the bounds' high side on `axis`, looking back into them.
        CameraFrame f;
        f.origin = s.bounds.center();
        f.origin[axis] = s.bounds.hi[axis] + 0.7 * s.bounds.extent()[axis];
        f.z = Vec3(0.0), f.x = Vec3(0.0), f.y = Vec3(0.0);
        f.z[axis] = -1.0, f.x[(axis + 1) % 3] = 1.0, f.y[(axis + 2) % 3] = 1.0;
        const PrimitiveHulls hulls = PrimitiveHulls::make(s, f, FrameChoice{}, live, pad);
        for (uint32_t p : live) {
            if (p % 7 != 0) continue;
            const Box3 cam = f.box(s.minBox[p]);
            const glm::dvec2 whole(cam.lo.z, cam.hi.z);
            std::vector<Vec3> pts;
            for (int i = 0; i < 3000; ++i) {
                Vec3 w;
                for (int a = 0; a < 3; ++a)
                    w[a] = s.minBox[p].lo[a] + u01(rng) * s.minBox[p].extent()[a];
                pts.push_back(f.point(w));
            }
            for (ZoneColumn column : {ZoneColumn::Parallel, ZoneColumn::FromEye}) {
                auto screen = [&](const Vec3& c) {
                    return column == ZoneColumn::Parallel ? glm::dvec2(c.x, c.y)
                                                          : glm::dvec2(c.x / c.z, c.y / c.z);
                };
                glm::dvec2 lo(kInf), hi(-kInf);
                for (const Vec3& c : pts)
                    lo = glm::min(lo, screen(c)), hi = glm::max(hi, screen(c));
                for (int k = 0; k < 16; ++k) {
                    const glm::dvec2 e = 0.3 * (hi - lo);
                    const glm::dvec2 zlo(lo.x - e.x + u01(rng) * (hi.x - lo.x + e.x),
                                         lo.y - e.y + u01(rng) * (hi.y - lo.y + e.y));
                    const glm::dvec2 zhi = zlo + e;
                    const bool touches = hulls.touches(p, column, zlo, zhi);
                    const glm::dvec2 d = hulls.depthIn(p, column, zlo, zhi, 1e-3, whole);
                    ++pairs;
                    misses += !touches;
                    EXPECT_EQ(touches, d.x <= d.y) << "p" << p;
                    for (const Vec3& c : pts) {
                        const glm::dvec2 q = screen(c);
                        if (q.x < zlo.x || q.x > zhi.x || q.y < zlo.y || q.y > zhi.y) continue;
                        ++samples;
                        EXPECT_TRUE(touches) << "p" << p << " dropped from a zone it reaches";
                        EXPECT_GE(c.z, d.x - pad) << "p" << p;
                        EXPECT_LE(c.z, d.y + pad) << "p" << p;
                    }
                    // Each end is attained: at that depth the column's cross-section meets
                    // the box's (the depths the column meets form an interval).
                    for (double z : {d.x, d.y}) {
                        if (!(d.x <= d.y)) break;
                        const glm::dvec2 a = column == ZoneColumn::Parallel ? zlo : zlo * z;
                        const glm::dvec2 b = column == ZoneColumn::Parallel ? zhi : zhi * z;
                        const double tol = 4.0 * pad;
                        EXPECT_TRUE(a.x <= cam.hi.x + tol && b.x >= cam.lo.x - tol &&
                                    a.y <= cam.hi.y + tol && b.y >= cam.lo.y - tol &&
                                    z >= cam.lo.z - tol && z <= cam.hi.z + tol)
                            << "p" << p << ": depth " << z << " of the range is not attained";
                    }
                }
            }
        }
    }
    EXPECT_GT(samples, 10000u);
    EXPECT_GT(misses, 0u) << pairs << " pairs";
}

// The hulls and the zones' depth ranges are made in loops that grow with the scene (balls:5:
// about a tenth of a second each): both stop at a cancellation, as the rest of the build does.
TEST(PrimitiveHulls, MakingAndNarrowingStopWhenTheBuildIsCancelled) {
    Scene s = loadScene(std::string(LANCER_SOURCE_DIR) + "/assets/spd/gears1.nff");
    const CameraFrame frame = CameraFrame::of(s.camera);
    const std::vector<uint32_t> live = s.livePrimitives();
    const double pad = 1e-9 * s.scale();
    const PrimitiveHulls hulls = PrimitiveHulls::make(s, frame, FrameChoice{}, live, pad);
    std::vector<Box3> box(s.prims.size());
    for (uint32_t p : live) box[p] = frame.box(s.minBox[p]);
    const Box3 cam = frame.box(s.bounds);
    ScreenBsp bsp = ScreenBsp::build(box, live, {cam.lo.x, cam.lo.y}, {cam.hi.x, cam.hi.y}, {});
    std::stop_source stop;
    BuildGuard running(0, {stop.get_token(), {}});
    EXPECT_NO_THROW(PrimitiveHulls::make(s, frame, FrameChoice{}, live, pad, &running));
    ScreenBsp copy = bsp;
    EXPECT_NO_THROW(
        narrowZones(copy, hulls, ZoneColumn::Parallel, box, cam.lo.z, cam.hi.z, pad, &running));
    stop.request_stop();
    EXPECT_THROW(PrimitiveHulls::make(s, frame, FrameChoice{}, live, pad, &running),
                 BuildCancelled);
    EXPECT_THROW(
        narrowZones(bsp, hulls, ZoneColumn::Parallel, box, cam.lo.z, cam.hi.z, pad, &running),
        BuildCancelled);
}

// The hulls of an unturned scene (SPD's gears1: polygons on and off the world's axes, seen
// from a camera off them): points of each polygon (convex combinations of its vertices, inside
// its own plane's box and its world box) lie in the depth range its hull gives any zone whose
// column holds them, and the ranges over a small zone are mostly tighter than the box's.
TEST(PrimitiveHulls, FlatAndWorldBoxesHoldThePolygonsPoints) {
    Scene s = loadScene(std::string(LANCER_SOURCE_DIR) + "/assets/spd/gears1.nff");
    const FrameChoice turned = chooseGridFrame(s);
    ASSERT_FALSE(turned.frame.turned);
    const CameraFrame frame = CameraFrame::of(s.camera);
    const std::vector<uint32_t> live = s.livePrimitives();
    const PrimitiveHulls hulls = PrimitiveHulls::make(s, frame, turned, live, 1e-9 * s.scale());
    ASSERT_FALSE(hulls.empty());
    std::mt19937_64 rng(5);
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    size_t polygons = 0, pairs = 0, tighter = 0, samples = 0;
    for (uint32_t p : live) {
        const Polygon* g = std::get_if<Polygon>(&s.prims[p].shape);
        if (!g || polygons >= 60) continue;
        ++polygons;
        const Box3 cam = frame.box(s.minBox[p]);
        const glm::dvec2 whole(cam.lo.z, cam.hi.z);
        for (int k = 0; k < 40; ++k) {
            // A point of the polygon's vertices' hull, and a zone a tenth of its rectangle
            // across around it.
            Vec3 w(0.0);
            double sum = 0.0;
            for (const Vec3& v : g->p) {
                const double a = u01(rng);
                w += a * (s.prims[p].hasXf ? s.prims[p].xf.point(v) : v);
                sum += a;
            }
            const Vec3 c = frame.point(w / sum);
            const glm::dvec2 e = 0.1 * glm::dvec2(cam.hi.x - cam.lo.x, cam.hi.y - cam.lo.y);
            const glm::dvec2 lo(c.x - u01(rng) * e.x, c.y - u01(rng) * e.y);
            const glm::dvec2 d = hulls.depthIn(p, ZoneColumn::Parallel, lo, lo + e, 0.0, whole);
            ASSERT_TRUE(hulls.touches(p, ZoneColumn::Parallel, lo, lo + e)) << "p" << p;
            EXPECT_GE(c.z, d.x - 1e-9 * s.scale()) << "p" << p;
            EXPECT_LE(c.z, d.y + 1e-9 * s.scale()) << "p" << p;
            ++samples;
            ++pairs;
            tighter += d.y - d.x < 0.6 * (whole.y - whole.x);
        }
    }
    EXPECT_GE(polygons, 20u);
    EXPECT_GT(samples, 800u);
    EXPECT_GT(tighter, pairs / 4) << tighter << " of " << pairs;
}

/// A box of the camera frame along the world-frame axes `axes`, as PrimitiveHulls makes it:
/// corners and planes (axis . x between lo and hi).
struct KeptFacesBox {
    std::array<Vec3, 8> corner;
    std::array<Vec3, 3> axis;
    Vec3 lo, hi;
};

KeptFacesBox keptFacesBox(const CameraFrame& frame, const Box3& b, const Mat3& axes, double pad) {
    KeptFacesBox s;
    const Box3 w{b.lo - Vec3(pad), b.hi + Vec3(pad)};
    for (int a = 0; a < 3; ++a) {
        s.axis[size_t(a)] = frame.vector(axes[a]);
        const double o = glm::dot(axes[a], frame.origin);
        s.lo[a] = w.lo[a] - o;
        s.hi[a] = w.hi[a] - o;
    }
    for (int c = 0; c < 8; ++c) s.corner[size_t(c)] = frame.point(axes * boxCorner(w, c));
    return s;
}

/// The rectangle of the camera-frame box `cam` seen along `column` (false: from the eye, the
/// box is not wholly in front of it).
bool hullColumnRect(const Box3& cam, ZoneColumn column, glm::dvec2& lo, glm::dvec2& hi) {
    lo = {cam.lo.x, cam.lo.y};
    hi = {cam.hi.x, cam.hi.y};
    if (column == ZoneColumn::Parallel) return true;
    if (!(cam.lo.z > 0.0)) return false;
    const glm::dvec2 l = lo, h = hi;
    lo = glm::min(l / cam.lo.z, l / cam.hi.z);
    hi = glm::max(h / cam.lo.z, h / cam.hi.z);
    return true;
}

/// The part of `in` where n . x <= d, one Sutherland-Hodgman pass.
std::vector<Vec3> keptFacesClip(const std::vector<Vec3>& in, const Vec3& n, double d) {
    std::vector<Vec3> out;
    for (size_t i = 0; i < in.size(); ++i) {
        const Vec3& a = in[i];
        const Vec3& b = in[(i + 1) % in.size()];
        const double da = glm::dot(n, a) - d, db = glm::dot(n, b) - d;
        if (da <= 0.0) out.push_back(a);
        if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
            const double s = da / (da - db);
            out.push_back(a + s * (b - a));
        }
    }
    return out;
}

/// The depth range of the world box and the turned box (null: the world box alone) within the
/// column over [lo, hi], computed the plain way: each face of each box clipped by the other box,
/// then by every column plane that cuts a corner off either box, pass after pass.
glm::dvec2 keptFacesRange(const KeptFacesBox& world, const KeptFacesBox* turned, ZoneColumn column,
                          glm::dvec2 lo, glm::dvec2 hi, double zNear, glm::dvec2 whole) {
    std::vector<Vec3> cn;
    std::vector<double> cd;
    if (column == ZoneColumn::Parallel) {
        cn = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 1, 0)};
        cd = {-lo.x, hi.x, -lo.y, hi.y};
    } else {
        cn = {Vec3(-1, 0, lo.x), Vec3(1, 0, -hi.x), Vec3(0, -1, lo.y), Vec3(0, 1, -hi.y),
              Vec3(0, 0, -1)};
        cd = {0.0, 0.0, 0.0, 0.0, -zNear};
    }
    const KeptFacesBox* boxes[2] = {&world, turned};
    const int n = turned ? 2 : 1;
    std::vector<bool> cuts(cn.size(), false);
    for (size_t k = 0; k < cn.size(); ++k) {
        for (int s = 0; s < n; ++s) {
            int beyond = 0;
            for (const Vec3& c : boxes[s]->corner) beyond += glm::dot(cn[k], c) > cd[k];
            if (beyond == 8) return {whole.x, -kInf};
            cuts[k] = cuts[k] || beyond > 0;
        }
    }
    glm::dvec2 range(kInf, -kInf);
    for (int s = 0; s < n; ++s) {
        const KeptFacesBox& me = *boxes[s];
        for (int axis = 0; axis < 3; ++axis) {
            const int u = 1 << ((axis + 1) % 3), v = 1 << ((axis + 2) % 3);
            for (int side = 0; side < 2; ++side) {
                const int base = side << axis;
                std::vector<Vec3> f = {me.corner[size_t(base)], me.corner[size_t(base | u)],
                                       me.corner[size_t(base | u | v)],
                                       me.corner[size_t(base | v)]};
                if (turned) {
                    const KeptFacesBox& other = *boxes[1 - s];
                    for (size_t k = 0; k < 3 && !f.empty(); ++k) {
                        f = keptFacesClip(f, other.axis[k], other.hi[int(k)]);
                        if (f.empty()) break;
                        f = keptFacesClip(f, -other.axis[k], -other.lo[int(k)]);
                    }
                }
                for (size_t k = 0; k < cn.size() && !f.empty(); ++k)
                    if (cuts[k]) f = keptFacesClip(f, cn[k], cd[k]);
                for (const Vec3& q : f) {
                    range.x = std::min(range.x, q.z);
                    range.y = std::max(range.y, q.z);
                }
            }
        }
    }
    if (column == ZoneColumn::FromEye && range.x <= range.y)
        for (int s = 0; s < n; ++s)
            for (const Vec3& c : boxes[s]->corner)
                if (c.z < zNear) range.x = zNear;
    return {std::max(range.x, whole.x), std::min(range.y, whole.y)};
}

// depthIn keeps each face of a hull's two boxes clipped by the other box (they do not depend on
// the zone), clips only by the column planes at each zone, takes the corners' distances to
// those planes from its pre-check and skips a plane that a polygon lies wholly on one side of:
// the ranges are those of the plain clipping, bit for bit (the slabs cut at them), on turned
// bars cut by a CSG's minimized boxes (two boxes each) and gears1's polygons (a box along each
// one's plane off the world's axes), with all, some or none of the faces kept. A world box
// alone (balls seen from a turned camera) has its vertices found without clipping
// (singleBoxDepth): the same ranges to a trillionth of their depths (an ulp or so, measured),
// missing where clipping misses. A box of its own within the world box (a bar that nothing
// cuts) is the hull alone: its ranges hold the two boxes' and are at most the padding wider.
TEST(PrimitiveHulls, KeptFacesGiveThePlainClippingsRangesBitForBit) {
    size_t compared = 0, twoBoxes = 0, cut = 0, single = 0, paired = 0, alone = 0;
    double worst = 0.0;
    auto compare = [&](const Scene& s, bool reference) {
        const FrameChoice turned = chooseGridFrame(s);
        const CameraFrame frame = CameraFrame::of(s.camera);
        const std::vector<uint32_t> live = s.livePrimitives();
        const double pad = 1e-9 * s.scale();
        const PrimitiveHulls hulls = PrimitiveHulls::make(s, frame, turned, live, pad);
        const PrimitiveHulls none = PrimitiveHulls::make(s, frame, turned, live, pad, nullptr, 0);
        EXPECT_EQ(none.keptFaces(), 0u);
        EXPECT_EQ(none.faceBytes(), 0u);
        // At the bytes that all the faces take, the doubling counted, about half are kept.
        const PrimitiveHulls some =
            PrimitiveHulls::make(s, frame, turned, live, pad, nullptr, hulls.faceBytes());
        EXPECT_LE(2 * some.faceBytes(), hulls.faceBytes());
        if (hulls.keptFaces() > 1) {
            EXPECT_GT(some.keptFaces(), 0u);
            EXPECT_LT(some.keptFaces(), hulls.keptFaces());
        }
        twoBoxes += hulls.keptFaces();
        std::mt19937_64 rng(live.size());
        std::uniform_real_distribution<double> u01(0.0, 1.0);
        const double zNear = 1e-3 * s.scale();
        for (uint32_t p : live) {
            const Box3 cam = frame.box(s.minBox[p]);
            const glm::dvec2 whole(cam.lo.z, cam.hi.z);
            const KeptFacesBox world = keptFacesBox(frame, s.minBox[p], Mat3(1.0), pad);
            std::optional<KeptFacesBox> own;
            if (turned.frame.turned && !turned.boxes[p].isEmpty())
                own = keptFacesBox(frame, turned.boxes[p], turned.frame.axes, pad);
            bool ownWithin = own.has_value();
            for (size_t c = 0; c < 8 && ownWithin; ++c)
                for (size_t a = 0; a < 3 && ownWithin; ++a) {
                    const double x = glm::dot(world.axis[a], own->corner[c]);
                    ownWithin =
                        x >= world.lo[int(a)] - 2.0 * pad && x <= world.hi[int(a)] + 2.0 * pad;
                }
            for (ZoneColumn column : {ZoneColumn::Parallel, ZoneColumn::FromEye}) {
                glm::dvec2 lo, hi;
                if (!hullColumnRect(cam, column, lo, hi)) continue;
                // Zones from a twentieth to the whole of the rectangle across, most cutting it.
                for (int k = 0; k < 12; ++k) {
                    const glm::dvec2 e = (0.05 + 0.95 * u01(rng)) * (hi - lo);
                    const glm::dvec2 zlo =
                        lo - 0.5 * e + glm::dvec2(u01(rng), u01(rng)) * (hi - lo);
                    const glm::dvec2 d = hulls.depthIn(p, column, zlo, zlo + e, zNear, whole);
                    const glm::dvec2 o = none.depthIn(p, column, zlo, zlo + e, zNear, whole);
                    const glm::dvec2 h = some.depthIn(p, column, zlo, zlo + e, zNear, whole);
                    EXPECT_EQ(d.x, o.x) << "p" << p;
                    EXPECT_EQ(d.y, o.y) << "p" << p;
                    EXPECT_EQ(d.x, h.x) << "p" << p;
                    EXPECT_EQ(d.y, h.y) << "p" << p;
                    if (reference) {
                        const glm::dvec2 r = keptFacesRange(world, own ? &*own : nullptr, column,
                                                            zlo, zlo + e, zNear, whole);
                        const double ulps = 1e-12 * (std::abs(whole.x) + std::abs(whole.y));
                        if (own && !ownWithin) {
                            EXPECT_EQ(d.x, r.x) << "p" << p;
                            EXPECT_EQ(d.y, r.y) << "p" << p;
                            ++paired;
                        } else if (!own) {
                            // The world box alone: its vertices found directly, not by clipping.
                            EXPECT_EQ(d.x <= d.y, r.x <= r.y) << "p" << p;
                            if (d.x <= d.y && r.x <= r.y) {
                                EXPECT_NEAR(d.x, r.x, ulps) << "p" << p;
                                EXPECT_NEAR(d.y, r.y, ulps) << "p" << p;
                                worst = std::max({worst, std::abs(d.x - r.x) / ulps,
                                                  std::abs(d.y - r.y) / ulps});
                            }
                            ++single;
                        } else {
                            // A box of its own within the world box (up to the padding) is the
                            // hull alone: it holds the two boxes' common part, wider by at most
                            // the padding.
                            const double wider = 4.0 * pad + ulps;
                            if (!(d.x <= d.y)) {
                                EXPECT_FALSE(r.x <= r.y) << "p" << p;
                            }
                            if (r.x <= r.y) {
                                EXPECT_LE(d.x, r.x + ulps) << "p" << p;
                                EXPECT_GE(d.y, r.y - ulps) << "p" << p;
                            }
                            if (d.x <= d.y && r.x <= r.y) {
                                EXPECT_GE(d.x, r.x - wider) << "p" << p;
                                EXPECT_LE(d.y, r.y + wider) << "p" << p;
                            }
                            ++alone;
                        }
                    }
                    ++compared;
                    cut += d.x <= d.y && (d.x > whole.x || d.y < whole.y);
                }
            }
        }
    };
    for (uint64_t seed = 1; seed <= 3; ++seed) compare(test::turnedBars(seed * 29 + 1, 16), true);
    compare(loadScene("builtin:balls:2"), true);
    compare(loadScene("builtin:sponge:1"), true);
    compare(loadScene(std::string(LANCER_SOURCE_DIR) + "/assets/spd/gears1.nff"), false);
    EXPECT_GT(twoBoxes, 10u) << twoBoxes;
    EXPECT_GT(paired, 200u) << paired;
    EXPECT_GT(alone, 60u) << alone;
    EXPECT_GT(compared, 5000u);
    EXPECT_GT(cut, compared / 4) << cut << " of " << compared;
    EXPECT_GT(single, 1000u);
    EXPECT_LT(worst, 1.0);
}

// depthIn writes the column planes' distances to the boxes' corners out (lo.x - x, x - hi.x ..,
// or from the eye lo.x z - x ..) instead of glm::dot's products by 0 and 1: the ranges are
// glm::dot's bit for bit (withDotPlanes), sign of zero included. Checked on hulls of every kind
// (turned bars of two boxes, balls seen turned, sponge:1's cubes, gears1's polygons off the
// world's axes, balls under a light's frame along the world's axes, whose closed form is left
// to depthIn's planes behind the eye) in both columns, over zones across the primitive's
// rectangle, grazing it (a side at its rectangle's side, a few ulps and a millionth off), of
// no width, and zNear in front of, at and behind the eye.
TEST(PrimitiveHulls, WrittenOutPlaneDistancesGiveGlmDotsRangesBitForBit) {
    size_t compared = 0, grazing = 0, cutRanges = 0, misses = 0, flat = 0;
    auto bits = [](double v) { return std::bit_cast<uint64_t>(v); };
    auto check = [&](const Scene& s, const CameraFrame& frame, const FrameChoice& turned) {
        const std::vector<uint32_t> live = s.livePrimitives();
        const double pad = 1e-9 * s.scale();
        const PrimitiveHulls hulls = PrimitiveHulls::make(s, frame, turned, live, pad);
        const PrimitiveHulls dot = hulls.withDotPlanes();
        std::mt19937_64 rng(live.size() * 7 + 1);
        std::uniform_real_distribution<double> u01(0.0, 1.0);
        for (uint32_t p : live) {
            const Box3 cam = frame.box(s.minBox[p]);
            const glm::dvec2 whole(cam.lo.z, cam.hi.z);
            for (ZoneColumn column : {ZoneColumn::Parallel, ZoneColumn::FromEye}) {
                glm::dvec2 lo, hi;
                if (!hullColumnRect(cam, column, lo, hi)) continue;
                const glm::dvec2 ext = hi - lo;
                for (int k = 0; k < 40; ++k) {
                    // A zone from nothing to twice the rectangle across.
                    glm::dvec2 e = 2.0 * u01(rng) * ext;
                    if (k % 8 == 7) e[k % 2] = 0.0;
                    glm::dvec2 zlo = lo - 0.5 * e + glm::dvec2(u01(rng), u01(rng)) * ext;
                    glm::dvec2 zhi = zlo + e;
                    // Or one side grazing the rectangle's (its corners' extreme).
                    const int how = int(rng() % 4);
                    if (how > 0) {
                        const int axis = int(rng() % 2);
                        const bool high = rng() % 2;
                        double c = rng() % 2 ? lo[axis] : hi[axis];
                        if (how == 2)
                            for (int i = int(rng() % 4); i > 0; --i)
                                c = std::nextafter(c, rng() % 2 ? kInf : -kInf);
                        if (how == 3) c += (rng() % 2 ? 1e-6 : -1e-6) * ext[axis];
                        (high ? zhi : zlo)[axis] = c;
                        if (!(zlo[axis] <= zhi[axis])) std::swap(zlo[axis], zhi[axis]);
                        ++grazing;
                    }
                    const double zNears[4] = {0.5 * cam.lo.z, cam.lo.z, 0.0, -0.5 * s.scale()};
                    const double zNear = zNears[k % 4];
                    const glm::dvec2 a = hulls.depthIn(p, column, zlo, zhi, zNear, whole);
                    const glm::dvec2 b = dot.depthIn(p, column, zlo, zhi, zNear, whole);
                    EXPECT_EQ(bits(a.x), bits(b.x)) << "p" << p << " " << a.x << " " << b.x;
                    EXPECT_EQ(bits(a.y), bits(b.y)) << "p" << p << " " << a.y << " " << b.y;
                    ++compared;
                    misses += !(a.x <= a.y);
                    flat += zlo.x == zhi.x || zlo.y == zhi.y;
                    cutRanges += a.x <= a.y && (a.x > whole.x || a.y < whole.y);
                }
            }
        }
    };
    auto eye = [&](const Scene& s) { check(s, CameraFrame::of(s.camera), chooseGridFrame(s)); };
    for (uint64_t seed = 1; seed <= 3; ++seed) eye(test::turnedBars(seed * 31 + 5, 16));
    eye(loadScene("builtin:balls:2"));
    eye(loadScene("builtin:sponge:1"));
    eye(loadScene(std::string(LANCER_SOURCE_DIR) + "/assets/spd/gears1.nff"));
    {
        const Scene s = loadScene("builtin:balls:2");
        CameraFrame f;
        f.origin = s.bounds.center();
        f.origin.z = s.bounds.hi.z + 0.7 * s.bounds.extent().z;
        f.z = Vec3(0, 0, -1), f.x = Vec3(1, 0, 0), f.y = Vec3(0, 1, 0);
        check(s, f, FrameChoice{});
    }
    // Enough ranges cut by the zones, missing them, grazing and flat, for the check to mean
    // something.
    EXPECT_GT(compared, 20000u) << compared;
    EXPECT_GT(cutRanges, compared / 4) << cutRanges << " of " << compared;
    EXPECT_GT(misses, compared / 20) << misses << " of " << compared;
    EXPECT_GT(grazing, compared / 2) << grazing << " of " << compared;
    EXPECT_GT(flat, compared / 20) << flat << " of " << compared;
}

TEST(Irregular, SparseRestrictionEqualsRestrictTree) {
    std::mt19937_64 rng(17);
    for (uint64_t seed = 50; seed < 70; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 20;
        opt.surfaces = seed % 2 == 0;
        Scene scene = test::randomCsgScene(seed, opt);
        TreeRestrictor restrictor(scene.tree);
        for (int k = 0; k < 20; ++k) {
            std::vector<char> keep(scene.prims.size(), 0);
            std::vector<uint32_t> prims;
            for (uint32_t p = 0; p < scene.prims.size(); ++p)
                if (rng() % 3 == 0) {
                    keep[p] = 1;
                    prims.push_back(p);
                }
            CsgTree a, b;
            a.root = restrictTree(scene.tree, scene.tree.root, keep, a);
            b.root = restrictor.restrict(prims, b);
            EXPECT_EQ(a.toString(), b.toString()) << "seed " << seed;
            EXPECT_EQ(a.nodes.size(), b.nodes.size());
        }
    }
}

TEST(Irregular, RefusesBadParameters) {
    Scene scene = loadScene("builtin:default");
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    p.irregular.maxObjects = -2;  // -1 is kAutoObjects
    try {
        buildAccelerator(scene, p);
        ADD_FAILURE() << "negative --max-objects accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("--max-objects"), std::string::npos) << e.what();
    }
    p.irregular.maxObjects = 0;
    scene.camera.at = scene.camera.from;  // no viewing direction
    EXPECT_THROW(buildAccelerator(scene, p), std::invalid_argument);
}

TEST(IrregularKnobs, ExplicitMaxObjectsBuildsByTheReportsRule) {
    // balls:2 with the cost stop leaves the same zones at max-objects 1, 2 and 4; an explicit
    // max-objects turns it off (docs/irregular.md, "Explicit max-objects"), and each zone is
    // counted by the reason its cell was not split.
    Scene scene = loadScene("builtin:balls:2");
    scene.width = 64;
    scene.height = 64;
    BuildParams p;
    p.scheme = SchemeKind::Irregular;
    auto zonesOf = [&](int maxObjects) {
        p.irregular.maxObjects = maxObjects;
        auto a = buildAccelerator(scene, p);
        const nlohmann::json& x = a->info().extra;
        const nlohmann::json& r = x["stop_reasons"];
        size_t sum = 0;
        for (const char* k : {"max_objects", "max_level", "cost", "memory"}) sum += size_t(r[k]);
        EXPECT_EQ(sum, size_t(x["zones"])) << maxObjects;
        EXPECT_EQ(size_t(r["max_level"]), 0u);
        EXPECT_LE(size_t(x["covered_zones"]), size_t(r["cost"]));
        EXPECT_EQ(x["cost_stop"], maxObjects == kAutoObjects);
        return size_t(x["zones"]);
    };
    const size_t automatic = zonesOf(kAutoObjects), one = zonesOf(1), two = zonesOf(2),
                 sixteen = zonesOf(16);
    EXPECT_GT(one, automatic);
    EXPECT_GE(one, two);
    EXPECT_GT(two, sixteen);
    EXPECT_NE(one, two);
}

// The zone hint of a projective walk (ProjectiveZones::locate: the zone its last walk located,
// checked by its rectangle) finds the zone the screen BSP finds, whatever zone the hint holds:
// for random points, and for the corners and edge midpoints of every zone, which lie on the
// BSP's lines, where a point belongs to the zone below the line.
TEST(Irregular, ProjectiveZoneHintLocatesAsTheScreenBsp) {
    Scene scene = loadScene("builtin:drilled:6");
    auto accel = buildIrregular(scene, BspHeuristic::Balanced, kAutoObjects);
    const IrregularSubdivision& s = irregularOf(*accel);
    std::vector<const ProjectiveZones*> structures{&s.projective()};
    for (const ProjectiveZones& lz : s.lights())
        if (lz.zoneCount() > 0) structures.push_back(&lz);
    ASSERT_GT(structures.size(), 1u);
    std::mt19937_64 rng(29);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    size_t checked = 0;
    for (const ProjectiveZones* pz : structures) {
        const ScreenBsp& bsp = pz->screen();
        ASSERT_GT(bsp.zoneCount(), 100u);
        const glm::dvec2 lo = pz->rectLo(), hi = pz->rectHi();
        std::vector<glm::dvec2> pts;
        std::uniform_real_distribution<double> ux(lo.x, hi.x), uy(lo.y, hi.y);
        for (int i = 0; i < 2000; ++i) pts.push_back({ux(rng), uy(rng)});
        for (size_t z = 0; z < bsp.zoneCount(); ++z) {
            const glm::dvec2 a = bsp.zoneLo[z], b = bsp.zoneHi[z];
            for (glm::dvec2 p :
                 {a, b, glm::dvec2(a.x, b.y), glm::dvec2(b.x, a.y), 0.5 * (a + b),
                  glm::dvec2(a.x, 0.5 * (a.y + b.y)), glm::dvec2(0.5 * (a.x + b.x), b.y)})
                pts.push_back(p);
        }
        std::uniform_int_distribution<uint32_t> anyZone(0, uint32_t(bsp.zoneCount()) + 5);
        for (size_t i = 0; i < pts.size(); ++i) {
            const glm::dvec2 p = pts[i];
            const uint32_t want = bsp.locate(p.x, p.y, 0, 0);
            // The hint as the walk leaves it (the previous point's zone), the zone itself, a
            // random zone (some beyond the count).
            for (int k = 0; k < 3; ++k) {
                for (uint32_t& h : ctx.zoneHint) {
                    if (k == 1) h = want;
                    if (k == 2) h = anyZone(rng);
                }
                ASSERT_EQ(pz->locate(p.x, p.y, ctx), want)
                    << "point (" << p.x << ", " << p.y << "), hint " << k;
                ++checked;
            }
        }
    }
    std::printf("%zu locations checked\n", checked);
}

// A ray from the eye whose (u, v) lies outside the zones' rectangle (the union of the projected
// boxes of every primitive beyond zNear) can meet only the near region's primitives: the
// projective walk answers it there, in no region at all when the near region is empty, instead
// of handing it to the camera-frame walk (whose regions it used to cross: two thirds of the
// turned sponge's primary rays at 128x128). Its hit is brute force's, and inside the rectangle
// nothing changes.
TEST(Irregular, EyeRaysOutsideEveryProjectedBoxVisitOnlyTheNearRegion) {
    // The bracket with a ball behind the eye, which puts a primitive in the near region.
    const std::string bracket = R"({
      "camera": {"from": [70, -50, 60], "at": [20, 10, 5], "up": [0, 0, 1], "fov": 35},
      "scene": {"union": [
        {"difference": [
          {"box": {"min": [0, 0, 0], "max": [40, 20, 10]}},
          {"cylinder": {"radius": 4, "height": 12}, "transform": [{"translate": [10, 10, -1]}]}
        ]},
        {"sphere": {"radius": 2}, "transform": [{"translate": [95, -80, 87.5]}]}
      ]}})";
    std::vector<std::pair<std::string, Scene>> scenes;
    scenes.emplace_back("builtin:sponge:3", loadScene("builtin:sponge:3"));
    scenes.emplace_back("bracket", readJsonScene(SourceText("bracket.json", bracket)));
    for (const auto& [name, scene] : scenes) {
        auto accel = buildIrregular(scene);
        const IrregularSubdivision& s = irregularOf(*accel);
        const ProjectiveZones& pz = s.projective();
        ASSERT_GT(pz.zoneCount(), 0u) << name;
        EXPECT_EQ(pz.hasNearRegion(), name == "bracket");
        const std::vector<Ray> rays = test::pixelRays(scene, 48, 48);
        expectSame(scene, *accel, rays, name.c_str());
        TraceContext ctx(scene.prims.size(), scene.tree.depth());
        ctx.useMailboxes = accel->usesMailboxes();
        const uint32_t nearId = uint32_t(s.regions().size()) + uint32_t(pz.zoneFirst().back());
        size_t outside = 0, inside = 0, nearVisits = 0;
        for (const Ray& ray : rays) {
            const Ray rc = pz.frame().ray(ray);
            double u, v;
            ASSERT_TRUE(pz.covers(ray, rc, u, v)) << name << ": every pixel's ray is answered";
            const RecordingObserver obs = test::recordWalk(*accel, ray, ctx);
            if (pz.inZones(u, v)) {
                ++inside;
                continue;
            }
            ++outside;
            for (const WalkEvent& e : obs.events) {
                if (e.kind() != WalkEvent::Region) continue;
                ASSERT_TRUE(pz.hasNearRegion()) << name << ": a region visited, none to visit";
                EXPECT_EQ(std::get<walk::Region>(e.data).region, nearId) << name;
                ++nearVisits;
            }
        }
        EXPECT_GT(outside, rays.size() / 10) << name;
        EXPECT_GT(inside, rays.size() / 10) << name;
        EXPECT_EQ(nearVisits, pz.hasNearRegion() ? outside : 0u) << name;
    }
}

// The walk model (ZoneWalkModel) splits a cell only where the rays through it go on past what
// it lists: 256 small squares behind an opaque square that covers the whole screen stay in the
// 16 zones the first levels always make (every ray ends on the front square), the same squares
// in front of it are split into a zone each. The count model (stepCost) is left out of it.
TEST(Irregular, WalkModelSplitsOnlyWhereRaysGoOn) {
    auto build = [](double frontDepth) {
        std::vector<Box3> rect;
        std::vector<uint32_t> prims;
        rect.push_back({{0.0, 0.0, frontDepth}, {1.0, 1.0, frontDepth + 1.0}});
        prims.push_back(0);
        for (int i = 0; i < 16; ++i)
            for (int j = 0; j < 16; ++j) {
                const double x = (i + 0.25) / 16.0, y = (j + 0.25) / 16.0;
                rect.push_back({{x, y, 5.0}, {x + 0.5 / 16.0, y + 0.5 / 16.0, 6.0}});
                prims.push_back(uint32_t(prims.size()));
            }
        const std::vector<float> stops(rect.size(), 1.0f);
        // In units of a slab visit: a test as much, a level a twentieth, the build as the
        // build's own model charges it (walkModel(), irregular.cpp), 1e5 rays over the screen.
        const ZoneWalkModel m{.visit = 1.0,
                              .test = 1.0,
                              .level = 0.05,
                              .fill = 0.5,
                              .raysPerArea = 1e5,
                              .rays = 0.0,
                              .zone = 2.0,
                              .ref = 4.0};
        ScreenBspParams p;
        p.heuristic = BspHeuristic::Balanced;
        p.stopObjects = 1;
        p.stepCost = 1e9;  // the count model never pays
        p.walk = &m;
        p.stops = &stops;
        return ScreenBsp::build(rect, prims, {0.0, 0.0}, {1.0, 1.0}, p);
    };
    const ScreenBsp hidden = build(1.0), seen = build(10.0);
    std::printf("squares hidden: %zu zones; in front: %zu zones\n", hidden.zoneCount(),
                seen.zoneCount());
    EXPECT_LE(hidden.zoneCount(), 16u);
    EXPECT_GT(hidden.costStops, 0u);
    EXPECT_GE(seen.zoneCount(), 256u);
}

}  // namespace
}  // namespace lancer
