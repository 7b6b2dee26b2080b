// The NFF reader on every SPD scene (entity counts, depths known by hand) and on every entity
// of the NFF spec, with one error test per class of malformed input.
#include "engine/scene/nff_reader.h"

#include <gtest/gtest.h>

#include <cmath>

#include "app/cli/options.h"
#include "engine/accel/accelerator.h"
#include "engine/scene/loader.h"

namespace lancer {
namespace {

std::string spd(const std::string& name) { return std::string(LANCER_SPD_DIR) + "/" + name; }

Scene nffText(const std::string& text, NffCounts* counts = nullptr) {
    return readNff(SourceText("mem.nff", text), counts);
}

/// Brute-force primary hit through pixel (x, y) of a w x h image.
Hit primaryHit(const Scene& scene, double x, double y, int w, int h) {
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    auto acc = buildAccelerator(scene, bp);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    NullObserver obs;
    Hit hit;
    ctx.beginRay();
    acc->intersect(scene.camera.primaryRay(x, y, w, h), 0.0, kInf, ctx, obs, hit);
    return hit;
}

/// Distance along the (unit) ray to the plane through three points.
double planeT(const Ray& r, Vec3 a, Vec3 b, Vec3 c) {
    Vec3 n = glm::cross(b - a, c - a);
    return glm::dot(a - r.o, n) / glm::dot(r.d, n);
}

/// Nearest distance along the (unit) ray to a sphere, from outside.
double sphereT(const Ray& r, Vec3 c, double rad) {
    Vec3 oc = r.o - c;
    double b = glm::dot(oc, r.d), q = glm::dot(oc, oc) - rad * rad;
    return -b - std::sqrt(b * b - q);
}

struct SpdCounts {
    const char* file;
    int spheres, polygons, patches, cones, lights, materials;
};

// Counted independently with grep on the files (`grep -c '^s '` and so on).
const SpdCounts kSpd[] = {
    {"balls1.nff", 10, 1, 0, 0, 3, 2},     {"balls2.nff", 91, 1, 0, 0, 3, 2},
    {"balls3.nff", 820, 1, 0, 0, 3, 2},    {"balls4.nff", 7381, 1, 0, 0, 3, 2},
    {"gears1.nff", 0, 147, 0, 0, 5, 2},    {"gears2.nff", 0, 1169, 0, 0, 5, 9},
    {"mount3.nff", 4, 128, 0, 0, 1, 2},    {"rings2.nff", 150, 1, 0, 150, 3, 31},
    {"rings3.nff", 420, 1, 0, 420, 3, 85}, {"teapot2.nff", 0, 4, 240, 0, 2, 3},
    {"tetra3.nff", 0, 64, 0, 0, 1, 1},     {"tetra4.nff", 0, 256, 0, 0, 1, 1},
    {"tree4.nff", 31, 1, 0, 31, 7, 2},
};

TEST(NffReader, EverySpdSceneHasItsEntityCounts) {
    for (const SpdCounts& e : kSpd) {
        SCOPED_TRACE(e.file);
        NffCounts c;
        Scene s = readNff(SourceText::fromFile(spd(e.file)), &c);
        EXPECT_EQ(c.spheres, e.spheres);
        EXPECT_EQ(c.polygons, e.polygons);
        EXPECT_EQ(c.patches, e.patches);
        EXPECT_EQ(c.cones, e.cones);
        EXPECT_EQ(c.lights, e.lights);
        EXPECT_EQ(c.materials, e.materials);
        EXPECT_EQ(c.degenerate, 0);
        // Every entity is a primitive (SPD's patches are triangles); all live in one union.
        EXPECT_EQ(s.prims.size(), size_t(e.spheres + e.polygons + e.patches + e.cones));
        EXPECT_EQ(s.tree.primitives().size(), s.prims.size());
        EXPECT_EQ(s.lights.size(), size_t(e.lights));
        EXPECT_EQ(s.width, 512);
        EXPECT_EQ(s.height, 512);
        EXPECT_EQ(s.background, Vec3(0.078, 0.361, 0.753));
    }
}

TEST(NffReader, AngleSpansPixelCentresOfTopAndBottomRows) {
    Scene s = loadScene(spd("balls1.nff"));
    // The rays through the centres of the top and bottom rows are 45 degrees apart (NFF spec).
    Ray top = s.camera.primaryRay(255.5, 0, 512, 512),
        bottom = s.camera.primaryRay(255.5, 511, 512, 512);
    EXPECT_NEAR(glm::degrees(std::acos(glm::dot(top.d, bottom.d))), 45.0, 1e-9);
    // Left and right columns too (square pixels, square image).
    Ray left = s.camera.primaryRay(0, 255.5, 512, 512),
        right = s.camera.primaryRay(511, 255.5, 512, 512);
    EXPECT_NEAR(glm::degrees(std::acos(glm::dot(left.d, right.d))), 45.0, 1e-9);
    // Edge to edge: 2 atan(tan(22.5) * 512 / 511).
    EXPECT_NEAR(s.camera.fov,
                glm::degrees(2.0 * std::atan(std::tan(glm::radians(22.5)) * 512.0 / 511.0)), 1e-12);
}

TEST(NffReader, WidthAndHeightOptionsKeepTheFieldOfView) {
    Scene s = loadScene(spd("balls1.nff"));
    cli::CommonOptions o;
    int w, h;
    cli::resolveSize(o, s, w, h);
    EXPECT_EQ(w, 512);
    EXPECT_EQ(h, 512);
    o.knobs.height = 101;
    cli::resolveSize(o, s, w, h);
    EXPECT_EQ(w, 101);
    EXPECT_EQ(h, 101);
    // The centre ray of a 101 x 101 image is the view direction, the same as at 512 x 512: the
    // big sphere at |from| - 0.5.
    EXPECT_NEAR(primaryHit(s, 50, 50, 101, 101).t,
                std::sqrt(2.1 * 2.1 + 1.3 * 1.3 + 1.7 * 1.7) - 0.5, 1e-12);
    // The image's top edge stays where it was: the ray through the top edge of the centre column.
    Vec3 f, r, u;
    s.camera.basis(f, r, u);
    double half = std::tan(glm::radians(s.camera.fov) * 0.5);
    for (int size : {512, 101}) {
        Ray top = s.camera.primaryRay(0.5 * size - 0.5, -0.5, size, size);
        EXPECT_NEAR(glm::dot(top.d, u) / glm::dot(top.d, f), half, 1e-12) << size;
    }
}

TEST(NffReader, DepthsKnownByHand) {
    struct Probe {
        const char* file;
        double x, y;
        enum { Sphere, Plane } kind;
        Vec3 a, b, c;  // sphere: centre a, radius b.x; plane: three points
    };
    const Vec3 g0(12, 12, -0.5), g1(-12, 12, -0.5), g2(-12, -12, -0.5);  // balls' ground polygon
    const Probe probes[] = {
        // The centre ray of balls1 goes through the big sphere's centre: |from| - 0.5.
        {"balls1.nff", 255.5, 255.5, Probe::Sphere, {0, 0, 0}, {0.5, 0, 0}, {}},
        {"balls1.nff", 0, 511, Probe::Plane, g0, g1, g2},
        {"balls2.nff",
         255.5,
         255.5,
         Probe::Sphere,
         {0.461844, 0.304709, 0.43322},
         {0.0555556, 0, 0},
         {}},
        {"balls2.nff", 511, 0, Probe::Plane, g0, g1, g2},
        {"balls3.nff",
         255.5,
         255.5,
         Probe::Sphere,
         {0.529584, 0.334488, 0.436618},
         {0.0185185, 0, 0},
         {}},
        {"balls3.nff", 255.5, 511, Probe::Plane, g0, g1, g2},
        {"balls4.nff", 0, 511, Probe::Plane, g0, g1, g2},
        {"balls4.nff", 511, 255.5, Probe::Plane, g0, g1, g2},
        {"gears1.nff", 0, 511, Probe::Plane, {2, 2, 0}, {-2, 2, 0}, {-2, -2, 0}},
        {"gears2.nff", 255.5, 511, Probe::Plane, {2, 2, 0}, {-2, 2, 0}, {-2, -2, 0}},
        {"mount3.nff",
         255.5,
         255.5,
         Probe::Plane,
         {0, 0.25, 0.275634},
         {-0.25, 0.25, 0.0368136},
         {-0.25, 0, 0.401415}},
        {"rings2.nff",
         0,
         0,
         Probe::Plane,
         {3.37286, 7.83938, 4.87286},
         {-5.37286, 7.83938, 4.87286},
         {-5.37286, 7.83938, -3.87286}},
        {"rings3.nff",
         511,
         511,
         Probe::Plane,
         {4.46608, 10.4525, 5.96608},
         {-6.46608, 10.4525, 5.96608},
         {-6.46608, 10.4525, -4.96608}},
        {"teapot2.nff", 0, 255.5, Probe::Plane, {-4, -4, 0}, {0, -4, 0}, {0, 0, 0}},
        {"teapot2.nff", 255.5, 511, Probe::Plane, {-4, -4, 0}, {0, -4, 0}, {0, 0, 0}},
        {"tetra3.nff", 255.5, 255.5, Probe::Plane, {0, -1, 0}, {0, -0.5, -0.5}, {0.5, -1, -0.5}},
        {"tetra4.nff",
         255.5,
         255.5,
         Probe::Plane,
         {0.25, -1, -0.25},
         {0.25, -0.75, -0.5},
         {0.5, -1, -0.5}},
        {"tree4.nff", 0, 511, Probe::Plane, {50, 50, 0}, {-50, 50, 0}, {-50, -50, 0}},
    };
    for (const Probe& p : probes) {
        SCOPED_TRACE(std::string(p.file) + " pixel " + std::to_string(p.x) + ", " +
                     std::to_string(p.y));
        Scene s = loadScene(spd(p.file));
        Ray ray = s.camera.primaryRay(p.x, p.y, 512, 512);
        double expected =
            p.kind == Probe::Sphere ? sphereT(ray, p.a, p.b.x) : planeT(ray, p.a, p.b, p.c);
        Hit hit = primaryHit(s, p.x, p.y, 512, 512);
        ASSERT_TRUE(hit.valid());
        EXPECT_NEAR(hit.t, expected, 1e-9 * expected);
    }
    EXPECT_NEAR(sphereT(loadScene(spd("balls1.nff")).camera.primaryRay(255.5, 255.5, 512, 512),
                        Vec3(0.0), 0.5),
                std::sqrt(8.99) - 0.5, 1e-12);
}

TEST(NffReader, EveryEntityOfTheSpec) {
    NffCounts c;
    Scene s = nffText(
        "# a comment line\n"
        "v\nfrom 0 -10 0\nat 0 0 0\nup 0 0 1\nangle 30\nhither 0.5\nresolution 320 200\n"
        "b 0.1 0.2 0.3\n"
        "l 0 -10 10\n"
        "l 5 -10 10 1 0.5 0.25   # with a colour\n"
        "f 1 0 0 0.7 0.3 50 0 1.5\n"
        "s 0 0 0 1\n"
        "p 3 -3 2 -1  3 2 -1  0 2 3\n"
        "pp 3\n-3 3 -1 0 -1 0\n3 3 -1 0 -1 0\n0 3 3 0 -1 1\n"
        "c 2 0 0 0.5 2 0 1 0.25\n"      // on one line, as SPD writes it
        "c -2 0 0 0.5\n-2 0 1 0.5\n"    // on two, as the spec shows it
        "c 0 0 -3 -0.5 0 0 -2 -0.5\n",  // both negative: inside visible
        &c);
    EXPECT_EQ(c.spheres, 1);
    EXPECT_EQ(c.polygons, 1);
    EXPECT_EQ(c.patches, 1);
    EXPECT_EQ(c.cones, 3);
    EXPECT_EQ(c.lights, 2);
    EXPECT_EQ(c.materials, 1);
    EXPECT_EQ(s.width, 320);
    EXPECT_EQ(s.height, 200);
    EXPECT_EQ(s.background, Vec3(0.1, 0.2, 0.3));
    ASSERT_EQ(s.lights.size(), 2u);
    EXPECT_EQ(s.lights[0].color.x, s.lights[0].color.y);                 // white
    EXPECT_NEAR(s.lights[1].color.y / s.lights[1].color.x, 0.5, 1e-12);  // coloured
    EXPECT_EQ(s.materials.back().color, Vec3(1, 0, 0));
    EXPECT_EQ(s.materials.back().ior, 1.5);
    // Sphere solid; polygon, patch and cones surfaces; all under one union.
    int surfaces = 0;
    for (const Primitive& p : s.prims) surfaces += p.isSurface();
    EXPECT_EQ(s.prims.size(), 6u);
    EXPECT_EQ(surfaces, 5);
    for (const CsgNode& n : s.tree.nodes) EXPECT_TRUE(n.op == Op::Primitive || n.op == Op::Union);
    // The two-line and one-line cones are the same shape, mirrored in x.
    EXPECT_NEAR(s.prims[3].worldBox.lo.x, -s.prims[4].worldBox.hi.x, 1e-12);
    EXPECT_NEAR(s.prims[5].worldBox.hi.x, 0.5, 1e-12);
    // Centre ray (pixel centres straddle the middle of 320 x 200): the sphere at distance 9.
    EXPECT_NEAR(primaryHit(s, 159.5, 99.5, 320, 200).t, 9.0, 1e-12);
}

TEST(NffReader, NonConvexPatchKeepsItsExactOutline) {
    // An L-shaped patch: a fan from vertex 0 would cover the notch; a polygon does not.
    std::string l =
        "pp 6\n0 0 0 0 0 1\n2 0 0 0 0 1\n2 1 0 0 0 1\n1 1 0 0 0 1\n1 2 0 0 0 1\n0 2 0 0 0 1\n";
    Scene s = nffText(
        "v\nfrom 1.5 1.5 5\nat 1.5 1.5 0\nup 0 1 0\nangle 10\nhither 0\nresolution 11 11\n" + l);
    ASSERT_EQ(s.prims.size(), 1u);
    EXPECT_TRUE(std::holds_alternative<Polygon>(s.prims[0].shape));
    EXPECT_FALSE(primaryHit(s, 5, 5, 11, 11).valid());  // the notch at (1.5, 1.5)
}

void expectNffError(const std::string& text, const std::string& message) {
    try {
        nffText(text);
        ADD_FAILURE() << "no error for:\n" << text;
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), message);
    }
}

