// The structure description (engine/accel/structure_view.h) and its dump, on random scenes, for
// every scheme and both cameras: zones tile the screen rectangle, leaves tile the bounds, every
// region lists the primitives whose boxes cross it, every region's corners hold the stretch of
// ray the walk reports in it, and the dump round-trips the description.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "engine/accel/regular/grid_frame.h"
#include "engine/accel/structure_dump.h"
#include "engine/accel/structure_view.h"
#include "engine/model/restriction.h"
#include "tests/support/differential.h"
#include "tests/support/hexahedron.h"

namespace lancer {
namespace {

constexpr int kW = 40, kH = 30;  // the image the pixel units refer to

/// One configuration: a random scene seen by one camera, built by one scheme.
struct Case {
    uint64_t seed;
    SchemeKind scheme;
    bool ortho;
    IrregularFrame frame = IrregularFrame::Projective;
    std::string name() const {
        return std::string(schemeName(scheme)) + (ortho ? " ortho" : " persp") +
               (scheme == SchemeKind::Irregular ? std::string(" ") + irregularFrameName(frame)
                                                : "") +
               " seed " + std::to_string(seed);
    }
};

/// Five seeds of random scenes with a few live primitives (some random trees drop everything).
std::vector<uint64_t> seeds() {
    std::vector<uint64_t> out;
    test::RandomSceneOptions ro;
    ro.primitives = 24;
    for (uint64_t seed = 11; out.size() < 5; ++seed) {
        Scene s = test::randomCsgScene(seed, ro);
        if (!s.bounds.isEmpty() && s.livePrimitives().size() >= 4) out.push_back(seed);
    }
    return out;
}

std::vector<Case> cases() {
    std::vector<Case> out;
    for (uint64_t seed : seeds())
        for (bool ortho : {false, true}) {
            out.push_back({seed, SchemeKind::Brute, ortho});
            out.push_back({seed, SchemeKind::Regular, ortho});
            out.push_back({seed, SchemeKind::Irregular, ortho, IrregularFrame::Camera});
            out.push_back({seed, SchemeKind::Irregular, ortho, IrregularFrame::Projective});
        }
    return out;
}

struct Built {
    Scene scene;
    std::unique_ptr<Accelerator> accel;
};

Built build(const Case& c) {
    Built b;
    test::RandomSceneOptions ro;
    ro.primitives = 24;
    b.scene = test::randomCsgScene(c.seed, ro);
    b.scene.width = kW;
    b.scene.height = kH;
    if (c.ortho) test::makeOrthographic(b.scene);
    BuildParams p;
    p.scheme = c.scheme;
    p.regular.maxLevel = 12;  // 4096 directory cells at most: every cell can be checked
    p.regular.maxObjects = 2;
    p.irregular.maxObjects = 0;
    p.irregular.frame = c.frame;
    b.accel = buildAccelerator(b.scene, p);
    return b;
}

double polygonArea(const std::vector<glm::dvec2>& p) {
    double a = 0.0;
    for (size_t i = 0; i < p.size(); ++i) {
        const glm::dvec2 &u = p[i], &v = p[(i + 1) % p.size()];
        a += u.x * v.y - v.x * u.y;
    }
    return 0.5 * std::abs(a);
}

/// p inside the convex polygon (axis-aligned rectangles here), half-open on the high sides.
bool inRect(const std::vector<glm::dvec2>& poly, glm::dvec2 p) {
    glm::dvec2 lo(kInf), hi(-kInf);
    for (const glm::dvec2& q : poly) {
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    return p.x >= lo.x && p.x < hi.x && p.y >= lo.y && p.y < hi.y;
}

/// Open overlap of two boxes shrunk by `margin`: they share volume beyond rounding.
bool crosses(const Box3& a, const Box3& b, double margin) {
    for (int k = 0; k < 3; ++k)
        if (!(a.lo[k] + margin < b.hi[k] && b.lo[k] + margin < a.hi[k])) return false;
    return true;
}

bool lists(std::span<const uint32_t> prims, uint32_t p) {
    return std::find(prims.begin(), prims.end(), p) != prims.end();
}

TEST(StructureView, RegionCountAndIdsMatchTheWalk) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name());
        Built b = build(c);
        StructureView v(b.scene, *b.accel);
        EXPECT_EQ(v.regionCount(), b.accel->info().regions);
        for (uint32_t id = 0; id < v.regionCount(); ++id) {
            RegionInfo r = v.region(id);
            EXPECT_EQ(r.id, id);
            std::string s = v.toString(id);
            EXPECT_NE(s.find(std::to_string(id)), std::string::npos) << s;
            EXPECT_EQ(s.find('\n'), std::string::npos) << "one line: " << s;
        }
    }
}

