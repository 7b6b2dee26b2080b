// The OpenSCAD .csg reader: hand-written exports compared, depth image against depth image,
// with the same scenes in the native JSON format; modifiers; and one error per malformed class.
#include "engine/scene/openscad_reader.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "engine/accel/accelerator.h"
#include "engine/render/image.h"
#include "engine/render/renderer.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

std::string source(const std::string& rel) { return std::string(LANCER_SOURCE_DIR) + "/" + rel; }

Scene csgText(const std::string& text, OpenScadCounts* counts = nullptr) {
    return readOpenScad(SourceText("mem.csg", text), nullptr, counts);
}

/// The brute-force depth image (primary hit distances) of a scene at w x h.
Image depthImage(const Scene& scene, int w, int h) {
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    auto acc = buildAccelerator(scene, bp);
    RenderOptions ro;
    ro.width = w;
    ro.height = h;
    ro.shading.bounces = 0;
    ro.shading.shadows = false;
    Image img(w, h);
    render(scene, *acc, ro, img);
    return img;
}

/// Pixels whose depth differs (both miss, or both hit within a relative 1e-9).
int depthMismatches(const Image& a, const Image& b, int& hits) {
    int bad = 0;
    hits = 0;
    for (size_t i = 0; i < a.depth.size(); ++i) {
        float x = a.depth[i], y = b.depth[i];
        if (std::isinf(x) || std::isinf(y)) {
            bad += std::isinf(x) != std::isinf(y);
            continue;
        }
        ++hits;
        bad += std::abs(x - y) > 1e-5f * std::max(1.0f, std::abs(x));
    }
    return bad;
}

void expectSameDepth(const std::string& csg, const std::string& json) {
    SCOPED_TRACE(csg);
    Scene a = loadScene(source(csg));
    Scene b = loadScene(source(json));
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.camera.toJson(), b.camera.toJson());
    int w = a.width / 2, h = a.height / 2;
    int hits = 0;
    EXPECT_EQ(depthMismatches(depthImage(a, w, h), depthImage(b, w, h), hits), 0);
    EXPECT_GT(hits, w * h / 20);  // the comparison is about something
}

TEST(OpenScadReader, BracketMatchesItsNativeTwin) {
    expectSameDepth("assets/openscad/bracket.csg", "tests/data/csg_bracket.json");
    OpenScadCounts c;
    readOpenScadFile(source("assets/openscad/bracket.csg"), &c);
    EXPECT_EQ(c.cubes, 1);
    EXPECT_EQ(c.cylinders, 3);
    EXPECT_EQ(c.cones, 1);
    EXPECT_EQ(c.colors, 2);
    EXPECT_EQ(c.transforms, 6);
}

TEST(OpenScadReader, ModifiersMatchTheirNativeTwin) {
    expectSameDepth("assets/openscad/modifiers.csg", "tests/data/csg_modifiers.json");
    OpenScadCounts c;
    Scene s = readOpenScadFile(source("assets/openscad/modifiers.csg"), &c);
    EXPECT_EQ(c.leftOut, 2);  // the % sphere and the * cube
    EXPECT_EQ(s.prims.size(), 5u);
    EXPECT_EQ(s.lights.size(), 2u);  // from the sidecar
}

TEST(OpenScadReader, RootModifierMakesItsSubtreeTheWholeModel) {
    OpenScadCounts c;
    Scene s = csgText(
        "cube(5);\n"
        "multmatrix([[1, 0, 0, 100], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) {\n"
        "\tcolor(\"red\") !sphere(r = 2);\n"
        "\tsphere(r = 3);\n"
        "}\n"
        "!cube(7);\n",  // a second root is not used: OpenSCAD takes the first
        &c);
    ASSERT_EQ(s.prims.size(), 1u);
    // The transforms above the root do not apply, as in OpenSCAD.
    EXPECT_EQ(s.bounds, (Box3{Vec3(-2.0), Vec3(2.0)}));
    EXPECT_EQ(s.prims[0].material, 0);
    EXPECT_EQ(c.leftOut, 3);
}

TEST(OpenScadReader, OperatorsTakeAnyNumberOfChildren) {
    // difference: the first child minus all the others.
    Scene d = csgText(
        "difference() { cube(10, true); sphere(1); cylinder(h = 20, r = 0.5, center = true); "
        "group(); }");
    EXPECT_EQ(d.prims.size(), 3u);
    EXPECT_EQ(d.tree.nodes[size_t(d.tree.root)].op, Op::Difference);
    // An empty group or operator contributes nothing; an empty intersection operand empties it.
    EXPECT_TRUE(csgText("group(); union() {} difference() {} intersection() {}").tree.empty());
    EXPECT_TRUE(csgText("intersection() { cube(1); union() {} }").tree.empty());
    EXPECT_TRUE(csgText("intersection() { cube(1); cube(0); }").tree.empty());
    EXPECT_EQ(csgText("intersection() { cube(1); *sphere(1); }").prims.size(), 1u);
    EXPECT_TRUE(csgText("difference() { group(); cube(1); }").tree.empty());
    EXPECT_EQ(csgText("difference() { *group(); cube(1); }").prims.size(),
              1u);  // * child is not there
    // A child without braces, render() as a transparent group, named transforms.
    Scene t = csgText("translate([1, 2, 3]) rotate([0, 0, 90]) scale(2) render() cube(1);");
    EXPECT_NEAR(t.bounds.lo.x, -1.0, 1e-12);
    EXPECT_NEAR(t.bounds.hi.y, 4.0, 1e-12);
    EXPECT_NEAR(t.bounds.hi.z, 5.0, 1e-12);
    Scene m = csgText("mirror([1, 0, 0]) cube([1, 2, 3]);");
    EXPECT_NEAR(m.bounds.lo.x, -1.0, 1e-12);
}

TEST(OpenScadReader, PrimitiveArgumentsAsOpenScadReadsThem) {
    auto box = [](const std::string& t) { return csgText(t).bounds; };
    EXPECT_EQ(box("cube();"), (Box3{Vec3(0.0), Vec3(1.0)}));
    EXPECT_EQ(box("cube(size = 2, center = true);"), (Box3{Vec3(-1.0), Vec3(1.0)}));
    EXPECT_EQ(box("cube([1, 2, 3]);"), (Box3{Vec3(0.0), Vec3(1, 2, 3)}));
    EXPECT_EQ(box("sphere(d = 4);"), (Box3{Vec3(-2.0), Vec3(2.0)}));
    EXPECT_EQ(box("sphere(3);"), (Box3{Vec3(-3.0), Vec3(3.0)}));
    EXPECT_EQ(box("cylinder(h = 4, r = 1, center = true);"),
              (Box3{Vec3(-1, -1, -2), Vec3(1, 1, 2)}));
    EXPECT_EQ(box("cylinder(h = 4, d = 6, r = 1);"), (Box3{Vec3(-3, -3, 0), Vec3(3, 3, 4)}));
    EXPECT_EQ(box("cylinder(4, 1, 3);"), (Box3{Vec3(-3, -3, 0), Vec3(3, 3, 4)}));
    EXPECT_EQ(box("cylinder(h = 1, r = 5, r2 = 2, $fn = 64);"),
              (Box3{Vec3(-5, -5, 0), Vec3(5, 5, 1)}));
    Scene cone = csgText("cylinder(h = 2, d1 = 4, d2 = 0, r = undef);");
    const Cone& k = std::get<Cone>(cone.prims[0].shape);
    EXPECT_EQ(k.r1, 2.0);
    EXPECT_EQ(k.r2, 0.0);
    EXPECT_FALSE(k.open);
    OpenScadCounts c;
    EXPECT_TRUE(csgText("sphere(0); cube([1, 0, 1]); cylinder(h = 0, r = 1);", &c).tree.empty());
    EXPECT_EQ(c.empty, 3);
    // Colours: rgba vectors, SVG names in any case, #hex; innermost wins.
    Scene col = csgText(
        "color(\"Red\") { cube(); color([0, 0, 1, 0.5]) sphere(); color(\"#0f0\") sphere(); }");
    ASSERT_EQ(col.prims.size(), 3u);
    EXPECT_EQ(col.materials[size_t(col.prims[0].material)].color, Vec3(1, 0, 0));
    EXPECT_EQ(col.materials[size_t(col.prims[1].material)].color, Vec3(0, 0, 1));
    EXPECT_EQ(col.materials[size_t(col.prims[2].material)].color, Vec3(0, 1, 0));
}

TEST(OpenScadReader, CameraFromTheDefaultViewWithoutASidecar) {
    Scene s = csgText("cube(10, center = true);");
    Vec3 f, r, u;
    s.camera.basis(f, r, u);
    // OpenSCAD's default view ($vpr = [55, 0, 25]) looks down 35 degrees, from -y rotated 25
    // degrees toward +x, at the centre of the bounds.
    EXPECT_NEAR(glm::degrees(std::asin(-f.z)), 35.0, 1e-9);
    EXPECT_NEAR(glm::degrees(std::atan2(-f.x, f.y)), 25.0, 1e-9);
    EXPECT_EQ(s.camera.at, Vec3(0.0));
    EXPECT_EQ(s.lights.size(), 3u);  // the default rig
    Image img = depthImage(s, 11, 11);
    EXPECT_TRUE(std::isfinite(img.depth[img.index(5, 5)]));
}

