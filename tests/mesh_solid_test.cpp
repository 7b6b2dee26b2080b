// Closed meshes as solids (engine/model/mesh_solid.h): the convex pieces hold exactly the points
// the mesh's parity says are inside, an L-shaped mesh traces as the union of its two boxes, open
// and self-intersecting meshes are refused by name, the STL and OFF readers agree, and every
// scheme gives brute force's hit on random CSG scenes with meshes.
#include "engine/model/mesh_solid.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "engine/accel/accelerator.h"
#include "engine/accel/observer.h"
#include "engine/scene/mesh_file.h"
#include "engine/scene/openscad_reader.h"
#include "engine/scene/scene.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

/// A closed star-shaped mesh about the origin: a UV sphere whose vertices lie at random radii in
/// [0.4, 1] (non-convex, and never self-intersecting: each ray from the centre crosses it once).
TriangleMesh starMesh(uint64_t seed, int nu = 10, int nv = 7) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> rad(0.4, 1.0);
    TriangleMesh m;
    m.points.push_back({0, 0, -rad(rng)});
    for (int j = 1; j < nv; ++j)
        for (int i = 0; i < nu; ++i) {
            const double th = 2.0 * M_PI * i / nu, ph = M_PI * j / nv - M_PI / 2;
            m.points.push_back(rad(rng) * Vec3(std::cos(ph) * std::cos(th),
                                               std::cos(ph) * std::sin(th), std::sin(ph)));
        }
    m.points.push_back({0, 0, rad(rng)});
    const uint32_t top = uint32_t(m.points.size() - 1);
    auto at = [&](int j, int i) { return uint32_t(1 + (j - 1) * nu + (i % nu)); };
    for (int i = 0; i < nu; ++i) {
        m.triangles.push_back({0, at(1, i + 1), at(1, i)});
        m.triangles.push_back({top, at(nv - 1, i), at(nv - 1, i + 1)});
        for (int j = 1; j + 1 < nv; ++j) {
            m.triangles.push_back({at(j, i), at(j, i + 1), at(j + 1, i + 1)});
            m.triangles.push_back({at(j, i), at(j + 1, i + 1), at(j + 1, i)});
        }
    }
    return m;
}

/// The box [lo, hi] as 12 triangles, facing out (or in, `inward`), points appended to `m`.
void addBox(TriangleMesh& m, const Vec3& lo, const Vec3& hi, bool inward = false) {
    const uint32_t b = uint32_t(m.points.size());
    for (int k = 0; k < 8; ++k)
        m.points.push_back({k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z});
    const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                             {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& q : quads) {
        std::array<uint32_t, 3> t0{b + q[0], b + q[1], b + q[2]}, t1{b + q[0], b + q[2], b + q[3]};
        if (inward) std::swap(t0[0], t0[1]), std::swap(t1[0], t1[1]);
        m.triangles.push_back(t0);
        m.triangles.push_back(t1);
    }
}

/// The nearest hit's t along `r` (brute force), or -1 on a miss.
double nearestT(const Scene& scene, const Ray& r) {
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    const auto accel = buildAccelerator(scene, bp);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    NullObserver obs;
    Hit h;
    ctx.beginRay();
    return accel->intersect(r, 0.0, kInf, ctx, obs, h) ? h.t : -1.0;
}

bool inPieces(const MeshSolid& s, const Vec3& p) {
    for (const Polytope& k : s.pieces) {
        bool in = true;
        for (const glm::dvec4& pl : k.planes) in = in && glm::dot(Vec3(pl), p) <= pl.w;
        if (in) return true;
    }
    return false;
}

/// The pieces under one union, placed by `xf`, in `scene`: the tree node.
int addSolid(Scene& scene, const MeshSolid& s, const Transform& xf) {
    std::vector<int> items;
    for (const Polytope& k : s.pieces) {
        scene.prims.push_back(makePrimitive(k, xf, 0));
        items.push_back(scene.tree.leaf(uint32_t(scene.prims.size() - 1)));
    }
    return scene.tree.balanced(Op::Union, items);
}