TEST(StructureView, ZonesTileTheScreenRectangle) {
    for (const Case& c : cases()) {
        if (c.scheme != SchemeKind::Irregular) continue;
        SCOPED_TRACE(c.name());
        Built b = build(c);
        StructureView v(b.scene, *b.accel);
        ASSERT_NE(v.frame(ZoneFrameKind::Camera), nullptr);
        EXPECT_EQ(v.frame(ZoneFrameKind::Projective) != nullptr,
                  c.frame == IrregularFrame::Projective && !c.ortho);
        for (const ZoneFrameView& f : v.frames()) {
            SCOPED_TRACE(f.kind() == ZoneFrameKind::Camera ? "camera frame" : "projective");
            EXPECT_EQ(f.units() == FrameUnits::Pixels,
                      c.ortho || f.kind() == ZoneFrameKind::Projective);
            // The rectangle the polygons must tile: the frame's, clipped to the image in pixels.
            glm::dvec2 lo = f.rectLo(), hi = f.rectHi();
            if (f.units() == FrameUnits::Pixels) {
                glm::dvec2 a = f.toPixel(lo, kW, kH), bb = f.toPixel(hi, kW, kH);
                lo = glm::max(glm::min(a, bb), glm::dvec2(0.0));
                hi = glm::min(glm::max(a, bb), glm::dvec2(kW, kH));
            }
            const double want = std::max(0.0, hi.x - lo.x) * std::max(0.0, hi.y - lo.y);
            double sum = 0.0;
            std::vector<std::vector<glm::dvec2>> polys(f.zoneCount());
            for (uint32_t z = 0; z < f.zoneCount(); ++z) {
                polys[z] = f.zonePolygon(z, kW, kH);
                sum += polygonArea(polys[z]);
            }
            EXPECT_NEAR(sum, want, 1e-9 * std::max(1.0, want));
            // No overlap: random points of the rectangle lie in exactly one polygon, the zone
            // zoneAt names.
            std::mt19937_64 rng(c.seed);
            std::uniform_real_distribution<double> u(0.0, 1.0);
            for (int k = 0; k < 400 && want > 0.0; ++k) {
                glm::dvec2 p(lo.x + u(rng) * (hi.x - lo.x), lo.y + u(rng) * (hi.y - lo.y));
                int owners = 0;
                int64_t owner = -1;
                for (uint32_t z = 0; z < polys.size(); ++z)
                    if (!polys[z].empty() && inRect(polys[z], p)) ++owners, owner = z;
                ASSERT_EQ(owners, 1) << "point " << p.x << ", " << p.y;
                glm::dvec2 q = f.units() == FrameUnits::Pixels ? f.fromPixel(p, kW, kH) : p;
                EXPECT_EQ(f.zoneAt(q), owner);
                if (f.units() == FrameUnits::Pixels) {
                    EXPECT_EQ(f.zoneAtPixel(p.x, p.y, kW, kH), owner);
                }
            }
            // A zone's column holds each of its slabs.
            for (uint32_t z = 0; z < f.zoneCount(); z += 7) {
                const std::array<Vec3, 8> col = f.zoneCorners(z);
                for (const SlabInfo& sl : f.slabs(z))
                    for (const Vec3& p : v.regionCorners(sl.region))
                        EXPECT_LE(test::outside(col, p), 1e-9 * b.scene.scale())
                            << v.toString(sl.region);
            }
            // Every cut lies inside the rectangle and on its own line.
            std::vector<BspCut> cuts = f.cuts();
            EXPECT_EQ(cuts.size(), f.bsp().nodes.size());
            for (size_t i = 0; i < cuts.size(); ++i) {
                EXPECT_EQ(cuts[i].node, i);
                EXPECT_EQ(cuts[i].a[cuts[i].axis], cuts[i].value);
                EXPECT_EQ(cuts[i].b[cuts[i].axis], cuts[i].value);
                EXPECT_LE(cuts[i].depth, f.bsp().depth);
            }
        }
    }
}