void expectCsgError(const std::string& text, const std::string& message) {
    try {
        csgText(text);
        ADD_FAILURE() << "no error for:\n" << text;
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), message);
    }
}

TEST(OpenScadReader, MalformedInputNamesFileLineAndColumn) {
    // Truncated.
    expectCsgError("group() {\n\tcube(size = [1, 2",
                   "mem.csg:2:19: unexpected end of file: missing ']' for the '[' at mem.csg:2:14");
    expectCsgError("group() {\n\tcube();\n",
                   "mem.csg:3:1: unexpected end of file: missing '}' for the '{' at mem.csg:1:9");
    expectCsgError("cube()",
                   "mem.csg:1:7: unexpected end of file: expected ';' or '{' after cube(...)");
    expectCsgError("/* never closed\ncube();",
                   "mem.csg:1:1: unterminated comment: '/*' without '*/'");
    expectCsgError("color(\"red) cube();", "mem.csg:1:7: unterminated string: no closing '\"'");
    // Unbalanced braces.
    expectCsgError("group() { cube(); }\n}\n", "mem.csg:2:1: unmatched '}'");
    expectCsgError("group() { cube(); ) }",
                   "mem.csg:1:19: expected a node name such as cube or multmatrix, got ')'");
    // Wrong arity.
    expectCsgError("multmatrix([[1, 0, 0], [0, 1, 0], [0, 0, 1]]) cube();",
                   "mem.csg:1:12: multmatrix expects a 4x4 matrix (or its first 3 rows) of "
                   "numbers, as [[a, b, c, d], ...]");
    expectCsgError("cube(size = [1, 2]);", "mem.csg:1:13: expected [x, y, z] for 'size' of cube()");
    expectCsgError("sphere(1, 2);", "mem.csg:1:11: sphere() takes at most 1 positional argument");
    expectCsgError("cube(1, size = 2);", "mem.csg:1:9: argument 'size' of cube() is given twice");
    expectCsgError("cube(sise = 2);",
                   "mem.csg:1:6: unknown argument 'sise' of cube() (expected size, center)");
    expectCsgError("cube(1) { sphere(); }", "mem.csg:1:11: cube() takes no children");
    // Not numbers.
    expectCsgError("sphere(r = \"big\");", "mem.csg:1:12: expected a number for 'r' of sphere()");
    expectCsgError("cube(center = 1);",
                   "mem.csg:1:15: expected true or false for 'center' of cube()");
    expectCsgError("sphere(r = 2 * 3);",
                   "mem.csg:1:14: expected ')' to close the arguments of sphere, got '*'");
    expectCsgError("sphere(r = x);",
                   "mem.csg:1:12: expected a value (number, true, false, undef, string or "
                   "[vector]), got 'x': expressions are not part of OpenSCAD's CSG export");
    // NaN and infinities.
    expectCsgError("sphere(r = nan);", "mem.csg:1:12: expected a finite number, got 'nan'");
    expectCsgError("cube(size = [1, -inf, 1]);",
                   "mem.csg:1:18: expected a finite number, got '-inf'");
    expectCsgError("sphere(r = 1e999);",
                   "mem.csg:1:12: number '1e999' is out of range (not a finite double)");
    expectCsgError(
        "multmatrix([[1e100, 0, 0, 0], [0, 1e100, 0, 0], [0, 0, 1e100, 0], [0, 0, 0, 1]]) "
        "multmatrix([[1e300, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) cube();",
        "mem.csg:1:82: multmatrix() gives a transform with non-finite entries");
    // Negative sizes and radii; singular transforms.
    expectCsgError("sphere(r = -1);", "mem.csg:1:12: 'r' must not be negative");
    expectCsgError("cylinder(h = 1, r1 = 1, r2 = -2);", "mem.csg:1:30: 'r2' must not be negative");
    expectCsgError("cube([1, -1, 1]);", "mem.csg:1:6: cube sizes must not be negative");
    expectCsgError("scale([1, 0, 1]) cube();",
                   "mem.csg:1:1: scale() is singular (it flattens its children to nothing)");
    expectCsgError("multmatrix([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 1, 1]]) cube();",
                   "mem.csg:1:55: the last row of a multmatrix must be [0, 0, 0, 1] (projective "
                   "transforms are not supported)");
    // Unsupported nodes, named with their position.
    expectCsgError(
        "group() {\n\tminkowski() {\n\t\tcube(size = [1, 1, 1], center = false);\n\t}\n}",
        "mem.csg:2:2: the node 'minkowski' is not supported (supported: group, union, difference, "
        "intersection, render, multmatrix, translate, rotate, scale, mirror, color, cube, sphere, "
        "cylinder, linear_extrude, rotate_extrude, square, circle, polygon, polyhedron, hull, "
        "text, import, surface)");
    // A self-intersecting polyhedron (two tetrahedra that overlap) and a hull of an extrusion
    // are refused by name.
    expectCsgError(
        "polyhedron(points = [[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4], [1, 1, 1], [5, 1, 1], "
        "[1, 5, 1], [1, 1, 5]], faces = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2], [4, 5, 6], "
        "[4, 7, 5], [4, 6, 7], [5, 7, 6]]);",
        "mem.csg:1:1: polyhedron() (its faces cut into triangles) is self-intersecting: "
        "triangles 3 and 4 cross");
    expectCsgError("hull() { sphere(r = 1); linear_extrude(height = 2) square(1); }",
                   "mem.csg:1:25: 'linear_extrude' inside hull() at mem.csg:1:1 is not "
                   "supported: Lancer takes the hull of cubes, polyhedra, spheres and "
                   "cylinders (and their groups and transforms)");
    expectCsgError("hull() { sphere(r = 1, $fn = 200); sphere(r = 2, $fn = 200); }",
                   "mem.csg:1:36: hull() at mem.csg:1:1 of more than 20000 points (its curved "
                   "children's facets) is not supported");
    expectCsgError("linear_extrude(height = 1) hull() { difference() { square(2); circle(1); } }",
                   "mem.csg:1:37: a 2D boolean inside hull() at mem.csg:1:28 is not supported: "
                   "Lancer takes the hull of squares, circles, polygons, text and their unions "
                   "and transforms");
    // Twists Lancer cannot slice as OpenSCAD does, and a torus, are refused by name.
    expectCsgError(
        "linear_extrude(height = 10, twist = 90) { translate([3, 0]) circle(r = 1); }",
        "mem.csg:1:1: linear_extrude with twist of a circle (at mem.csg:1:61) that is off the "
        "twist axis, not round or scaled unevenly: its wall is a helical sweep, which Lancer "
        "does not trace");
    expectCsgError(
        "linear_extrude(height = 10, twist = 90, scale = 0.5) { square(size = [1, 1]); }",
        "mem.csg:1:1: linear_extrude with twist = 90 and scale without 'slices': OpenSCAD's "
        "default slice count for a scaled twist (its conical-helix rule) is not implemented; "
        "give 'slices'");
    expectCsgError(
        "linear_extrude(height = 10, twist = 90, slices = 20000) { square(size = [1, 1]); }",
        "mem.csg:1:1: linear_extrude with slices = 20000: Lancer makes at most 10000 slices");
    // 10,000 slices of a comb of 40 teeth (80 convex pieces) would be 800,000 polytopes.
    std::string comb = "[[0, 0], [80, 0]";
    for (int i = 39; i >= 0; --i)
        comb += ", [" + std::to_string(2 * i + 1) + ", 1], [" + std::to_string(2 * i + 1) +
                ", 3], [" + std::to_string(2 * i) + ", 3], [" + std::to_string(2 * i) + ", 1]";
    expectCsgError("linear_extrude(height = 10, twist = 90, slices = 10000) { polygon(points = " +
                       comb + ", [0, 1]]); }",
                   "mem.csg:1:1: linear_extrude with twist: 10000 slices of 80 convex pieces is "
                   "over the 200000 polytopes Lancer makes of a twisted extrusion");
    // A circle that crosses the axis (OpenSCAD refuses it too), even one subtracted from a
    // profile that does not, and an ellipse off the axis.
    expectCsgError(
        "rotate_extrude(angle = 360, convexity = 2) {\n\tmultmatrix([[1, 0, 0, 0.5], [0, 1, 0, "
        "0], [0, 0, 1, 0], [0, 0, 0, 1]]) {\n\t\tcircle(r = 1);\n\t}\n}",
        "mem.csg:1:1: rotate_extrude(): the profile crosses the axis (x from -0.500000 to "
        "1.500000); as in OpenSCAD, all of it must lie on one side of x = 0");
    expectCsgError(
        "rotate_extrude() {\n\tdifference() {\n\t\ttranslate([2, 0]) square(size = 2, center = "
        "true);\n\t\ttranslate([1, 0]) circle(r = 1.5);\n\t}\n}",
        "mem.csg:1:1: rotate_extrude() of the circle at mem.csg:4:21 (centre x = 1.000000, radius "
        "1.500000) crosses the axis; as in OpenSCAD, all of it must lie on one side of x = 0");
    expectCsgError(
        "rotate_extrude() {\n\ttranslate([3, 0]) scale([1, 2]) circle(r = 1);\n}",
        "mem.csg:1:1: rotate_extrude() of the ellipse at mem.csg:2:34 off the axis sweeps a ring "
        "of elliptic section, which Lancer does not model (circles off the axis make tori)");
    // A drawing with no solid says what Lancer traces.
    expectCsgError("circle(r = 1);",
                   "mem.csg:1:1: the model is 2D (its first 2D node is 'circle') and has no "
                   "solid: Lancer traces solids; extrude the drawing with linear_extrude or "
                   "rotate_extrude to render it");
    expectCsgError(
        "color(\"blurple\") cube();",
        "mem.csg:1:7: unknown colour name 'blurple' (OpenSCAD accepts the SVG colour names)");
    expectCsgError("x = 3;",
                   "mem.csg:1:3: assignments ('x = ...') are not part of OpenSCAD's CSG export; "
                   "export the model with 'openscad -o model.csg'");
    expectCsgError("cube(\x01);", "mem.csg:1:6: unexpected character '\\x01'");
    // Deep nesting is refused before the recursion can exhaust the stack.
    std::string deep, vec;
    for (int i = 0; i < 100000; ++i) deep += "group() ";
    expectCsgError(deep + "cube();", "mem.csg:1:4009: nesting deeper than 500 levels is refused");
    for (int i = 0; i < 100000; ++i) vec += "[";
    expectCsgError("cube(size = " + vec + ");",
                   "mem.csg:1:513: nesting deeper than 500 levels is refused");
}