TEST(NffReader, MalformedInputNamesFileLineAndColumn) {
    // Truncated.
    expectNffError("s 0 0 0 1\ns 1 2",
                   "mem.nff:2:6: unexpected end of file: expected the sphere centre");
    expectNffError(
        "v\nfrom 0 0 5\nat 0 0 0\n",
        "mem.nff:4:1: unexpected end of file: expected 'up' in the viewpoint ('v') block");
    // Wrong arity: a polygon announcing 4 vertices with 3 (the next entity is read as a number).
    expectNffError("p 4\n0 0 0\n1 0 0\n1 1 0\ns 0 0 0 1\n",
                   "mem.nff:5:1: expected a vertex (a finite number), got 's'");
    expectNffError("p 2\n0 0 0\n1 0 0\n", "mem.nff:1:3: a polygon needs at least 3 vertices");
    // Not numbers.
    expectNffError("s 0 0 zero 1\n",
                   "mem.nff:1:7: expected the sphere centre (a finite number), got 'zero'");
    expectNffError("l 1 2 3 1 x 1\n",
                   "mem.nff:1:11: expected the light colour (a finite number), got 'x'");
    // NaN and infinities.
    expectNffError("s 0 0 0 nan\n",
                   "mem.nff:1:9: expected the sphere radius (a finite number), got 'nan'");
    expectNffError("s 0 inf 0 1\n",
                   "mem.nff:1:5: expected the sphere centre (a finite number), got 'inf'");
    expectNffError("s 0 0 0 1e999\n",
                   "mem.nff:1:9: expected the sphere radius (a finite number), got '1e999'");
    // Negative radii and other values out of their range.
    expectNffError("s 0 0 0 -1\n", "mem.nff:1:9: the sphere radius must be positive");
    expectNffError("c 0 0 0 -1 0 0 1 1\n",
                   "mem.nff:1:9: a cone radius must not be negative (unless both are, for an "
                   "inside-visible cone)");
    expectNffError("c 0 0 0 1 0 0 0 1\n",
                   "mem.nff:1:1: the cone's base and apex are the same point");
    expectNffError("f 1 1 1 -0.5 0 1 0 1\n", "mem.nff:1:9: Kd must not be negative");
    expectNffError(
        "f 1 1 1 0.5 0 1 0.5 0\n",
        "mem.nff:1:21: a transmitting material (T > 0) needs a positive index of refraction");
    expectNffError("v\nfrom 0 0 5\nat 0 0 0\nup 0 0 1\nangle 180\n",
                   "mem.nff:5:7: the view angle must be in (0, 180) degrees");
    expectNffError("v\nfrom 0 0 5\nat 0 0 0\nup 0 0 1\nangle 40\nhither 1\nresolution 0 10\n",
                   "mem.nff:7:12: the resolution must be at least 1 x 1");
    expectNffError("v\nfrom 0 0 5\nat 0 0 0\nup 0 0 5\nangle 40\nhither 1\nresolution 10 10\n",
                   "mem.nff:1:1: camera 'up' is parallel to the view direction");
    // Huge counts are refused before anything is allocated.
    expectNffError("p 99999999999\n",
                   "mem.nff:1:3: the vertex count 99999999999 is larger than the limit of 1048576");
    expectNffError("v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 100000 10\n",
                   "mem.nff:7:12: the image width 100000 is larger than the limit of 16384");
    expectNffError("p 3.5\n",
                   "mem.nff:1:3: expected the vertex count (a non-negative integer), got '3.5'");
    // Unknown entities.
    expectNffError(
        "s 0 0 0 1\nsphere 0 0 0 1\n",
        "mem.nff:2:1: unknown NFF entity 'sphere' (expected v, b, l, f, s, p, pp, c or #)");
}

}  // namespace
}  // namespace lancer