TEST(StructureView, ProjectiveZonesMapToThePixelsTheirRaysCross) {
    for (const Case& c : cases()) {
        if (c.scheme != SchemeKind::Irregular || c.ortho || c.frame != IrregularFrame::Projective)
            continue;
        SCOPED_TRACE(c.name());
        Built b = build(c);
        StructureView v(b.scene, *b.accel);
        const ZoneFrameView* f = v.frame(ZoneFrameKind::Projective);
        ASSERT_NE(f, nullptr);
        TraceContext ctx(b.scene.prims.size(), b.scene.tree.depth());
        // A pixel's primary ray walks only the slabs of the zone under the pixel's centre.
        for (int y = 0; y < kH; y += 3)
            for (int x = 0; x < kW; x += 3) {
                int64_t z = f->zoneAtPixel(x + 0.5, y + 0.5, kW, kH);
                RecordingObserver obs =
                    test::recordWalk(*b.accel, b.scene.camera.primaryRay(x, y, kW, kH), ctx);
                for (const WalkEvent& e : obs.events) {
                    const walk::Region* g = e.get<walk::Region>();
                    if (!g) continue;
                    RegionInfo r = v.region(g->region);
                    if (r.kind == RegionKind::ProjectiveSlab) {
                        EXPECT_EQ(r.zone, z) << "pixel " << x << ", " << y;
                    }
                }
            }
    }
}

TEST(StructureView, LeavesTileTheBounds) {
    for (const Case& c : cases()) {
        if (c.scheme != SchemeKind::Regular) continue;
        SCOPED_TRACE(c.name());
        Built b = build(c);
        StructureView v(b.scene, *b.accel);
        const RegularGrid& g = *v.regular();
        const uint32_t n[3] = {g.cells(0), g.cells(1), g.cells(2)};
        for (int a = 0; a < 3; ++a) EXPECT_EQ(1u << v.directoryLog2(a), n[a]);
        // Cell counts and world volumes add up; every directory cell belongs to one leaf,
        // the one whose cell range holds it.
        uint64_t cells = 0;
        double volume = 0.0;
        std::vector<uint32_t> owner(size_t(n[0]) * n[1] * n[2], UINT32_MAX);
        for (uint32_t id = 0; id < v.regionCount(); ++id) {
            RegionInfo r = v.region(id);
            uint64_t k = 1;
            for (int a = 0; a < 3; ++a) k *= r.cellHi[a] - r.cellLo[a];
            cells += k;
            Vec3 e = r.frameBox.extent();
            volume += e.x * e.y * e.z;
            for (uint32_t i = r.cellLo[0]; i < r.cellHi[0]; ++i)
                for (uint32_t j = r.cellLo[1]; j < r.cellHi[1]; ++j)
                    for (uint32_t k2 = r.cellLo[2]; k2 < r.cellHi[2]; ++k2) {
                        uint32_t& o = owner[(size_t(i) * n[1] + j) * n[2] + k2];
                        EXPECT_EQ(o, UINT32_MAX) << "cell owned twice";
                        o = id;
                        EXPECT_EQ(g.directory().lookup(i, j, k2), id);
                    }
            // The level: a leaf at level l spans 2^-l of the grid.
            EXPECT_EQ(double(k) * std::ldexp(1.0, r.level), double(owner.size()));
        }
        EXPECT_EQ(cells, owner.size());
        Vec3 e = g.box().extent();
        EXPECT_NEAR(volume, e.x * e.y * e.z, 1e-9 * e.x * e.y * e.z);
        // The cut planes: one per inner node, inside their cells, levels non-decreasing.
        std::vector<CutPlane> cuts = v.cutPlanes();
        EXPECT_EQ(cuts.size() + 1, v.regionCount());
        for (size_t i = 0; i < cuts.size(); ++i) {
            const CutPlane& p = cuts[i];
            EXPECT_GT(p.value, p.cell.lo[p.axis]);
            EXPECT_LT(p.value, p.cell.hi[p.axis]);
            EXPECT_EQ(p.axis, g.schedule().axis(p.level));
            if (i) {
                EXPECT_GE(p.level, cuts[i - 1].level);
            }
        }
        // The directory's blocks: its entries cover every cell once, each inside its leaf.
        uint64_t covered = 0;
        for (const DirectoryBlock& d : v.directoryBlocks()) {
            if (d.subTable) continue;
            RegionInfo r = v.region(d.leaf);
            uint64_t k = 1;
            for (int a = 0; a < 3; ++a) {
                k *= d.hi[a] - d.lo[a];
                EXPECT_GE(d.lo[a], r.cellLo[a]);
                EXPECT_LE(d.hi[a], r.cellHi[a]);
            }
            covered += k;
        }
        EXPECT_EQ(covered, owner.size());
    }
}