/// Two models have the same bounds (within a hair: a polytope's box is grown by one) and the
/// same depth image from the first one's camera, pixel for pixel; they hit something.
/// With `bounds` false only the images are compared (a difference keeps its first operand's box).
/// `options` read the model (the twin is read exactly).
void expectSameSolid(const std::string& model, const std::string& twin, bool bounds = true,
                     const ReadOptions& options = {}) {
    SCOPED_TRACE(model);
    const Scene a = readOpenScad(SourceText("mem.csg", model), nullptr, nullptr, options);
    Scene b = csgText(twin);
    for (int k = 0; k < 3 && bounds; ++k) {
        EXPECT_NEAR(a.bounds.lo[k], b.bounds.lo[k], 1e-6 * a.scale());
        EXPECT_NEAR(a.bounds.hi[k], b.bounds.hi[k], 1e-6 * a.scale());
    }
    b.camera = a.camera;
    int hits = 0;
    EXPECT_EQ(depthMismatches(depthImage(a, 64, 48), depthImage(b, 64, 48), hits), 0);
    EXPECT_GT(hits, 64 * 48 / 20);
}

TEST(OpenScadExtrusions, EachEqualsItsSolidTwin) {
    const std::string ex = "linear_extrude(height = 3, center = false, convexity = 1, ";
    // An extruded square is a box; an extruded circle a cylinder (centred: both ways).
    expectSameSolid(ex + "scale = [1, 1]) { square(size = [2, 4], center = false); }",
                    "cube(size = [2, 4, 3], center = false);");
    expectSameSolid("linear_extrude(height = 5, center = true, scale = [1, 1]) { circle(r = 1); }",
                    "cylinder(h = 5, r1 = 1, r2 = 1, center = true);");
    // With scale: a frustum; of a circle, a cone.
    expectSameSolid(ex + "scale = [0.5, 0.5]) { circle(r = 2); }",
                    "cylinder(h = 3, r1 = 2, r2 = 1, center = false);");
    // A polygon with a hole (two paths).
    expectSameSolid(ex + "scale = [1, 1]) { polygon(points = [[0, 0], [4, 0], [4, 4], [0, 4], "
                         "[1, 1], [3, 1], [3, 3], [1, 3]], paths = [[0, 1, 2, 3], [4, 5, 6, "
                         "7]], convexity = 1); }",
                    "difference() { cube(size = [4, 4, 3]); multmatrix([[1, 0, 0, 1], [0, 1, 0, "
                    "1], [0, 0, 1, -1], [0, 0, 0, 1]]) { cube(size = [2, 2, 5]); } }");
    // 2D booleans: a square minus a circle, extruded, is the box minus the cylinder.
    expectSameSolid(ex + "scale = [1, 1]) { difference() { square(size = [4, 4], center = true); "
                         "circle(r = 1); } }",
                    "difference() { multmatrix([[1, 0, 0, -2], [0, 1, 0, -2], [0, 0, 1, 0], [0, "
                    "0, 0, 1]]) { cube(size = [4, 4, 3]); } multmatrix([[1, 0, 0, 0], [0, 1, 0, "
                    "0], [0, 0, 1, -1], [0, 0, 0, 1]]) { cylinder(h = 5, r1 = 1, r2 = 1); } }");
    // A mesh cube is a box; the hull of two equal spheres a capsule; of eight, a rounded box.
    expectSameSolid(
        "polyhedron(points = [[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0], [0, 0, 1], "
        "[2, 0, 1], [2, 3, 1], [0, 3, 1]], faces = [[0, 1, 2, 3], [4, 7, 6, 5], [0, "
        "4, 5, 1], [1, 5, 6, 2], [2, 6, 7, 3], [3, 7, 4, 0]]);",
        "cube(size = [2, 3, 1]);");
    expectSameSolid("hull() { sphere(r = 1); translate([4, 0, 0]) sphere(r = 1); }",
                    "union() { sphere(r = 1); translate([4, 0, 0]) sphere(r = 1); rotate([0, "
                    "90, 0]) cylinder(h = 4, r = 1); }");
    expectSameSolid("hull() { cube(size = [2, 2, 2]); translate([3, 0, 0]) cube(size = 2); }",
                    "cube(size = [5, 2, 2]);");
    // rotate_extrude of a square off the axis: a cylinder shell.
    expectSameSolid(
        "rotate_extrude(angle = 360, convexity = 2) { multmatrix([[1, 0, 0, 2], [0, "
        "1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) { square(size = [1, 3]); } }",
        "difference() { cylinder(h = 3, r1 = 3, r2 = 3); multmatrix([[1, 0, 0, 0], "
        "[0, 1, 0, 0], [0, 0, 1, -1], [0, 0, 0, 1]]) { cylinder(h = 5, r1 = 2, r2 = "
        "2); } }");
}

TEST(OpenScadExtrusions, CirclesOffTheAxisRevolveIntoTori) {
    OpenScadCounts n;
    // A circle at x = 3, y = 1 (rotated in the plane, mirrored to the other side: the same
    // circle) makes the torus R = 3, r = 1 one unit up; a circle on the axis a sphere.
    for (const char* profile :
         {"translate([3, 1]) circle(r = 1);", "translate([3, 1]) rotate(30) circle(r = 1);",
          "mirror([1, 0]) translate([3, 1]) circle(d = 2);"}) {
        SCOPED_TRACE(profile);
        const Scene s = csgText(std::string("rotate_extrude(angle = 360) { ") + profile + " }", &n);
        ASSERT_EQ(s.prims.size(), 1u);
        const Torus* t = std::get_if<Torus>(&s.prims[0].shape);
        ASSERT_NE(t, nullptr);
        EXPECT_NEAR(t->R, 3.0, 1e-12);
        EXPECT_NEAR(t->r, 1.0, 1e-12);
        EXPECT_NEAR(s.bounds.lo.z, 0.0, 1e-9);
        EXPECT_NEAR(s.bounds.hi.x, 4.0, 1e-9);
        EXPECT_EQ(n.tori, 1);
    }
    // A circle on the axis may only be subtracted (else the profile crosses the axis): turned
    // in the plane, it still makes a sphere.
    const Scene ball = csgText(
        "rotate_extrude() { difference() { translate([0, -2]) square(size = [3, 4]); rotate(30) "
        "circle(r = 1); } }",
        &n);
    ASSERT_EQ(ball.prims.size(), 2u);  // the square's cylinder and the circle's sphere
    EXPECT_TRUE(std::holds_alternative<Sphere>(ball.prims[1].shape));
    EXPECT_EQ(n.tori, 0);
    // Touching the axis: the horn torus.
    const Scene horn = csgText("rotate_extrude() { translate([1, 0]) circle(r = 1); }");
    ASSERT_EQ(horn.prims.size(), 1u);
    EXPECT_TRUE(std::holds_alternative<Torus>(horn.prims[0].shape));
    // The torus is its JSON twin, pixel for pixel.
    Scene js = readJsonScene(SourceText("t.json", R"({"scene": {"torus": {"major": 3, "minor": 1},
                                            "transform": [{"translate": [0, 0, 1]}]}})"));
    const Scene csg = csgText("rotate_extrude() { translate([3, 1]) circle(r = 1); }");
    js.camera = csg.camera;
    int hits = 0;
    EXPECT_EQ(depthMismatches(depthImage(csg, 64, 48), depthImage(js, 64, 48), hits), 0);
    EXPECT_GT(hits, 64 * 48 / 20);
}

