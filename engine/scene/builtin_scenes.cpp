#include "engine/scene/builtin_scenes.h"

#include <cmath>
#include <functional>

namespace lancer {

namespace {

/// A small helper to assemble scenes in code.
struct SceneBuilder {
    Scene s;
    int material(const Material& m) {
        s.materials.push_back(m);
        return int(s.materials.size()) - 1;
    }
    int prim(Shape shape, int mat, const Transform& xf = Transform()) {
        s.prims.push_back(makePrimitive(std::move(shape), xf, mat));
        return s.tree.leaf(uint32_t(s.prims.size() - 1));
    }
    int op(Op o, int a, int b) { return s.tree.combine(o, a, b); }
    int all(Op o, const std::vector<int>& items) { return s.tree.balanced(o, items); }
    Scene finish(int root, const std::string& name) {
        s.tree.root = root;
        s.name = "builtin:" + name;
        s.prepare();
        return std::move(s);
    }
};

Material mat(Vec3 c, double diffuse, double specular, double shine, double reflect = 0.0,
             double transmit = 0.0, double ior = 1.0) {
    Material m;
    m.color = c;
    m.diffuse = diffuse;
    m.specular = specular;
    m.shininess = shine;
    m.reflect = reflect;
    m.transmit = transmit;
    m.ior = ior;
    return m;
}

Block cube(Vec3 c, double half) { return Block{c - Vec3(half), c + Vec3(half)}; }
Cone cylinderZ(double r, double h) { return Cone{r, r, h, false}; }

// Union, intersection and difference side by side on a floor, with a mirror and a glass ball.
Scene defaultScene() {
    SceneBuilder b;
    int floorM = b.material(mat({0.85, 0.85, 0.8}, 0.8, 0.0, 1.0, 0.15));
    int red = b.material(mat({0.9, 0.2, 0.15}, 0.8, 0.4, 40.0));
    int green = b.material(mat({0.2, 0.75, 0.3}, 0.8, 0.4, 40.0));
    int blue = b.material(mat({0.2, 0.35, 0.9}, 0.8, 0.4, 40.0));
    int glass = b.material(mat({1.0, 1.0, 1.0}, 0.05, 0.6, 120.0, 0.1, 0.85, 1.5));
    std::vector<int> parts;
    parts.push_back(b.prim(Block{{-6, -4, -1.2}, {6, 5, -1.0}}, floorM));
    // Union: a sphere on a cylinder.
    parts.push_back(b.op(Op::Union, b.prim(Sphere{{-3.0, 0.0, 0.6}, 0.9}, red),
                         b.prim(cylinderZ(0.5, 1.6), red, Transform::translate({-3.0, 0.0, -1.0}))));
    // Intersection: a rounded cube (cube ∩ sphere).
    parts.push_back(b.op(Op::Intersection, b.prim(cube({0.0, 0.0, 0.0}, 1.0), green),
                         b.prim(Sphere{{0.0, 0.0, 0.0}, 1.35}, green)));
    // Difference: a cube drilled by a sphere and a cylinder across it.
    int drilled = b.op(Op::Difference, b.prim(cube({3.0, 0.0, 0.0}, 1.0), blue),
                       b.prim(Sphere{{3.0, 0.0, 1.0}, 0.9}, blue));
    drilled = b.op(Op::Difference, drilled,
                   b.prim(cylinderZ(0.45, 4.0), blue,
                          Transform::translate({3.0, 2.0, 0.0}) * Transform::rotate(90.0, {1, 0, 0})));
    parts.push_back(drilled);
    parts.push_back(b.prim(Sphere{{-1.5, -2.2, -0.45}, 0.55}, glass));
    Scene s = b.finish(b.all(Op::Union, parts), "default");
    s.background = {0.12, 0.14, 0.2};
    s.camera.from = {1.5, -10.0, 4.5};
    s.camera.at = {0.0, 0.0, -0.2};
    s.camera.up = {0, 0, 1};
    s.camera.fov = 38.0;
    s.camera.orthoHeight = 7.0;
    s.width = 640;
    s.height = 400;
    s.lights = {{{-6.0, -8.0, 10.0}, Vec3(0.75)}, {{8.0, -6.0, 6.0}, Vec3(0.45)}};
    return s;
}

// SPD "balls" (sphereflake): a sphere sprouting 9 spheres of a third of its radius, recursively.
Scene ballsScene(int size) {
    SceneBuilder b;
    int floorM = b.material(mat({1.0, 0.75, 0.33}, 0.8, 0.0, 100000.0));
    int ballM = b.material(mat({1.0, 0.9, 0.7}, 0.5, 0.5, 3.0827, 0.5));
    std::vector<int> leaves;
    Polygon floor;
    makePolygon({{12, 12, -0.5}, {-12, 12, -0.5}, {-12, -12, -0.5}, {12, -12, -0.5}}, floor);
    leaves.push_back(b.prim(floor, floorM));
    // Child directions in the parent's frame (z = the parent's direction), as in SPD's output:
    // three at 54.7° elevation and six around the equator.
    std::vector<Vec3> dirs;
    double e = std::asin(std::sqrt(2.0 / 3.0));
    for (int i = 0; i < 3; ++i) {
        double a = glm::radians(45.0 + 120.0 * i);
        dirs.push_back({std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e)});
    }
    for (int i = 0; i < 6; ++i) {
        double a = glm::radians(15.0 + 60.0 * i);
        dirs.push_back({std::cos(a), std::sin(a), 0.0});
    }
    std::function<void(Vec3, double, Vec3, int)> grow = [&](Vec3 c, double r, Vec3 dir, int depth) {
        leaves.push_back(b.prim(Sphere{c, r}, ballM));
        if (depth == 0) return;
        Vec3 u, v;
        orthonormalBasis(dir, u, v);
        for (const Vec3& d : dirs) {
            Vec3 w = glm::normalize(d.x * u + d.y * v + d.z * dir);
            grow(c + w * (r + r / 3.0), r / 3.0, w, depth - 1);
        }
    };
    grow(Vec3(0.0), 0.5, {0, 0, 1}, size);
    Scene s = b.finish(b.all(Op::Union, leaves), "balls:" + std::to_string(size));
    s.background = {0.078, 0.361, 0.753};
    s.camera.from = {2.1, 1.3, 1.7};
    s.camera.at = {0, 0, 0};
    s.camera.up = {0, 0, 1};
    s.camera.fov = glm::degrees(2.0 * std::atan(std::tan(glm::radians(22.5)) * 512.0 / 511.0));
    double share = 1.0 / std::sqrt(3.0);
    s.lights = {{{4, 3, 2}, Vec3(share)}, {{1, -4, 4}, Vec3(share)}, {{-3, 1, 5}, Vec3(share)}};
    return s;
}

// A block drilled by an n x n x n grid of spheres; the grid overhangs the block, so the outer
// spheres' boxes are clipped away by minimization and dropped.
Scene drilledScene(int n) {
    SceneBuilder b;
    int steel = b.material(mat({0.75, 0.78, 0.85}, 0.7, 0.5, 60.0, 0.1));
    int block = b.prim(Block{{-1, -1, -1}, {1, 1, 1}}, steel);
    std::vector<int> holes;
    double extent = 1.3, step = 2.0 * extent / n, r = 0.42 * step;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k) {
                Vec3 c = Vec3(-extent) + step * (Vec3(i, j, k) + 0.5);
                holes.push_back(b.prim(Sphere{c, r}, steel));
            }
    Scene s = b.finish(b.op(Op::Difference, block, b.all(Op::Union, holes)), "drilled:" + std::to_string(n));
    s.background = {0.1, 0.1, 0.12};
    s.frameCamera({-1.0, 2.2, -1.4}, {0, 0, 1});
    s.defaultLights();
    return s;
}

