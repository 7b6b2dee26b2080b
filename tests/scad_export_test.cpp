// `lancer export --scad` and the report's mesh axis: the OpenSCAD model's text (every solid shape,
// its matrix in OpenSCAD's row form, the CSG tree, a convex polytope as a closed polyhedron),
// surfaces refused by name, STL files read (ASCII and binary, a truncated one refused by line),
// and, where openscad is installed, OpenSCAD's mesh of the model traced against the exact solid:
// the same silhouette but for a few edge pixels, and depths that converge as $fn grows.
#include "app/bench/scad_export.h"

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "app/bench/image_error.h"
#include "app/bench/mesh_peer.h"
#include "engine/accel/observer.h"
#include "engine/render/renderer.h"

namespace lancer::bench {
namespace {

/// Solids of every shape OpenSCAD models: a block minus a sphere and a rotated cylinder, a cone
/// of two radii intersected with a sphere, a scaled and rotated block, a tilted torus, a
/// tetrahedron (a polytope of four planes).
Scene solidScene() {
    Scene s;
    auto prim = [&](Shape shape, const Transform& xf = Transform()) {
        s.prims.push_back(makePrimitive(std::move(shape), xf, 0));
        return s.tree.leaf(uint32_t(s.prims.size() - 1));
    };
    std::vector<int> parts;
    const int block = prim(Block{{-2.0, -1.0, 0.0}, {0.0, 1.0, 2.0}});
    const int hole = prim(Sphere{{-1.0, -1.0, 2.0}, 0.9});
    const int drill = prim(Cone{0.35, 0.35, 4.0, false}, Transform::translate({-1.0, 0.0, 1.0}) *
                                                             Transform::rotate(90.0, {0, 1, 0}) *
                                                             Transform::translate({0, 0, -2.0}));
    parts.push_back(
        s.tree.combine(Op::Difference, s.tree.combine(Op::Difference, block, hole), drill));
    parts.push_back(s.tree.combine(
        Op::Intersection, prim(Cone{1.0, 0.3, 2.0, false}, Transform::translate({1.5, 0, 0})),
        prim(Sphere{{1.5, 0.0, 0.8}, 1.05})));
    parts.push_back(
        prim(Block{{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}},
             Transform::translate({0.2, 1.8, 0.6}) * Transform::rotate(30.0, {0.3, 0.2, 1.0}) *
                 Transform::scale({1.0, 0.6, 0.8})));
    // A torus tilted towards the camera, its hole in view.
    parts.push_back(prim(Torus{0.5, 0.18}, Transform::translate({0.5, -1.9, 0.75}) *
                                               Transform::rotate(40.0, {1.0, 0.0, 0.0})));
    Polytope tet;
    const Vec3 v[4] = {{2.5, 1.5, 0.0}, {3.5, 1.5, 0.0}, {3.0, 2.4, 0.0}, {3.0, 1.8, 1.2}};
    const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    for (const auto& f : faces) {
        const Vec3 n = glm::normalize(glm::cross(v[f[1]] - v[f[0]], v[f[2]] - v[f[0]]));
        tet.planes.push_back({n, glm::dot(n, v[f[0]])});
    }
    tet.bounds = Box3{{2.5, 1.5, 0.0}, {3.5, 2.4, 1.2}};
    parts.push_back(prim(tet));
    s.tree.root = s.tree.balanced(Op::Union, parts);
    s.prepare();
    s.camera.from = {1.5, -6.0, 3.8};
    s.camera.at = {0.5, 0.5, 0.7};
    s.camera.up = {0.0, 0.0, 1.0};
    s.camera.fov = 45.0;
    s.defaultLights();
    return s;
}

std::string scadText(const Scene& s, int fn = 32) {
    std::ostringstream os;
    writeScad(os, s, fn);
    return os.str();
}

TEST(ScadExport, WritesEveryShapeAndTheTree) {
    const std::string scad = scadText(solidScene(), 24);
    for (const char* s :
         {"$fn = 24;", "union() {", "difference() {", "intersection() {", "sphere(r = 0.9)",
          "translate([-2, -1, 0]) cube([2, 2, 2])", "cylinder(h = 2, r1 = 1, r2 = 0.3)",
          "multmatrix([[", "polyhedron(", "rotate_extrude() translate([0.5, 0]) circle(r = 0.18)"})
        EXPECT_NE(scad.find(s), std::string::npos) << s << "\n" << scad;
    // The chain of differences is one difference: the block minus the sphere and the cylinder.
    EXPECT_EQ(scad.find("difference()", scad.find("difference()") + 1), std::string::npos);
    // The tetrahedron: its four vertices and four triangular faces.
    const std::regex poly("polyhedron\\(points = \\[(.*)\\], faces = \\[(.*)\\]\\)");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(scad, m, poly));
    const std::string pts = m[1].str(), faces = m[2].str();
    EXPECT_EQ(std::count(pts.begin(), pts.end(), '['), 4) << pts;
    EXPECT_EQ(std::count(faces.begin(), faces.end(), '['), 4) << faces;
}

TEST(ScadExport, MatrixIsOpenScadsRowForm) {
    const Scene s = solidScene();
    const std::string scad = scadText(s);
    const Primitive& p = s.prims[5];  // the rotated block
    ASSERT_TRUE(p.hasXf);
    const std::regex re(
        "multmatrix\\(\\[\\[([^\\]]+)\\], \\[([^\\]]+)\\], \\[([^\\]]+)\\], "
        "\\[0, 0, 0, 1\\]\\]\\) translate\\(\\[-0.5, -0.5, -0.5\\]\\) cube");
    std::smatch m;
    ASSERT_TRUE(std::regex_search(scad, m, re)) << scad;
    double row[3][4];
    for (int i = 0; i < 3; ++i) {
        std::stringstream ss(m[size_t(i) + 1].str());
        int j = 0;
        for (std::string item; std::getline(ss, item, ',') && j < 4; ++j)
            row[i][j] = std::stod(item);
        ASSERT_EQ(j, 4);
    }
    for (const Vec3& q : {Vec3(0.5, -0.5, 0.5), Vec3(-0.3, 0.2, 0.1)}) {
        const Vec3 ours = p.xf.point(q);
        for (int i = 0; i < 3; ++i)
            EXPECT_DOUBLE_EQ(row[i][0] * q.x + row[i][1] * q.y + row[i][2] * q.z + row[i][3],
                             ours[i]);
    }
}

TEST(ScadExport, RefusesSurfacesByName) {
    Scene s;
    Triangle t;
    t.p[0] = {0, 0, 0};
    t.p[1] = {1, 0, 0};
    t.p[2] = {0, 1, 0};
    s.prims.push_back(makePrimitive(t, Transform(), 0));
    s.prims.back().origin = "floor.nff:3:1";
    s.tree.root = s.tree.leaf(0);
    try {
        scadText(s);
        FAIL() << "a triangle was written";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("triangle, floor.nff:3:1"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("solids only"), std::string::npos) << e.what();
    }
    EXPECT_THROW(scadText(Scene{}), std::invalid_argument);
}

TEST(ScadExport, ReadsAsciiAndBinaryStl) {
    const auto dir = std::filesystem::temp_directory_path() / "lancer_stl_test";
    std::filesystem::create_directories(dir);
    const Vec3 v[4] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
    {
        std::ofstream a(dir / "t.stl");
        a << "solid t\n";
        for (const auto& f : faces) {
            a << " facet normal 0 0 0\n  outer loop\n";
            for (int k : f) a << "   vertex " << v[k].x << " " << v[k].y << " " << v[k].z << "\n";
            a << "  endloop\n endfacet\n";
        }
        a << "endsolid t\n";
        std::ofstream b(dir / "b.stl", std::ios::binary);
        char header[80] = "solid binary, told apart by its size";
        b.write(header, 80);
        const uint32_t n = 4;
        b.write(reinterpret_cast<const char*>(&n), 4);
        for (const auto& f : faces) {
            float rec[12] = {};
            for (int k = 0; k < 3; ++k)
                for (int c = 0; c < 3; ++c) rec[3 + 3 * k + c] = float(v[f[k]][c]);
            b.write(reinterpret_cast<const char*>(rec), sizeof rec);
            const uint16_t attr = 0;
            b.write(reinterpret_cast<const char*>(&attr), 2);
        }
        std::ofstream c(dir / "cut.stl");
        c << "solid t\n facet normal 0 0 0\n  outer loop\n   vertex 0 0 0\n   vertex 1 0\n";
    }
    Scene like = solidScene();
    for (const char* name : {"t.stl", "b.stl"}) {
        const Scene s = readStl((dir / name).string(), like);
        ASSERT_EQ(s.prims.size(), 4u) << name;
        EXPECT_EQ(s.lights.size(), like.lights.size());
        EXPECT_EQ(s.bounds.lo, Vec3(0.0)) << name;
        EXPECT_EQ(s.bounds.hi, Vec3(1.0)) << name;
        // A ray down the z axis at (0.2, 0.2) crosses the tetrahedron's top face at z = 0.6.
        auto brute = buildAccelerator(s, BuildParams{});
        TraceContext ctx(s.prims.size(), s.tree.depth());
        ctx.newStamp();  // a fresh walk, as the renderer starts each ray
        NullObserver none;
        Hit h;
        ASSERT_TRUE(brute->intersect(Ray{{0.2, 0.2, 5.0}, {0, 0, -1}}, 0.0, kInf, ctx, none, h))
            << name;
        EXPECT_NEAR(h.t, 4.4, 1e-6) << name;
    }
    try {
        readStl((dir / "cut.stl").string(), like);
        FAIL() << "a truncated STL was read";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("cut.stl:6:1: the file ends before a vertex's z"),
                  std::string::npos)
            << e.what();
    }
    std::filesystem::remove_all(dir);
}