TEST(OpenScadExtrusions, PartialSweepOfACircleIsTheTorusCutByTheWedge) {
    // Rays down through the tube's centre circle at a polar angle: inside the sweep they hit
    // the tube's top (z = 1), outside they miss.
    auto hitsAt = [](const Scene& s, double degrees) {
        const double a = glm::radians(degrees);
        const Ray ray{{3.0 * std::cos(a), 3.0 * std::sin(a), 10.0}, {0, 0, -1}};
        auto brute = buildAccelerator(s, BuildParams{});
        TraceContext ctx(s.prims.size(), s.tree.depth());
        NullObserver obs;
        ctx.beginRay();
        Hit h;
        if (!brute->intersect(ray, 0.0, kInf, ctx, obs, h)) return false;
        EXPECT_NEAR(h.t, 9.0, 1e-9) << degrees;
        return true;
    };
    const Scene quarter =
        csgText("rotate_extrude(angle = 90) { translate([3, 0]) circle(r = 1); }");
    EXPECT_TRUE(hitsAt(quarter, 45.0));
    EXPECT_TRUE(hitsAt(quarter, 5.0));
    EXPECT_FALSE(hitsAt(quarter, 120.0));
    EXPECT_FALSE(hitsAt(quarter, -30.0));
    const Scene most = csgText("rotate_extrude(angle = 270) { translate([3, 0]) circle(r = 1); }");
    EXPECT_TRUE(hitsAt(most, 120.0));
    EXPECT_TRUE(hitsAt(most, 260.0));
    EXPECT_FALSE(hitsAt(most, -60.0));
    const Scene back = csgText("rotate_extrude(angle = -90) { translate([3, 0]) circle(r = 1); }");
    EXPECT_TRUE(hitsAt(back, -45.0));
    EXPECT_FALSE(hitsAt(back, 45.0));
}

TEST(OpenScadExtrusions, SchemesAgreeWithBruteForce) {
    // Extrusions and revolutions under CSG, turned: every scheme, ray for ray.
    const Scene s = csgText(
        "difference() { linear_extrude(height = 2, center = true, scale = [0.6, 0.6]) { "
        "polygon(points = [[0, 0], [3, 0], [3, 2], [1.5, 3], [0, 2]], paths = [[0, 1, 2, 3, "
        "4]]); } multmatrix([[0.8, -0.6, 0, 1], [0.6, 0.8, 0, 1], [0, 0, 1, 0], [0, 0, 0, 1]]) "
        "{ rotate_extrude(angle = 360) { multmatrix([[1, 0, 0, 0.3], [0, 1, 0, -2], [0, 0, 1, "
        "0], [0, 0, 0, 1]]) { square(size = [0.4, 4]); } } } }\n"
        "multmatrix([[1, 0, 0, 5], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) { "
        "rotate_extrude(angle = 360) { polygon(points = [[0, 0], [2, 0], [1, 2]]); } }\n"
        "difference() { translate([0, 5, 0]) hull() { sphere(r = 0.5); translate([2, 0, 0]) "
        "sphere(r = 0.5); translate([0, 2, 1]) sphere(r = 0.5); translate([1, 1, 2]) sphere(r = "
        "0.5); } translate([1, 6, 0.5]) polyhedron(points = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], "
        "[0, -1, 0], [0, 0, 1.5]], faces = [[0, 1, 2, 3], [4, 1, 0], [4, 2, 1], [4, 3, 2], [4, "
        "0, 3]]); }\n"
        "translate([-4, 0, 0]) difference() { rotate([60, 0, 0]) rotate_extrude(angle = 250) "
        "translate([2, 0]) circle(r = 0.7); cube(size = [2, 6, 1], center = true); }");
    const std::vector<Ray> rays = test::randomRays(s, 5, 3000);
    test::expectEverySchemeSame(s, rays);
}

/// The twisted rectangle's exact section at height z: the half-sizes (a, b) turned by -twist
/// z / h (OpenSCAD turns clockwise seen from +z); a point's distance to its outline in 2D.
double twistedOutlineDistance(const Vec3& p, double a, double b, double twist, double h) {
    const double th = -glm::radians(twist) * p.z / h, c = std::cos(th), s = std::sin(th);
    // The point in the rectangle's own frame: turned back by th.
    const glm::dvec2 q(c * p.x + s * p.y, -s * p.x + c * p.y);
    const glm::dvec2 d = glm::abs(q) - glm::dvec2(a, b);
    if (d.x <= 0.0 && d.y <= 0.0) return -std::max(d.x, d.y);  // inside: to the nearer side
    return glm::length(glm::max(d, glm::dvec2(0.0)));
}

TEST(OpenScadTwist, SlicesFollowOpenScadsRule) {
    OpenScadCounts n;
    // $fa 12: ceil(90 / 12) = 8 slices, fewer than the helix rule's ceil(26.6 / 2) = 14.
    csgText(
        "linear_extrude(height = 20, twist = 90, $fn = 0, $fa = 12, $fs = 2) { "
        "square(size = [20, 10], center = true); }",
        &n);
    EXPECT_EQ(n.twistedExtrudes, 1);
    EXPECT_EQ(n.twistSlices, 8);
    // $fn > 0: ceil(twist / 360 $fn); 'slices' given wins; at least ceil(twist / 120).
    OpenScadCounts f, g, t;
    csgText("linear_extrude(height = 5, twist = 90, $fn = 12) { square(size = [2, 1]); }", &f);
    EXPECT_EQ(f.twistSlices, 3);
    csgText("linear_extrude(height = 5, twist = 90, slices = 5.7) { square(size = [2, 1]); }", &g);
    EXPECT_EQ(g.twistSlices, 5);
    csgText("linear_extrude(height = 5, twist = 600, $fn = 1) { square(size = [2, 1]); }", &t);
    EXPECT_EQ(t.twistSlices, 5);
}

/// A 20 x 10 rectangle twisted by 90 degrees over a height of 20 (OpenSCAD's 8 slices).
Scene twistedRectangle(OpenScadCounts* n) {
    return csgText(
        "linear_extrude(height = 20, twist = 90, $fn = 0, $fa = 12, $fs = 2) { square(size = "
        "[20, 10], center = true); }",
        n);
}

TEST(OpenScadTwist, EveryHitLiesWithinTheStatedBoundOfTheExactTwistedSurface) {
    OpenScadCounts n;
    const double twist = 90.0, h = 20.0, a = 10.0, b = 5.0;
    const Scene s = twistedRectangle(&n);
    // OpenSCAD's 8 slices, each cut into 16 (the hull's first-order error, 1.1 at pi/16 a
    // slice, is over 0.2% of the radius); the bound for a turn of pi/128 of the piece centred
    // on the axis, its corners 11.18 from it: 11.18 (pi/128)^2 / 8 + 11.18 (pi/128) / 2.
    EXPECT_EQ(n.twistSlices, 8);
    EXPECT_EQ(n.twistSubSlices, 16);
    const double dA = glm::radians(twist) / 128.0, w = std::hypot(a, b);
    EXPECT_NEAR(n.twistError, w * dA * dA / 8.0 + w * dA / 2.0, 1e-9);
    EXPECT_EQ(s.modelError, n.twistError) << "the bound the scene carries to --stats";
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    auto brute = buildAccelerator(s, bp);
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    double worst = 0.0;
    int hits = 0;
    // Horizontal rays towards the axis from every side, at heights through the whole extrusion.
    for (int k = 0; k < 40; ++k)
        for (int j = 0; j < 48; ++j) {
            const double z = 0.25 + 19.5 * k / 39.0, phi = 2.0 * M_PI * j / 48.0;
            const Vec3 dir(std::cos(phi), std::sin(phi), 0.0);
            const Vec3 side(-dir.y, dir.x, 0.0);
            const double off = -9.0 + 18.0 * ((k * 7 + j) % 13) / 12.0;
            Ray r{Vec3(0.0, 0.0, z) - 40.0 * dir + off * side, dir};
            Hit hit;
            ctx.beginRay();
            if (!brute->intersect(r, 0.0, kInf, ctx, obs, hit)) continue;
            ++hits;
            const Vec3 p = r.at(hit.t);
            const double d = twistedOutlineDistance(p, a, b, twist, h);
            worst = std::max(worst, d);
            EXPECT_LE(d, n.twistError + 1e-9) << r.toString();
        }
    EXPECT_GT(hits, 40 * 48 / 2);
    // The bound is not vacuous: the slices' walls do stray by a good part of it.
    EXPECT_GT(worst, n.twistError / 4.0);
}