TEST(MeshSolid, PiecesHoldWhatParitySaysOfRandomStarMeshes) {
    for (uint64_t seed = 1; seed <= 16; ++seed) {
        const TriangleMesh m = starMesh(seed, 8 + int(seed), 6 + int(seed % 5));
        const MeshSolid s = meshSolid(m);
        EXPECT_GT(s.pieces.size(), 1u) << "seed " << seed << ": a star mesh is not convex";
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> u(-1.05, 1.05);
        int inside = 0;
        for (int i = 0; i < 3000; ++i) {
            const Vec3 p(u(rng), u(rng), u(rng));
            const bool want = meshContains(m, p);
            inside += want;
            ASSERT_EQ(inPieces(s, p), want) << "seed " << seed << " at " << toString(p);
        }
        EXPECT_GT(inside, 200) << "seed " << seed;
    }
}

TEST(MeshSolid, AHollowBoxKeepsItsCavityWhicheverWayItsInnerShellFaces) {
    for (bool inward : {false, true}) {
        TriangleMesh m;
        addBox(m, Vec3(-2.0), Vec3(2.0));
        addBox(m, Vec3(-1.0), Vec3(1.0), inward);
        const MeshSolid s = meshSolid(m);
        EXPECT_FALSE(inPieces(s, Vec3(0.0)));
        EXPECT_FALSE(inPieces(s, Vec3(0.9, -0.9, 0.5)));
        EXPECT_TRUE(inPieces(s, Vec3(1.5, 0.0, 0.0)));
        EXPECT_TRUE(inPieces(s, Vec3(-1.9, 1.9, -1.9)));
        EXPECT_FALSE(inPieces(s, Vec3(2.1, 0.0, 0.0)));
    }
}

// An L-shaped prism as one mesh (its faces cut into triangles) traces as the union of its two
// boxes: the same spans to rounding on random lines.
TEST(MeshSolid, AnLShapedMeshTracesAsTheUnionOfItsBoxes) {
    // The L's outline in the xy plane, extruded from z = 0 to 1.
    const std::vector<Vec3> outline{{0, 0, 0}, {3, 0, 0}, {3, 1, 0},
                                    {1, 1, 0}, {1, 2, 0}, {0, 2, 0}};
    TriangleMesh m;
    const uint32_t n = uint32_t(outline.size());
    for (const Vec3& p : outline) m.points.push_back(p);
    for (const Vec3& p : outline) m.points.push_back(p + Vec3(0, 0, 1));
    std::vector<uint32_t> bottom, topLoop;
    for (uint32_t i = 0; i < n; ++i) bottom.push_back(n - 1 - i), topLoop.push_back(n + i);
    ASSERT_TRUE(m.addPolygon(bottom));
    ASSERT_TRUE(m.addPolygon(topLoop));
    for (uint32_t i = 0; i < n; ++i)
        ASSERT_TRUE(m.addPolygon({i, (i + 1) % n, n + (i + 1) % n, n + i}));
    const MeshSolid s = meshSolid(m);
    ASSERT_GE(s.pieces.size(), 2u);

    Scene mesh, boxes;
    mesh.tree.root = addSolid(mesh, s, Transform());
    boxes.prims.push_back(makePrimitive(Block{{0, 0, 0}, {3, 1, 1}}, Transform(), 0));
    boxes.prims.push_back(makePrimitive(Block{{0, 0, 0}, {1, 2, 1}}, Transform(), 0));
    boxes.tree.root = boxes.tree.combine(Op::Union, boxes.tree.leaf(0), boxes.tree.leaf(1));
    mesh.prepare();
    boxes.prepare();
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int hits = 0;
    for (int i = 0; i < 4000; ++i) {
        const Vec3 at(1.5 + 1.6 * u(rng), 1.0 + 1.1 * u(rng), 0.5 + 0.6 * u(rng));
        const Vec3 d = glm::normalize(Vec3(u(rng), u(rng), u(rng)));
        const Ray r{at - 6.0 * d, d};
        const double ta = nearestT(mesh, r), tb = nearestT(boxes, r);
        ASSERT_EQ(ta < 0.0, tb < 0.0) << r.toString();
        if (ta < 0.0) continue;
        ++hits;
        EXPECT_NEAR(ta, tb, 1e-12) << r.toString();
    }
    EXPECT_GT(hits, 1000);
}