TEST(StructureView, RegionsListThePrimitivesWhoseBoxesCrossThem) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name());
        Built b = build(c);
        const Scene& scene = b.scene;
        StructureView v(scene, *b.accel);
        const std::vector<uint32_t> live = scene.livePrimitives();
        const double margin = 1e-7 * scene.scale();
        const IrregularSubdivision* s = v.irregular();
        // A scene turned off the world's axes: each primitive also has a minimized box along
        // the turn's axes (grid_frame.h), which the regular grid is built in and which cuts the
        // irregular scheme's camera-frame bound.
        const FrameChoice fc = chooseGridFrame(scene);
        // A light's projective regions are in the light's frame (RegionInfo::light).
        const auto frameOf = [&](const RegionInfo& r) -> const CameraFrame& {
            return r.light >= 0 ? s->lights()[size_t(r.light)].frame() : s->frame();
        };
        const auto cameraBound = [&](uint32_t p, const CameraFrame& frame) {
            Box3 b = frame.box(scene.minBox[p]);
            if (!fc.frame.turned) return b;
            const Box3& f = fc.boxes[p];
            Box3 c;
            for (int i = 0; i < 8 && !f.isEmpty(); ++i)
                c.expand(frame.point(fc.frame.toWorld(boxCorner(f, i))));
            return overlap(b, c);
        };
        // The irregular scheme's zones narrow each primitive's boxes to the depths they take
        // over the zone (primitive_hulls.h), so a slab need not list a primitive whose camera-frame
        // bound merely overlaps it; it must list one whose bound (its minimized box and, turned,
        // its box along the turn's axes) holds a point of the slab's interior: sampled on a
        // 5 x 5 x 5 grid inside it (`box` in (u, v, depth) for a projective slab).
        const auto holdsAPointOf = [&](uint32_t p, const Box3& box, bool projective,
                                       const CameraFrame& frame) {
            for (int i = 0; i < 125; ++i) {
                Vec3 c;
                for (int a = 0, j = i; a < 3; ++a, j /= 5)
                    c[a] = box.lo[a] + (0.1 + 0.2 * (j % 5)) * (box.hi[a] - box.lo[a]);
                if (projective) c = {c.x * c.z, c.y * c.z, c.z};
                const Vec3 w = frame.toWorld(c);
                if (scene.minBox[p].contains(w) &&
                    (!fc.frame.turned || fc.boxes[p].contains(fc.frame.toFrame(w))))
                    return true;
            }
            return false;
        };
        for (uint32_t id = 0; id < v.regionCount(); ++id) {
            RegionInfo r = v.region(id);
            std::vector<uint32_t> crossed;
            for (uint32_t p : live) {
                const Box3& box = scene.minBox[p];
                bool crossing = false;
                switch (r.kind) {
                    case RegionKind::SceneBox:
                        crossing = crosses(box, r.frameBox, margin);
                        break;
                    case RegionKind::BvhLeaf:  // both in the BVH's frame
                    case RegionKind::BvhInner:
                        crossing = crosses(v.bvh()->frame().turned ? fc.boxes[p] : box, r.frameBox,
                                           margin);
                        break;
                    case RegionKind::Leaf:  // both in the grid's frame
                        crossing = crosses(v.regular()->boxes()[p], r.frameBox, margin);
                        break;
                    case RegionKind::Slab:
                        crossing = holdsAPointOf(p, r.frameBox, false, frameOf(r));
                        break;
                    case RegionKind::NearRegion:
                        crossing = cameraBound(p, frameOf(r)).lo.z < r.frameBox.hi.z - margin;
                        break;
                    case RegionKind::ProjectiveSlab:
                        crossing = holdsAPointOf(p, r.frameBox, true, frameOf(r));
                        break;
                }
                if (crossing) crossed.push_back(p);
            }
            // The regular scheme lists the primitives of its restricted tree: one whose box
            // crosses the leaf but that the restriction drops (a subtrahend or an intersection
            // operand alone there) cannot contribute in it. Restriction is monotone, so the
            // restriction to the crossing primitives keeps only listed ones.
            std::vector<uint32_t> need = crossed;
            if (r.kind == RegionKind::Leaf) {
                std::vector<char> keep(scene.prims.size(), 0);
                for (uint32_t p : crossed) keep[p] = 1;
                CsgTree t;
                t.root = restrictTree(scene.tree, scene.tree.root, keep, t);
                need = t.primitives();
            }
            // A leaf that a convex solid fills keeps only what has a boundary there
            // (restrictionWithin): no primitive need be listed; what it lists is checked below.
            if (r.kind == RegionKind::Leaf &&
                std::any_of(crossed.begin(), crossed.end(), [&](uint32_t p) {
                    const Primitive& prim = scene.prims[p];
                    for (int i = 0; i < 8; ++i) {
                        const Vec3 w = v.regular()->frame().toWorld(boxCorner(r.frameBox, i));
                        const Vec3 l = prim.hasXf ? Vec3(prim.xf.inv * glm::dvec4(w, 1.0)) : w;
                        if (!convexSolidHolds(prim.shape, l)) return false;
                    }
                    return true;
                }))
                need.clear();
            for (uint32_t p : need) {
                EXPECT_TRUE(lists(r.prims, p)) << v.toString(id) << " does not list p" << p << " "
                                               << scene.minBox[p].toString();
            }
            // The restricted tree only holds listed primitives.
            if (r.root >= 0) {
                CsgTree t;
                t.nodes = r.pool->nodes;
                t.root = r.root;
                for (uint32_t p : t.primitives()) EXPECT_TRUE(lists(r.prims, p));
            }
        }
    }
}