TEST(OpenScadTwist, OpenScadsOwnMeshLiesWithinTheStatedBoundOfTheExactTwistedSurface) {
    // OpenSCAD meshes the same twist as 8 slices whose wall quads (an edge at one end, the same
    // edge turned pi/16 at the other) are cut into two triangles: scripts/cgal-check adds how
    // far they stray (openscad_mesh_error) to its tolerance. Bound: rho (pi/16)^2 / 8 for the
    // corners' arcs plus the longest edge (20) times pi/16 / 4 for the cut quads.
    OpenScadCounts n;
    const double twist = 90.0, h = 20.0, a = 10.0, b = 5.0;
    const Scene s = twistedRectangle(&n);
    const double d = glm::radians(twist) / 8.0, rho = std::hypot(a, b);
    // (times 1 + 1e-9: the transform's stretch is rounded up)
    EXPECT_NEAR(n.openScadTwistMeshError, rho * d * d / 8.0 + 20.0 * d / 4.0, 1e-8);
    EXPECT_EQ(s.openScadMeshError, n.openScadTwistMeshError) << "the bound --stats reports";
    const glm::dvec2 corner[4] = {{-a, -b}, {a, -b}, {a, b}, {-a, b}};
    auto at = [&](int c, int slice) {  // corner c of the section at the slice's bottom
        const double th = -glm::radians(twist) * slice / 8.0;
        const glm::dvec2 q = glm::dvec2(std::cos(th) * corner[c].x - std::sin(th) * corner[c].y,
                                        std::sin(th) * corner[c].x + std::cos(th) * corner[c].y);
        return Vec3(q, h * slice / 8.0);
    };
    double worst = 0.0;
    // Both cuts of every quad (whichever diagonal OpenSCAD takes), sampled on a grid.
    for (int k = 0; k < 8; ++k)
        for (int c = 0; c < 4; ++c) {
            const Vec3 p0 = at(c, k), p1 = at((c + 1) % 4, k), q0 = at(c, k + 1),
                       q1 = at((c + 1) % 4, k + 1);
            const Vec3 tris[4][3] = {{p0, p1, q1}, {p0, q1, q0}, {p0, p1, q0}, {p1, q1, q0}};
            for (const auto& t : tris)
                for (int i = 0; i <= 20; ++i)
                    for (int j = 0; i + j <= 20; ++j) {
                        const Vec3 p =
                            t[0] + (t[1] - t[0]) * (i / 20.0) + (t[2] - t[0]) * (j / 20.0);
                        const double dist = twistedOutlineDistance(p, a, b, twist, h);
                        worst = std::max(worst, dist);
                        EXPECT_LE(dist, n.openScadTwistMeshError + 1e-9);
                    }
        }
    // Not vacuous: OpenSCAD's triangles stray by most of it (0.98 of 1.04).
    EXPECT_GT(worst, n.openScadTwistMeshError / 2.0);
}

TEST(OpenScadTwist, SliverPiecesKeepEveryFaceOfTheirHull) {
    // example009 (OpenSCAD's examples, CC0; tests/data): its fan, a cross with a round hole
    // cut into trapezoids, has sliver pieces whose centre lies within rounding of their long
    // edges. Taking an edge's outward side from that centre lost faces of their slices' hulls,
    // which then reached outside their boxes: the schemes, clipping by the boxes, missed what
    // brute force hit (259 of 96x96 pixels for the regular scheme, 9 for the BVH, 2026-12-06).
    const Scene s = readOpenScadFile(source("tests/data/example009.csg"));
    for (const Primitive& p : s.prims) {
        const auto* pt = std::get_if<Polytope>(&p.shape);
        if (!pt) continue;
        // Every corner of the polytope (three of its planes meeting) lies in its box.
        const size_t n = pt->planes.size();
        for (size_t a = 0; a < n; ++a)
            for (size_t b = a + 1; b < n; ++b)
                for (size_t c = b + 1; c < n; ++c) {
                    const glm::dvec4 &u = pt->planes[a], &v = pt->planes[b], &w = pt->planes[c];
                    const glm::dmat3 m = glm::transpose(glm::dmat3(Vec3(u), Vec3(v), Vec3(w)));
                    if (std::abs(glm::determinant(m)) < 1e-9) continue;
                    const Vec3 x = glm::inverse(m) * Vec3(u.w, v.w, w.w);
                    bool inside = true;
                    for (const glm::dvec4& q : pt->planes)
                        inside =
                            inside && glm::dot(Vec3(q), x) <= q.w + 1e-7 * (1.0 + std::abs(q.w));
                    if (!inside) continue;
                    const Vec3 pad =
                        1e-6 * (glm::abs(pt->bounds.lo) + glm::abs(pt->bounds.hi) + 1.0);
                    ASSERT_TRUE(glm::all(glm::greaterThanEqual(x, pt->bounds.lo - pad)) &&
                                glm::all(glm::lessThanEqual(x, pt->bounds.hi + pad)))
                        << p.toString() << " has a corner outside its box";
                }
    }
    test::expectEverySchemeSame(s, test::pixelRays(s, 24, 24));
}

TEST(OpenScadTwist, SchemesAgreeWithBruteForce) {
    // A twisted L (two convex pieces), a twisted scaled square minus a twisted round hole on
    // the axis (exact), turned: every scheme, ray for ray.
    const Scene s = csgText(
        "linear_extrude(height = 4, twist = 120, slices = 6) { polygon(points = [[0, 0], [3, 0], "
        "[3, 1], [1, 1], [1, 3], [0, 3]]); }\n"
        "multmatrix([[0.8, -0.6, 0, 5], [0.6, 0.8, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]) { "
        "linear_extrude(height = 3, center = true, twist = -200, slices = 9, scale = 0.6) { "
        "difference() { square(size = [3, 2], center = true); circle(r = 0.5); } } }");
    const std::vector<Ray> rays = test::randomRays(s, 11, 3000);
    test::expectEverySchemeSame(s, rays);
}

/// A DXF file of `entities` (group code and value lines) with an optional BLOCKS section.
std::string dxfText(const std::string& entities, const std::string& blocks = "") {
    std::string s;
    if (!blocks.empty()) s += "0\nSECTION\n2\nBLOCKS\n" + blocks + "0\nENDSEC\n";
    return s + "0\nSECTION\n2\nENTITIES\n" + entities + "0\nENDSEC\n0\nEOF\n";
}

std::string dxfLine(const std::string& layer, glm::dvec2 a, glm::dvec2 b) {
    auto num = [](double v) { return std::to_string(v); };
    return "0\nLINE\n8\n" + layer + "\n10\n" + num(a.x) + "\n20\n" + num(a.y) + "\n11\n" +
           num(b.x) + "\n21\n" + num(b.y) + "\n";
}

/// Writes `text` to a fresh file in the test's temporary folder and returns its path.
std::string writeTemp(const std::string& name, const std::string& text) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("lancer_dxf_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::filesystem::path p = dir / name;
    std::ofstream(p) << text;
    return p.string();
}

TEST(OpenScadDxf, LayersLinesCirclesPolylinesAndBlocksMatchTheirPolygonTwins) {
    // Layer "a": a 4 x 3 rectangle of three LINEs, open (OpenSCAD closes it by its ends), a
    // CIRCLE hole cut into 8 by $fn; layer "b": a closed LWPOLYLINE; layer "c": a block's
    // triangle inserted at (10, 0), turned 90 degrees and scaled 2. A LINE elsewhere is ignored.
    const std::string ents =
        dxfLine("a", {0, 0}, {4, 0}) + dxfLine("a", {4, 0}, {4, 3}) + dxfLine("a", {4, 3}, {0, 3}) +
        "0\nCIRCLE\n8\na\n10\n2\n20\n1.5\n40\n1\n" +
        "0\nLWPOLYLINE\n8\nb\n90\n3\n70\n1\n10\n0\n20\n5\n10\n3\n20\n5\n10\n0\n20\n7\n" +
        "0\nINSERT\n8\nc\n2\ntri\n10\n10\n20\n0\n41\n2\n42\n2\n50\n90\n" +
        dxfLine("other", {-5, -5}, {-6, -6});
    const std::string blocks = "0\nBLOCK\n8\n0\n2\ntri\n10\n0\n20\n0\n" +
                               dxfLine("0", {0, 0}, {1, 0}) + dxfLine("0", {1, 0}, {0, 1}) +
                               dxfLine("0", {0, 1}, {0, 0}) + "0\nENDBLK\n";
    const std::string path = writeTemp("shapes.dxf", dxfText(ents, blocks));
    auto imp = [&](const std::string& layer, const std::string& extra = "") {
        return "linear_extrude(height = 2) { import(file = \"" + path + "\", layer = \"" + layer +
               "\"" + extra + ", $fn = 8); }";
    };
    std::string octagon;
    for (int i = 0; i < 8; ++i) {
        const double t = 2.0 * M_PI * i / 8.0;
        octagon += ", [" + std::to_string(2.0 + std::cos(t)) + ", " +
                   std::to_string(1.5 + std::sin(t)) + "]";
    }
    expectSameSolid(imp("a"),
                    "linear_extrude(height = 2) { polygon(points = [[0, 0], [4, 0], "
                    "[4, 3], [0, 3]" +
                        octagon + "], paths = [[0, 1, 2, 3], [4, 5, 6, 7, 8, 9, 10, 11]]); }");
    expectSameSolid(imp("b"),
                    "linear_extrude(height = 2) { polygon(points = [[0, 5], [3, 5], [0, 7]]); }");
    // The block's (0, 0), (1, 0), (0, 1), scaled 2, turned 90 degrees, moved to (10, 0).
    expectSameSolid(imp("c"),
                    "linear_extrude(height = 2) { polygon(points = [[10, 0], [10, 2], "
                    "[8, 0]]); }");
    // origin and scale: (p - origin) scale.
    expectSameSolid(imp("b", ", origin = [0, 5], scale = 2"),
                    "linear_extrude(height = 2) { polygon(points = [[0, 0], [6, 0], [0, 4]]); }");
    OpenScadCounts n;
    csgText(imp("a"), &n);
    EXPECT_EQ(n.dxfImports, 1);
    EXPECT_EQ(n.dxfOpenChains, 1);
    // Every scheme, ray for ray, on the layers together under a difference.
    const Scene s =
        csgText("difference() { " + imp("") + " translate([2, 1.5, 1]) sphere(r = 1.2); }");
    test::expectEverySchemeSame(s, test::randomRays(s, 13, 2000));
}