TEST(MeshSolid, OpenSelfIntersectingAndFoldedMeshesAreRefusedByName) {
    TriangleMesh open;
    addBox(open, Vec3(0.0), Vec3(1.0));
    open.triangles.pop_back();
    try {
        meshSolid(open);
        FAIL() << "an open mesh was accepted";
    } catch (const MeshError& e) {
        EXPECT_NE(std::string(e.what()).find("not a closed mesh: the edge from point"),
                  std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("belongs to 1 triangle"), std::string::npos);
    }
    TriangleMesh crossing;
    addBox(crossing, Vec3(0.0), Vec3(2.0));
    addBox(crossing, Vec3(1.0), Vec3(3.0));
    try {
        meshSolid(crossing);
        FAIL() << "two overlapping boxes as one mesh were accepted";
    } catch (const MeshError& e) {
        EXPECT_NE(std::string(e.what()).find("self-intersecting: triangles"), std::string::npos)
            << e.what();
    }
    // A tetrahedron's face folded onto its neighbour: two triangles on one edge, one plane.
    TriangleMesh folded;
    folded.points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    folded.triangles = {{0, 1, 2}, {1, 0, 2}};
    EXPECT_THROW(meshSolid(folded), MeshError);
    TriangleMesh huge;
    addBox(huge, Vec3(0.0), Vec3(1.0));
    MeshLimits small;
    small.maxTriangles = 11;
    EXPECT_THROW(meshSolid(huge, small), MeshError);
}

TEST(MeshFile, StlAsciiBinaryAndOffReadTheSameSolid) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("lancer-mesh-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    TriangleMesh m;
    addBox(m, Vec3(-1.0, -2.0, -0.5), Vec3(1.5, 2.0, 0.5));
    {
        std::ofstream a(dir / "b.stl");
        a << "solid box\n";
        for (const auto& t : m.triangles) {
            a << " facet normal 0 0 0\n  outer loop\n";
            for (uint32_t i : t)
                a << "   vertex " << m.points[i].x << " " << m.points[i].y << " " << m.points[i].z
                  << "\n";
            a << "  endloop\n endfacet\n";
        }
        a << "endsolid box\n";
        std::ofstream b(dir / "bin.STL", std::ios::binary);
        const std::string header(80, ' ');
        b.write(header.data(), 80);
        const uint32_t count = uint32_t(m.triangles.size());
        b.write(reinterpret_cast<const char*>(&count), 4);
        for (const auto& t : m.triangles) {
            float v[12] = {};
            for (int k = 0; k < 3; ++k)
                for (int c = 0; c < 3; ++c) v[3 + 3 * k + c] = float(m.points[t[k]][c]);
            b.write(reinterpret_cast<const char*>(v), sizeof v);
            b.write("\0\0", 2);
        }
        std::ofstream o(dir / "b.off");
        o << "OFF\n# a box\n8 6 0\n";
        for (const Vec3& p : m.points) o << p.x << " " << p.y << " " << p.z << "\n";
        const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                 {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
        for (const auto& q : quads)
            o << "4 " << q[0] << " " << q[1] << " " << q[2] << " " << q[3] << " 255 0 0\n";
        std::ofstream csg(dir / "m.csg");
        csg << "union() { import(\"b.stl\"); translate([5, 0, 0]) import(file = \"bin.STL\");\n"
               "  translate([10, 0, 0]) import(\"b.off\", convexity = 2); }\n";
    }
    for (const char* f : {"b.stl", "bin.STL", "b.off"}) {
        const MeshSolid s = meshSolid(readMeshFile((dir / f).string()));
        ASSERT_EQ(s.pieces.size(), 1u) << f;  // a box is one convex piece
        Box3 b = s.pieces[0].bounds;
        EXPECT_NEAR(b.lo.y, -2.0, 1e-6) << f;
        EXPECT_NEAR(b.hi.x, 1.5, 1e-6) << f;
        EXPECT_EQ(s.pieces[0].planes.size(), 6u) << f;
    }
    OpenScadCounts counts;
    const Scene scene = readOpenScadFile((dir / "m.csg").string(), &counts);
    EXPECT_EQ(counts.meshes, 3);
    EXPECT_NEAR(scene.bounds.hi.x, 11.5, 1e-6);

    // Bad files name the import's position and the mesh's path and line.
    auto refusal = [&](const std::string& body, const std::string& csgText) {
        std::ofstream(dir / "bad.off") << body;
        std::ofstream(dir / "bad.csg") << csgText;
        try {
            readOpenScadFile((dir / "bad.csg").string());
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    std::string e = refusal("OFF\n8 6 0\n0 0 x\n", "\n  import(\"bad.off\");\n");
    EXPECT_NE(e.find("bad.csg:2:10: import(): "), std::string::npos) << e;
    EXPECT_NE(e.find("bad.off:3:5: expected a finite number"), std::string::npos) << e;
    e = refusal("OFF\n", "import(\"missing.stl\");\n");
    EXPECT_NE(e.find("bad.csg:1:8: import(): "), std::string::npos) << e;
    EXPECT_NE(e.find("missing.stl: no such file"), std::string::npos) << e;
    e = refusal("OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n",
                "import(\"bad.off\");\n");
    EXPECT_NE(e.find("bad.csg:1:1: import() of 'bad.off' is not a closed mesh"), std::string::npos)
        << e;
    fs::remove_all(dir);
}

TEST(MeshSolid, APolyhedronThatIsNotConvexIsAMeshSolid) {
    // A box with a notch cut into its top: 12 points, the notch's faces making it non-convex.
    const char* text = R"(polyhedron(points = [[0,0,0],[4,0,0],[4,2,0],[0,2,0],
        [0,0,2],[1.5,0,2],[2,0,1],[2.5,0,2],[4,0,2],[4,2,2],[2.5,2,2],[2,2,1],[1.5,2,2],[0,2,2]],
      faces = [[0,3,2,1],[0,1,8,7,6,5,4],[3,13,12,11,10,9,2],[1,2,9,8],[0,4,13,3],
               [4,5,12,13],[5,6,11,12],[6,7,10,11],[7,8,9,10]]);)";
    OpenScadCounts counts;
    const Scene s = readOpenScad(SourceText("notch.csg", text), nullptr, &counts);
    EXPECT_EQ(counts.meshes, 1);
    EXPECT_GE(counts.meshPieces, 2);
    // Straight down into the notch's bottom (z = 1 at x = 2) and beside it (z = 2).
    EXPECT_NEAR(nearestT(s, {{2.0, 1.0, 5.0}, {0, 0, -1}}), 4.0, 1e-12);
    EXPECT_NEAR(nearestT(s, {{0.5, 1.0, 5.0}, {0, 0, -1}}), 3.0, 1e-12);
}