TEST(StructureView, CornersHoldTheStretchOfRayTheWalkReports) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name());
        Built b = build(c);
        const Scene& scene = b.scene;
        StructureView v(scene, *b.accel);
        std::vector<Ray> rays = test::randomRays(scene, c.seed, 150);
        for (const Ray& r : test::pixelRays(scene, 8, 6)) rays.push_back(r);
        TraceContext ctx(scene.prims.size(), scene.tree.depth());
        const double tol = 1e-7 * scene.scale();
        size_t checked = 0;
        for (const Ray& ray : rays) {
            RecordingObserver obs = test::recordWalk(*b.accel, ray, ctx);
            for (const WalkEvent& e : obs.events) {
                const walk::Region* g = e.get<walk::Region>();
                if (!g || !std::isfinite(g->t1) || !(g->t0 <= g->t1)) continue;
                const std::array<Vec3, 8> corners = v.regionCorners(g->region);
                for (double f : {0.0, 0.3, 0.7, 1.0}) {
                    Vec3 p = ray.at(g->t0 + f * (g->t1 - g->t0));
                    ASSERT_LE(test::outside(corners, p), tol)
                        << v.toString(g->region) << " t " << g->t0 << ".." << g->t1 << " "
                        << ray.toString();
                    ++checked;
                }
            }
        }
        if (c.scheme != SchemeKind::Brute) {
            EXPECT_GT(checked, 0u);
        }
        // Picking in 3D: the region holding a point holds it.
        std::mt19937_64 rng(c.seed);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        const Box3 wb = v.worldBounds();
        for (int k = 0; k < 100; ++k) {
            Vec3 p = wb.lo + Vec3(u(rng), u(rng), u(rng)) * wb.extent();
            if (test::outside(v.structureCorners(), p) > 0.0) continue;
            uint32_t id = v.regionAt(p);
            EXPECT_LE(test::outside(v.regionCorners(id), p), tol) << v.toString(id);
        }
    }
}

TEST(StructureView, NeighboursShareAFace) {
    for (const Case& c : cases()) {
        if (c.scheme == SchemeKind::Brute) continue;
        SCOPED_TRACE(c.name());
        Built b = build(c);
        StructureView v(b.scene, *b.accel);
        for (uint32_t id = 0; id < v.regionCount(); ++id) {
            RegionInfo r = v.region(id);
            for (int a = 0; a < 3; ++a) {
                if (r.lo[a] >= 0) {
                    EXPECT_EQ(v.region(uint32_t(r.lo[a])).frameBox.hi[a], r.frameBox.lo[a]);
                }
                if (r.hi[a] >= 0) {
                    EXPECT_EQ(v.region(uint32_t(r.hi[a])).frameBox.lo[a], r.frameBox.hi[a]);
                }
            }
        }
    }
}