TEST(OpenScadDxf, FilesAreFoundBesideTheCsgAndBadOnesAreNamed) {
    const std::string dxf = writeTemp(
        "beside.dxf", dxfText(dxfLine("0", {0, 0}, {2, 0}) + dxfLine("0", {2, 0}, {0, 2}) +
                              dxfLine("0", {0, 2}, {0, 0})));
    const std::string csg =
        writeTemp("beside.csg", "linear_extrude(height = 1) { import(file = \"beside.dxf\"); }\n");
    const Scene s = readOpenScadFile(csg);
    EXPECT_EQ(s.livePrimitives().size(), 1u);
    EXPECT_NEAR(s.bounds.hi.x, 2.0, 1e-6);
    // A missing file is named with the import's file argument's position.
    expectCsgError("linear_extrude(height = 1) { import(file = \"/no/such.dxf\"); }",
                   "mem.csg:1:44: import(): /no/such.dxf: no such file");
    // A malformed DXF names its own line.
    const std::string bad = writeTemp("bad.dxf",
                                      "0\nSECTION\n2\nENTITIES\n0\nLINE\n10\n"
                                      "x1\n0\nENDSEC\n0\nEOF\n");
    expectCsgError("linear_extrude(height = 1) { import(file = \"" + bad + "\"); }",
                   "mem.csg:1:44: import(): " + bad +
                       ":8:1: expected a number for DXF group code 10, found 'x1'");
    expectCsgError("linear_extrude(height = 1) { import(file = \"" + bad.substr(0, bad.size() - 7) +
                       "/missing.stl\"); }",
                   "mem.csg:1:44: import() of '" + bad.substr(0, bad.size() - 7) +
                       "/missing.stl' inside a 2D context: only DXF drawings are 2D imports");
    // A curve cut finer than a polygon may be is refused, not made.
    const std::string fine =
        writeTemp("fine.dxf", dxfText("0\nCIRCLE\n8\n0\n10\n0\n20\n0\n40\n1\n"));
    expectCsgError("linear_extrude(height = 1) { import(file = \"" + fine + "\", $fn = 1e20); }",
                   "mem.csg:1:44: import(): " + fine +
                       ":6:1: a CIRCLE of 1000000000 segments (by $fn, $fa, $fs): Lancer cuts a "
                       "curve into at most 20000");
    // An arc segment of a polyline is refused, not drawn straight.
    const std::string bulge = writeTemp(
        "bulge.dxf",
        dxfText("0\nLWPOLYLINE\n8\n0\n90\n2\n70\n1\n10\n0\n20\n0\n42\n0.5\n10\n1\n20\n0\n"));
    expectCsgError("linear_extrude(height = 1) { import(file = \"" + bulge + "\"); }",
                   "mem.csg:1:44: import(): " + bulge +
                       ":18:1: a polyline with an arc (bulge) segment is not supported: OpenSCAD "
                       "reads its ends as a straight edge");
    // A device is refused, not read for ever.
    const std::string zero = dxf.substr(0, dxf.size() - 10) + "zero.dxf";
    std::filesystem::remove(zero);
    std::filesystem::create_symlink("/dev/zero", zero);
    expectCsgError("linear_extrude(height = 1) { import(file = \"" + zero + "\"); }",
                   "mem.csg:1:44: import(): " + zero + ": not a regular file");
    expectCsgError("import(file = \"part.stl\");",
                   "mem.csg:1:15: import(): part.stl: no such file");
    expectCsgError("import(file = \"part.3mf\");",
                   "mem.csg:1:1: import() of 'part.3mf': Lancer imports STL and OFF meshes and "
                   "DXF drawings (inside an extrusion); other formats are not supported");
}

TEST(OpenScadOffset, RoundOffsetEqualsItsMinkowskiTwin) {
    const std::string ex =
        "linear_extrude(height = 3, center = false, convexity = 1, scale = [1, "
        "1]) { ";
    // offset(r) of a square: the square grown by r with round corners, exactly.
    expectSameSolid(ex + "offset(r = 1, $fn = 40) { square(size = [2, 4]); } }",
                    "union() { translate([-1, 0, 0]) cube(size = [4, 4, 3]); translate([0, -1, "
                    "0]) cube(size = [2, 6, 3]); cylinder(h = 3, r = 1); translate([2, 0, 0]) "
                    "cylinder(h = 3, r = 1); translate([2, 4, 0]) cylinder(h = 3, r = 1); "
                    "translate([0, 4, 0]) cylinder(h = 3, r = 1); }");
    // Of a circle: the circle of radius + r; under a uniform scale, r scales too.
    expectSameSolid(ex + "offset(r = 0.5) { circle(r = 1.5); } }", "cylinder(h = 3, r = 2);");
    expectSameSolid(ex + "scale([2, 2, 1]) offset(r = 0.5) { circle(r = 1); } }",
                    "cylinder(h = 3, r = 3);");
    // offset(r < 0): a circle shrinks; a square shrinks with its corners still square.
    expectSameSolid(ex + "offset(r = -0.5) { circle(r = 1.5); } }", "cylinder(h = 3, r = 1);");
    expectSameSolid(ex + "offset(r = -0.5) { square(size = [2, 4]); } }",
                    "translate([0.5, 0.5, 0]) cube(size = [1, 3, 3]);", false);
    // An L's reflex corner rounds: eroded by 0.5, the L (4 x 4 minus its 2 x 2 corner) is its
    // two arms' cores and, at the reflex corner (2, 2), the square [1.5, 2]^2 minus the disk of
    // radius 0.5 around it.
    expectSameSolid(ex + "offset(r = -0.5) { polygon(points = [[0, 0], [4, 0], [4, 2], [2, 2], "
                         "[2, 4], [0, 4]]); } }",
                    "union() { translate([0.5, 0.5, 0]) cube(size = [1, 3, 3]); translate([0.5, "
                    "0.5, 0]) cube(size = [3, 1, 3]); difference() { translate([1.5, 1.5, 0]) "
                    "cube(size = [0.5, 0.5, 3]); translate([2, 2, -1]) cylinder(h = 5, r = 0.5); "
                    "} }",
                    false);
    // Of a union: the union of the offsets (two far squares stay two rounded squares).
    const Scene s = csgText(ex +
                            "offset(r = 1) { square(size = [2, 2]); translate([10, 0]) "
                            "square(size = [2, 2]); } }");
    const Scene far = csgText(ex + "square(size = [2, 2]); }");
    EXPECT_NEAR(s.bounds.lo.x, -1.0, 1e-6);
    EXPECT_NEAR(s.bounds.hi.x, 13.0, 1e-6);
    EXPECT_NEAR(far.bounds.hi.x, 2.0, 1e-6);
}

TEST(OpenScadOffset, UnsupportedOffsetsAreRefusedByName) {
    const std::string ex = "linear_extrude(height = 3) { ";
    expectCsgError(ex + "offset(r = -1) { square(2); circle(1); } }",
                   "mem.csg:1:30: offset(r < 0) is supported of one square, polygon or circle "
                   "only (its child made at mem.csg:1:58 is another shape or a boolean)");
    expectCsgError(ex + "offset(delta = -1) { square(2); translate([5, 0]) square(2); } }",
                   "mem.csg:1:30: offset(delta < 0) is supported of one square, polygon, glyph "
                   "or DXF drawing only (the shapes made at mem.csg:1:80 and mem.csg:1:51)");
    expectCsgError(ex + "offset(delta = 1) { square(2); translate([1, 1]) square(2); } }",
                   "mem.csg:1:30: offset(delta) of outlines that cross or touch (of the shapes "
                   "made at mem.csg:1:79, ...) is not supported: their region's outline is not "
                   "their paths");
    expectCsgError(ex + "offset(delta = 1) { square(4); translate([1, 1]) square(1); } }",
                   "mem.csg:1:30: offset(delta) of the shape made at mem.csg:1:79, which lies "
                   "inside the shape made at mem.csg:1:50, is not supported: their union's "
                   "outline is not theirs");
    expectCsgError(ex + "offset(delta = 1) { square(2); translate([5, 0]) circle(1); } }",
                   "mem.csg:1:30: offset(delta) of a circle (at mem.csg:1:79) beside other "
                   "shapes is not supported (only of one circle)");
    expectCsgError(ex + "offset(delta = 1) offset(r = 1) square(2); }",
                   "mem.csg:1:30: offset(delta) of the shape made at mem.csg:1:48 (a boolean or "
                   "an offset) is not supported: Lancer offsets by delta squares, polygons, "
                   "text, DXF drawings and circles");
    expectCsgError(ex + "offset(r = 1) difference() { square(2); circle(1); } }",
                   "mem.csg:1:30: offset() of an intersection or difference (made at "
                   "mem.csg:1:44) is not supported (only of unions)");
    expectCsgError(ex + "offset(r = 1) scale([2, 1]) circle(1); }",
                   "mem.csg:1:30: offset() of an ellipse (the circle at mem.csg:1:58 under a "
                   "non-uniform scale) is not supported");
}