// OpenSCAD's CGAL render of the model, traced (by Lancer's brute force, so that Embree is not
// needed) against the exact solid: the silhouettes agree but for the facets' edge pixels, and
// the depth error falls as $fn grows.
TEST(ScadExport, OpenScadMeshConvergesOnTheExactSolid) {
    if (!MeshPeer::available()) GTEST_SKIP() << "openscad is not installed";
    const Scene exact = solidScene();
    const auto dir = std::filesystem::temp_directory_path() / "lancer_mesh_test";
    const MeshPeer model(exact, dir.string(), "solids");
    RenderOptions opt;
    opt.width = 64;
    opt.height = 48;
    opt.threads = 2;
    opt.shading.bounces = 0;
    Image ref(opt.width, opt.height);
    render(exact, *buildAccelerator(exact, BuildParams{}), opt, ref);
    double previous = kInf;
    for (int fn : {8, 32}) {
        const MeshRun run = model.mesh(fn, 120.0);
        ASSERT_EQ(run.failure, "") << "$fn " << fn;
        const Scene mesh = readStl(run.stl, exact);
        EXPECT_GT(mesh.prims.size(), 100u);
        Image img(opt.width, opt.height);
        render(mesh, *buildAccelerator(mesh, BuildParams{}), opt, img);
        const ImageError e = compareSurfaces(ref, img);
        EXPECT_LT(e.silhouetteDiff, size_t(opt.width * opt.height / 20)) << "$fn " << fn;
        EXPECT_GT(e.rmsDepthDiff, 0.0) << "$fn " << fn;
        EXPECT_LT(e.rmsDepthDiff, fn == 8 ? 0.5 : 0.1) << "$fn " << fn;
        EXPECT_LT(e.rmsDepthDiff, previous) << "$fn " << fn;
        EXPECT_GT(e.p99DepthDiff, 0.0) << "$fn " << fn;
        EXPECT_LE(e.p99DepthDiff, e.maxDepthDiff) << "$fn " << fn;
        previous = e.rmsDepthDiff;
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lancer::bench