nlohmann::json dump(const StructureView& v, StructureDumpOptions o);

TEST(StructureView, EmptyScene) {
    // No primitive at all: the schemes build empty structures, and so are they described.
    Scene scene;
    scene.prepare();
    for (SchemeKind k : {SchemeKind::Brute, SchemeKind::Regular, SchemeKind::Irregular}) {
        BuildParams p;
        p.scheme = k;
        auto accel = buildAccelerator(scene, p);
        StructureView v(scene, *accel);
        EXPECT_EQ(v.regionCount(), accel->info().regions) << schemeName(k);
        if (k == SchemeKind::Irregular) {
            EXPECT_TRUE(v.frames().empty() || v.regionCount() > 0);
        }
        StructureDumpOptions o;
        o.width = kW;
        o.height = kH;
        nlohmann::json j = dump(v, o);
        EXPECT_EQ(j["regions"], v.regionCount());
    }
}

nlohmann::json dump(const StructureView& v, StructureDumpOptions o) {
    std::ostringstream s;
    writeStructureJson(v, o, s);
    return nlohmann::json::parse(s.str());
}

std::vector<uint32_t> vecOf(std::span<const uint32_t> s) { return {s.begin(), s.end()}; }
nlohmann::json pointJson(glm::dvec2 p) { return {p.x, p.y}; }
nlohmann::json boxJson(const Box3& b) {
    return {{b.lo.x, b.lo.y, b.lo.z}, {b.hi.x, b.hi.y, b.hi.z}};
}

TEST(StructureDump, RoundTripsTheDescription) {
    for (const Case& c : cases()) {
        SCOPED_TRACE(c.name());
        Built b = build(c);
        const Scene& scene = b.scene;
        StructureView v(scene, *b.accel);
        StructureDumpOptions o;
        o.width = kW;
        o.height = kH;
        nlohmann::json j = dump(v, o);
        EXPECT_EQ(j["scheme"], schemeName(c.scheme));
        EXPECT_EQ(j["width"], kW);
        EXPECT_EQ(j["height"], kH);
        EXPECT_EQ(j["camera"]["width"], kW);
        EXPECT_EQ(j["camera"].contains("projection"), c.ortho);
        EXPECT_EQ(j["regions"], v.regionCount());
        EXPECT_EQ(j["summary"], false);
        ASSERT_EQ(j["primitives"].size(), scene.prims.size());
        for (uint32_t p = 0; p < scene.prims.size(); ++p) {
            const nlohmann::json& q = j["primitives"][p];
            EXPECT_EQ(q["id"], p);
            EXPECT_EQ(q["kind"], shapeName(scene.prims[p].shape));
            if (scene.minBox[p].isEmpty())
                EXPECT_TRUE(q["box"].is_null());
            else
                EXPECT_EQ(q["box"], boxJson(scene.minBox[p]));
        }
        EXPECT_EQ(j.contains("regular"), c.scheme == SchemeKind::Regular);
        EXPECT_EQ(j.contains("irregular"), c.scheme == SchemeKind::Irregular);
        EXPECT_EQ(j.contains("projective"), v.frame(ZoneFrameKind::Projective) != nullptr);
        if (const RegularGrid* g = v.regular()) {
            const nlohmann::json& rj = j["regular"];
            EXPECT_EQ(rj["bounds"], boxJson(g->box()));
            EXPECT_EQ(rj["directory"],
                      nlohmann::json({v.directoryLog2(0), v.directoryLog2(1), v.directoryLog2(2)}));
            ASSERT_EQ(rj["leaves"].size(), v.regionCount());
            for (uint32_t id = 0; id < v.regionCount(); ++id) {
                const nlohmann::json& l = rj["leaves"][id];
                RegionInfo r = v.region(id);
                EXPECT_EQ(l["id"], id);
                EXPECT_EQ(l["level"], r.level);
                EXPECT_EQ(l["box"], boxJson(r.frameBox));
                EXPECT_EQ(l["prims"].get<std::vector<uint32_t>>(), vecOf(r.prims));
            }
        }
        for (const ZoneFrameView& f : v.frames()) {
            const bool cam = f.kind() == ZoneFrameKind::Camera;
            const nlohmann::json& fj = j[cam ? "irregular" : "projective"];
            const bool px = f.units() == FrameUnits::Pixels;
            auto pt = [&](glm::dvec2 p) { return pointJson(px ? f.toPixel(p, kW, kH) : p); };
            EXPECT_EQ(fj["frame"], cam ? "camera" : "projective");
            EXPECT_EQ(fj["units"], px ? "pixels" : "camera");
            std::vector<BspCut> cuts = f.cuts();
            ASSERT_EQ(fj["bsp"].size(), cuts.size());
            for (size_t i = 0; i < cuts.size(); ++i) {
                EXPECT_EQ(fj["bsp"][i]["node"], cuts[i].node);
                EXPECT_EQ(fj["bsp"][i]["depth"], cuts[i].depth);
                EXPECT_EQ(fj["bsp"][i]["segment"], nlohmann::json({pt(cuts[i].a), pt(cuts[i].b)}));
            }
            size_t k = 0;
            double area = 0.0;
            for (uint32_t z = 0; z < f.zoneCount(); ++z) {
                std::vector<glm::dvec2> poly = f.zonePolygon(z, kW, kH);
                if (poly.empty()) continue;
                ASSERT_LT(k, fj["zones"].size());
                const nlohmann::json& zj = fj["zones"][k++];
                EXPECT_EQ(zj["id"], z);
                nlohmann::json pj = nlohmann::json::array();
                for (glm::dvec2 p : poly) pj.push_back(pointJson(p));
                EXPECT_EQ(zj["polygon"], pj);
                area += polygonArea(poly);
                EXPECT_EQ(zj["prims"].get<std::vector<uint32_t>>(), vecOf(f.zonePrims(z)));
                std::vector<SlabInfo> slabs = f.slabs(z);
                ASSERT_EQ(zj["slabs"].size(), slabs.size());
                for (size_t i = 0; i < slabs.size(); ++i) {
                    const nlohmann::json& sj = zj["slabs"][i];
                    EXPECT_EQ(sj["region"], slabs[i].region);
                    EXPECT_EQ(sj["z0"], slabs[i].z0);
                    EXPECT_EQ(sj["z1"], slabs[i].z1);
                    EXPECT_EQ(sj["prims"].get<std::vector<uint32_t>>(), vecOf(slabs[i].prims));
                    if (i) {
                        EXPECT_EQ(slabs[i].z0, slabs[i - 1].z1);
                    }
                    RegionInfo r = v.region(slabs[i].region);
                    EXPECT_EQ(r.zone, z);
                    EXPECT_EQ(r.frameBox.lo.z, slabs[i].z0);
                }
            }
            EXPECT_EQ(k, fj["zones"].size());
            EXPECT_GT(area, 0.0);
        }
    }
}