TEST(OpenScadOffset, DeltaOffsetsEqualTheirPolygonTwins) {
    const std::string ex = "linear_extrude(height = 3) { ";
    // A square grown by delta is the larger square (mitred corners), both ways round.
    expectSameSolid(ex + "offset(delta = 1, chamfer = false) { square(size = [2, 4]); } }",
                    "translate([-1, -1, 0]) cube(size = [4, 6, 3]);");
    expectSameSolid(ex + "offset(delta = 1) { mirror([1, 0]) square(size = [2, 4]); } }",
                    "translate([-3, -1, 0]) cube(size = [4, 6, 3]);");
    // Chamfered, each corner is cut square to its bisector at distance 1: along the moved
    // edges by tan(22.5 degrees) = sqrt(2) - 1 past the corner.
    const double t = std::sqrt(2.0) - 1.0;
    auto pt = [](double x, double y) {
        char buf[80];
        std::snprintf(buf, sizeof buf, "[%.17g, %.17g]", x, y);
        return std::string(buf);
    };
    expectSameSolid(ex + "offset(delta = 1, chamfer = true) { square(size = [2, 2]); } }",
                    ex + "polygon(points = [" + pt(-t, -1) + ", " + pt(2 + t, -1) + ", " +
                        pt(3, -t) + ", " + pt(3, 2 + t) + ", " + pt(2 + t, 3) + ", " + pt(-t, 3) +
                        ", " + pt(-1, 2 + t) + ", " + pt(-1, -t) + "]); }");
    // A triangle's mitre reaches d / sin(half its angle) out: the right isosceles triangle
    // (0,0), (2,0), (0,2) grown by 1 is the triangle of the three moved lines, x >= -1,
    // y >= -1, x + y <= 2 + sqrt(2).
    const double s2 = 2.0 + std::sqrt(2.0);
    expectSameSolid(ex + "offset(delta = 1) { polygon(points = [[0, 0], [2, 0], [0, 2]]); } }",
                    ex + "polygon(points = [" + pt(-1, -1) + ", " + pt(s2 + 1, -1) + ", " +
                        pt(-1, s2 + 1) + "]); }");
    // Shrunk, an L keeps its mitred reflex corner: the L of arms 1 wide inside the 4 x 4 L
    // of arms 2 wide.
    expectSameSolid(ex + "offset(delta = -0.5) { polygon(points = [[0, 0], [4, 0], [4, 2], "
                         "[2, 2], [2, 4], [0, 4]]); } }",
                    ex + "polygon(points = [[0.5, 0.5], [3.5, 0.5], [3.5, 1.5], [1.5, 1.5], "
                         "[1.5, 3.5], [0.5, 3.5]]); }",
                    false);
    // A hole grows inward as the outline grows outward: a frame 4 wide with a 2 wide hole,
    // grown by 0.5, is the frame 5 wide with a 1 wide hole; shrunk, 3 wide around 3 wide.
    const std::string frame =
        "polygon(points = [[0, 0], [4, 0], [4, 4], [0, 4], [1, 1], [3, 1], [3, 3], [1, 3]], "
        "paths = [[0, 1, 2, 3], [4, 5, 6, 7]]); } }";
    expectSameSolid(ex + "offset(delta = 0.5) { " + frame,
                    "difference() { translate([-0.5, -0.5, 0]) cube(size = [5, 5, 3]); "
                    "translate([1.5, 1.5, -1]) cube(size = [1, 1, 5]); }");
    expectSameSolid(ex + "offset(delta = -0.25) { " + frame,
                    "difference() { translate([0.25, 0.25, 0]) cube(size = [3.5, 3.5, 3]); "
                    "translate([0.75, 0.75, -1]) cube(size = [2.5, 2.5, 5]); }",
                    false);
    // Two apart grow each; a circle, which has no corner, grows or shrinks round.
    const Scene two = csgText(ex +
                              "offset(delta = 1) { square(2); translate([10, 0]) "
                              "square(2); } }");
    EXPECT_NEAR(two.bounds.lo.x, -1.0, 1e-6);
    EXPECT_NEAR(two.bounds.hi.x, 13.0, 1e-6);
    expectSameSolid(ex + "offset(delta = -0.5, chamfer = true) { circle(r = 1.5); } }",
                    "cylinder(h = 3, r = 1);");
    // Shrunk past its width, a shape is gone.
    expectSameSolid("cube(1); " + ex + "offset(delta = -1.5) { square(2); } }", "cube(1);", false);
}

TEST(OpenScadOffset, SchemesAgreeWithBruteForce) {
    const Scene s = csgText(
        "difference() { linear_extrude(height = 2, center = true) { offset(r = 0.4) { "
        "polygon(points = [[0, 0], [3, 0], [3, 2], [1.5, 1], [0, 2]]); circle(r = 0.5); } } "
        "translate([1.5, 1, 0]) sphere(r = 0.8); }\n"
        "translate([0, 4, 0]) linear_extrude(height = 1) { offset(r = -0.3) { polygon(points = "
        "[[0, 0], [3, 0], [3, 2], [1.5, 1], [0, 2]]); } }\n"
        "translate([5, 0, 0]) linear_extrude(height = 1.5, twist = 30) { offset(delta = 0.3) "
        "{ polygon(points = [[0, 0], [3, 0], [3, 2], [1.5, 0.5], [0, 2]]); } }\n"
        "translate([5, 4, 0]) difference() { linear_extrude(height = 1) { offset(delta = "
        "0.4, chamfer = true) { polygon(points = [[0, 0], [3, 0], [3, 2], [1.5, 1], [0, 2], "
        "[0.5, 0.5], [1, 0.5], [0.75, 0.8]], paths = [[0, 1, 2, 3, 4], [5, 6, 7]]); } } "
        "translate([0, 4, 0]) linear_extrude(height = 1) offset(delta = -0.3) polygon(points = "
        "[[0, 0], [3, 0], [3, 2], [1.5, 1], [0, 2]]); }");
    const std::vector<Ray> rays = test::randomRays(s, 7, 3000);
    test::expectEverySchemeSame(s, rays);
}

// ---- --facets openscad ----

Scene facetedText(const std::string& text, OpenScadCounts* counts = nullptr) {
    ReadOptions o;
    o.facets = Facets::OpenScad;
    return readOpenScad(SourceText("mem.csg", text), nullptr, counts, o);
}

/// The faceted model of `model` and `twin` (read exactly) are the same solid.
void expectFacetedTwin(const std::string& model, const std::string& twin) {
    ReadOptions o;
    o.facets = Facets::OpenScad;
    expectSameSolid(model, twin, true, o);
}

TEST(OpenScadFacets, FewFragmentsMakeTheirPolyhedronTwins) {
    // $fn = 4: the circle's square has corners at 0, 90, 180, 270 degrees, radius 1 (a unit
    // square turned by 45 degrees, side sqrt(2)); the sphere's two rings lie at polar angles 45
    // and 135 degrees (radius and height sqrt(1/2)): a box of side 1 and height sqrt(2).
    const std::string turn =
        "multmatrix([[0.70710678118654757, -0.70710678118654746, 0, 0], "
        "[0.70710678118654746, 0.70710678118654757, 0, 0], [0, 0, 1, 0], "
        "[0, 0, 0, 1]]) ";
    expectFacetedTwin("sphere(r = 1, $fn = 4);",
                      turn + "cube(size = [1, 1, 1.4142135623730951], center = true);");
    expectFacetedTwin("cylinder(h = 2, r = 1, center = true, $fn = 4);",
                      turn +
                          "cube(size = [1.4142135623730951, 1.4142135623730951, 2], center = "
                          "true);");
    expectFacetedTwin("linear_extrude(height = 2) circle(r = 1, $fn = 4);",
                      turn +
                          "translate([-0.70710678118654757, -0.70710678118654757, 0]) "
                          "cube(size = [1.4142135623730951, 1.4142135623730951, 2]);");
    // A cone to an apex: the square pyramid.
    expectFacetedTwin("cylinder(h = 1, r1 = 1, r2 = 0, $fn = 4);",
                      "polyhedron(points = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0], [0, 0, "
                      "1]], faces = [[0, 3, 2, 1], [4, 0, 1], [4, 1, 2], [4, 2, 3], [4, 3, 0]]);");
    // The default rule: r = 10 with $fa = 12, $fs = 2 is 30 fragments, r = 1 is 5.
    OpenScadCounts n;
    const Scene ball = facetedText("sphere(r = 10, $fn = 0, $fa = 12, $fs = 2);", &n);
    EXPECT_EQ(n.polytopes, 14);  // 15 rings, 14 bands
    EXPECT_EQ(n.facetedShapes, 1);
    ASSERT_TRUE(std::holds_alternative<Polytope>(ball.prims[0].shape));
    EXPECT_EQ(std::get<Polytope>(ball.prims[0].shape).planes.size(), 32u);
    const Scene pent = facetedText("cylinder(h = 1, r = 1);", &n);
    EXPECT_EQ(std::get<Polytope>(pent.prims[0].shape).planes.size(), 7u);
    EXPECT_THROW(facetedText("sphere(r = 1, $fn = 2000);"), SceneError);  // 2 million facets
    // Exact by default: the same model is one sphere.
    const Scene exact = csgText("sphere(r = 10, $fn = 0, $fa = 12, $fs = 2);", &n);
    ASSERT_EQ(exact.prims.size(), 1u);
    EXPECT_TRUE(std::holds_alternative<Sphere>(exact.prims[0].shape));
    EXPECT_EQ(exact.modelError, 0.0);
}