// Every scheme gives brute force's hit on every pixel (and random and secondary rays) of random
// CSG trees of star meshes, boxes and spheres.
TEST(MeshCsg, EverySchemeGivesBruteForcesHitOnRandomScenesWithMeshes) {
    size_t total = 0;
    for (uint64_t seed = 1; seed <= 8; ++seed) {
        std::mt19937_64 rng(seed);
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        Scene scene;
        std::vector<int> nodes;
        for (int i = 0; i < 6; ++i) {
            const Transform xf = Transform::translate(2.5 * Vec3(u(rng), u(rng), u(rng))) *
                                 Transform::rotate(180.0 * u(rng), {u(rng), u(rng), 1.0}) *
                                 Transform::scale(Vec3(1.5 + u(rng), 1.5 + u(rng), 1.5));
            if (i % 3 == 2) {
                scene.prims.push_back(makePrimitive(Sphere{Vec3(0.0), 0.9}, xf, 0));
                nodes.push_back(scene.tree.leaf(uint32_t(scene.prims.size() - 1)));
            } else {
                nodes.push_back(addSolid(scene, meshSolid(starMesh(seed * 10 + uint64_t(i))), xf));
            }
        }
        while (nodes.size() > 1) {
            const int a = nodes.back();
            nodes.pop_back();
            const size_t j = rng() % nodes.size();
            nodes[j] = scene.tree.combine(std::array<Op, 4>{Op::Union, Op::Union, Op::Intersection,
                                                            Op::Difference}[rng() % 4],
                                          nodes[j], a);
        }
        scene.tree.root = nodes[0];
        scene.prepare();
        if (scene.bounds.isEmpty()) continue;
        scene.frameCamera({-1.0, 2.0, -1.0}, {0, 0, 1});
        scene.defaultLights();
        std::vector<Ray> rays = test::pixelRays(scene, 40, 40);
        const std::vector<Ray> rnd = test::randomRays(scene, seed, 600);
        rays.insert(rays.end(), rnd.begin(), rnd.end());
        test::expectEverySchemeSame(scene, rays);
        for (const SchemeInfo& info : kSchemeTable) {
            BuildParams p;
            p.scheme = info.kind;
            const auto accel = buildAccelerator(scene, p);
            test::expectSame(scene, *accel, test::secondaryRays(scene, rays, seed),
                             "seed " + std::to_string(seed) + " " + info.name + " secondary",
                             1e-9 * scene.scale());
        }
        total += rays.size();
    }
    EXPECT_GE(total, 8000u);
}

}  // namespace
}  // namespace lancer