TEST(StructureDump, SummarisedAboveTheLimitUnlessAll) {
    for (const Case& c : cases()) {
        if (c.seed != seeds()[0] || c.scheme == SchemeKind::Brute) continue;
        SCOPED_TRACE(c.name());
        Built b = build(c);
        StructureView v(b.scene, *b.accel);
        StructureDumpOptions o;
        o.width = kW;
        o.height = kH;
        o.limit = v.regionCount() - 1;
        nlohmann::json j = dump(v, o);
        EXPECT_EQ(j["summary"], true);
        EXPECT_EQ(j["regions"], v.regionCount());
        EXPECT_EQ(j["primitives"].size(), b.scene.prims.size());
        if (c.scheme == SchemeKind::Regular) {
            EXPECT_FALSE(j["regular"].contains("leaves"));
            EXPECT_EQ(j["regular"]["leaf_count"], v.regionCount());
        } else {
            EXPECT_FALSE(j["irregular"].contains("zones"));
            EXPECT_FALSE(j["irregular"].contains("bsp"));
            EXPECT_EQ(j["irregular"]["zone_count"], v.frame(ZoneFrameKind::Camera)->zoneCount());
            EXPECT_EQ(j["irregular"]["slab_count"], v.irregular()->regions().size());
        }
        o.all = true;
        j = dump(v, o);
        EXPECT_EQ(j["summary"], false);
        EXPECT_TRUE(j.contains(c.scheme == SchemeKind::Regular ? "regular" : "irregular"));
        EXPECT_TRUE(c.scheme == SchemeKind::Regular ? j["regular"].contains("leaves")
                                                    : j["irregular"].contains("zones"));
        o.all = false;
        o.limit = v.regionCount();
        EXPECT_EQ(dump(v, o)["summary"], false);
    }
}

}  // namespace
}  // namespace lancer