// An n x n x n lattice of cells, each a rounded cube (cube ∩ sphere) bored by a cylinder,
// the whole lattice cut by a slab: cells outside the slab are dropped by minimization.
Scene latticeScene(int n) {
    SceneBuilder b;
    std::vector<int> cells;
    int ma = b.material(mat({0.9, 0.55, 0.2}, 0.8, 0.3, 30.0));
    int mb = b.material(mat({0.25, 0.6, 0.85}, 0.8, 0.3, 30.0));
    double step = 2.0 / n, half = 0.4 * step;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k) {
                Vec3 c = Vec3(-1.0) + step * (Vec3(i, j, k) + 0.5);
                int m = ((i + j + k) % 2) ? ma : mb;
                int rounded = b.op(Op::Intersection, b.prim(cube(c, half), m), b.prim(Sphere{c, 1.3 * half}, m));
                int bore = b.prim(cylinderZ(0.45 * half, 2.4 * half), m, Transform::translate(c - Vec3(0, 0, 1.2 * half)));
                cells.push_back(b.op(Op::Difference, rounded, bore));
            }
    int slab = b.prim(Block{{-1.1, -1.1, -0.55}, {1.1, 1.1, 0.55}}, ma);
    Scene s = b.finish(b.op(Op::Intersection, b.all(Op::Union, cells), slab), "lattice:" + std::to_string(n));
    s.background = {0.1, 0.1, 0.12};
    s.frameCamera({-1.0, 2.0, -1.2}, {0, 0, 1});
    s.defaultLights();
    return s;
}

}  // namespace

const std::vector<BuiltinInfo>& builtinScenes() {
    static const std::vector<BuiltinInfo> list = {
        {"default", 1, 1, 1, "union, intersection and difference on a floor, with a glass ball"},
        {"balls", 3, 0, 5, "SPD sphereflake: 1 + 9 + ... + 9^SIZE spheres and a floor polygon"},
        {"drilled", 6, 1, 40, "a block minus SIZE^3 spheres (CSG stress)"},
        {"lattice", 6, 1, 30, "SIZE^3 cells of (cube ∩ sphere) − cylinder, cut by a slab (CSG stress)"},
    };
    return list;
}

Scene makeBuiltin(const std::string& name, int size) {
    for (const BuiltinInfo& info : builtinScenes()) {
        if (name != info.name) continue;
        if (size < 0) size = info.defaultSize;
        if (size < info.minSize || size > info.maxSize)
            throw SceneError("builtin:" + name + ": size " + std::to_string(size) + " is outside [" +
                             std::to_string(info.minSize) + ", " + std::to_string(info.maxSize) + "]");
        if (name == "default") return defaultScene();
        if (name == "balls") return ballsScene(size);
        if (name == "drilled") return drilledScene(size);
        if (name == "lattice") return latticeScene(size);
    }
    std::string names;
    for (const BuiltinInfo& info : builtinScenes()) names += std::string(names.empty() ? "" : ", ") + info.name;
    throw SceneError("builtin:" + name + ": unknown built-in scene (available: " + names + ")");
}

}  // namespace lancer