/// Where brute force's nearest hits of `count` random rays (seed `seed`) lie.
std::vector<Vec3> bruteHits(const Scene& s, uint64_t seed, int count) {
    auto brute = buildAccelerator(s, BuildParams{});
    TraceContext ctx(s.prims.size(), s.tree.depth());
    NullObserver obs;
    std::vector<Vec3> out;
    for (const Ray& ray : test::randomRays(s, seed, count)) {
        ctx.beginRay();
        Hit h;
        if (brute->intersect(ray, 0.0, kInf, ctx, obs, h)) out.push_back(ray.at(h.t));
    }
    return out;
}

TEST(OpenScadFacets, HitsLieWithinTheStatedSagittaInsideTheExactSurface) {
    // Every hit on a faceted sphere lies inside the sphere, by at most the stated error; on a
    // faceted cylinder, inside its radius by at most the sagitta. $fn = 300 cuts each band
    // into sectors (302 planes are over a polytope's 255).
    for (const char* model : {"sphere(r = 2, $fn = 300);", "sphere(r = 2, $fn = 12);",
                              "scale(3) sphere(r = 2, $fa = 12, $fs = 2);",
                              "cylinder(h = 3, r = 2, center = true, $fn = 7);"}) {
        SCOPED_TRACE(model);
        OpenScadCounts n;
        const Scene s = facetedText(model, &n);
        const bool sphere = std::string(model).find("sphere") != std::string::npos;
        const double scale = std::string(model).rfind("scale", 0) == 0 ? 3.0 : 1.0;
        const double r = 2.0 * scale;
        const double stated = s.modelError;
        EXPECT_GT(stated, 0.0);
        EXPECT_EQ(stated, n.facetError);
        double worst = 0.0;
        const std::vector<Vec3> hits = bruteHits(s, 11, 2000);
        for (const Vec3& p : hits) {
            const double inside = r - (sphere ? glm::length(p) : std::hypot(p.x, p.y));
            if (!sphere && std::abs(p.z) > 1.5 - 1e-9) continue;  // on a cap: exact
            EXPECT_GE(inside, -1e-9 * r);
            worst = std::max(worst, inside);
        }
        EXPECT_GT(hits.size(), 500u);
        EXPECT_LE(worst, stated * (1.0 + 1e-9));
        EXPECT_GT(worst, 0.5 * stated);  // the bound is near what the facets do
    }
}

TEST(OpenScadFacets, SchemesAgreeWithBruteForce) {
    const Scene s = facetedText(
        "difference() { sphere(r = 2, $fn = 20); cylinder(h = 5, r = 1, center = true, $fn = "
        "9); }\n"
        "translate([5, 0, 0]) cylinder(h = 3, r1 = 2, r2 = 0.5, $fn = 300);\n"
        "translate([0, 5, 0]) rotate_extrude() translate([2, 0]) circle(r = 0.5, $fn = 8);\n"
        "translate([5, 5, 0]) linear_extrude(height = 1, twist = 45) difference() { circle(r = "
        "1.5, $fn = 16); square(1, center = true); }");
    const std::vector<Ray> rays = test::randomRays(s, 13, 3000);
    test::expectEverySchemeSame(s, rays);
}

// ---- hull() of curved children by their facets ----

TEST(OpenScadHullFacets, CurvedChildrenMakeTheHullOfTheirFacets) {
    // $fn = 4: a sphere's polyhedron is a box turned by 45 degrees (side r sqrt(2), height
    // r sqrt(2)), a cylinder's a square prism, a circle's a square: the hull of their facets
    // is the hull of those boxes' corners.
    const std::string turn =
        "multmatrix([[0.70710678118654757, -0.70710678118654746, 0, 0], "
        "[0.70710678118654746, 0.70710678118654757, 0, 0], [0, 0, 1, 0], "
        "[0, 0, 0, 1]]) ";
    expectSameSolid(
        "hull() { sphere(r = 1, $fn = 4); translate([4, 0, 0]) sphere(r = 2, $fn = "
        "4); }",
        "hull() { " + turn +
            "cube(size = [1, 1, 1.4142135623730951], center = true); translate([4, "
            "0, 0]) " +
            turn + "cube(size = [2, 2, 2.8284271247461903], center = true); }");
    expectSameSolid("hull() { cylinder(h = 1, r = 1, $fn = 4); translate([3, 0, 0]) cube(1); }",
                    "hull() { " + turn +
                        "translate([-0.70710678118654757, -0.70710678118654757, 0]) cube(size = "
                        "[1.4142135623730951, 1.4142135623730951, 1]); translate([3, 0, 0]) "
                        "cube(1); }");
    // In 2D: two squares of circles and a point of a polygon.
    expectSameSolid(
        "linear_extrude(height = 1) hull() { circle(r = 1, $fn = 4); translate([3, "
        "0]) circle(r = 1, $fn = 4); polygon(points = [[1.5, 3], [1.5, 2], [1, "
        "2]]); }",
        "linear_extrude(height = 1) polygon(points = [[-1, 0], [0, -1], [3, -1], "
        "[4, 0], [1.5, 3]]);");
    OpenScadCounts n;
    const Scene s = csgText("hull() { sphere(r = 1, $fn = 4); cube(1); }", &n);
    EXPECT_EQ(n.hulls, 1);
    EXPECT_EQ(n.facetedShapes, 1);
    EXPECT_NEAR(s.modelError, 0.5, 1e-8);  // the turned box's side faces lie 0.5 out
    // Equal balls stay exact: no error; with --facets openscad, their facets' hull.
    const Scene exact = csgText("hull() { sphere(1); translate([3, 0, 0]) sphere(1); }", &n);
    EXPECT_EQ(exact.modelError, 0.0);
    EXPECT_EQ(n.facetedShapes, 0);
    ReadOptions o;
    o.facets = Facets::OpenScad;
    const Scene faceted =
        readOpenScad(SourceText("mem.csg",
                                "hull() { sphere(1, $fn = 4); translate([3, 0, 0]) sphere(1, $fn = "
                                "4); }"),
                     nullptr, &n, o);
    EXPECT_EQ(n.polytopes, 1);
    // A corner of the turned box at x = 3 + sqrt(1/2).
    EXPECT_NEAR(faceted.bounds.hi.x, 3.0 + std::sqrt(0.5), 1e-6);
}

/// How far inside the exact hull of the balls (c0, r0) and (c1, r1) the point p lies (negative:
/// outside): the hull is the union of the balls between them, linearly, and its inner parallel
/// body at depth e their hull with radii less e.
double depthInHullOfTwoBalls(const Vec3& p, const Vec3& c0, double r0, const Vec3& c1, double r1) {
    auto f = [&](double t) { return glm::length(p - glm::mix(c0, c1, t)) - glm::mix(r0, r1, t); };
    double lo = 0.0, hi = 1.0;  // f is convex in t: ternary search for its least value
    for (int i = 0; i < 200; ++i) {
        const double a = lo + (hi - lo) / 3.0, b = hi - (hi - lo) / 3.0;
        (f(a) < f(b) ? hi : lo) = f(a) < f(b) ? b : a;
    }
    return -std::min({f(lo), f(0.0), f(1.0)});
}

TEST(OpenScadHullFacets, HitsLieInsideTheExactHullWithinTheStatedError) {
    // Spheres of radii 1 and 2 at OpenSCAD's default facets (5 and 7 fragments), and finer.
    for (const char* fn : {"", ", $fn = 24", ", $fn = 48"}) {
        SCOPED_TRACE(fn);
        OpenScadCounts n;
        const Scene s = csgText(std::string("hull() { sphere(r = 1") + fn +
                                    "); translate([4, 1, 0]) sphere(r = 2" + fn + "); }",
                                &n);
        const double stated = s.modelError;
        EXPECT_GT(stated, 0.0);
        double worst = 0.0;
        const std::vector<Vec3> hits = bruteHits(s, 17, 2000);
        for (const Vec3& p : hits) {
            const double d = depthInHullOfTwoBalls(p, Vec3(0.0), 1.0, Vec3(4.0, 1.0, 0.0), 2.0);
            EXPECT_GE(d, -1e-9);
            worst = std::max(worst, d);
        }
        EXPECT_GT(hits.size(), 500u);
        EXPECT_LE(worst, stated * (1.0 + 1e-9));
        EXPECT_GT(worst, 0.3 * stated);
    }
}

TEST(OpenScadHullFacets, SchemesAgreeWithBruteForce) {
    // Past 255 faces ($fn = 40) the hull is cut into wedges about a vertical line.
    OpenScadCounts n;
    const Scene s = csgText(
        "difference() { hull() { sphere(r = 1); translate([3, 0, 1]) sphere(r = 2); "
        "translate([0, 3, 0]) cylinder(h = 2, r1 = 1, r2 = 0.2); } translate([1.5, 1, 0]) "
        "cube(1.5, center = true); }\n"
        "translate([0, -6, 0]) hull() { sphere(r = 1, $fn = 40); translate([3, 0, 0]) sphere(r "
        "= 1.5, $fn = 40); }\n"
        "translate([6, 0, 0]) linear_extrude(height = 1, twist = 30) hull() { circle(r = 1); "
        "translate([2, 1]) circle(r = 0.5); }",
        &n);
    EXPECT_GT(n.polytopes, 3);
    const std::vector<Ray> rays = test::randomRays(s, 19, 3000);
    test::expectEverySchemeSame(s, rays);
}

}  // namespace
}  // namespace lancer
