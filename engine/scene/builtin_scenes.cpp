#include "engine/scene/builtin_scenes.h"

#include <array>
#include <charconv>
#include <cmath>
#include <functional>
#include <numbers>

namespace lancer {

namespace {

constexpr std::string_view kPrefix = "builtin:";

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
    Scene finish(int root, const std::string& name, std::optional<int> size = std::nullopt) {
        s.tree.root = root;
        s.name = builtinSpec(name, size);
        s.prepare();
        return std::move(s);
    }
    /// finish(), then the look the generated scenes share: a background, a camera framed on the
    /// bounds looking along `viewDir` (z up) and the default lights.
    Scene finishFramed(int root, const std::string& name, int size, const Vec3& background,
                       const Vec3& viewDir) {
        Scene scene = finish(root, name, size);
        scene.background = background;
        scene.frameCamera(viewDir, {0, 0, 1});
        scene.defaultLights();
        return scene;
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
    parts.push_back(
        b.op(Op::Union, b.prim(Sphere{{-3.0, 0.0, 0.6}, 0.9}, red),
             b.prim(cylinderZ(0.5, 1.6), red, Transform::translate({-3.0, 0.0, -1.0}))));
    // Intersection: a rounded cube (cube ∩ sphere).
    parts.push_back(b.op(Op::Intersection, b.prim(cube({0.0, 0.0, 0.0}, 1.0), green),
                         b.prim(Sphere{{0.0, 0.0, 0.0}, 1.35}, green)));
    // Difference: a cube drilled by a sphere and a cylinder across it.
    int drilled = b.op(Op::Difference, b.prim(cube({3.0, 0.0, 0.0}, 1.0), blue),
                       b.prim(Sphere{{3.0, 0.0, 1.0}, 0.9}, blue));
    drilled =
        b.op(Op::Difference, drilled,
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
    Scene s = b.finish(b.all(Op::Union, leaves), "balls", size);
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
    return b.finishFramed(b.op(Op::Difference, block, b.all(Op::Union, holes)), "drilled", n,
                          {0.1, 0.1, 0.12}, {-1.0, 2.2, -1.4});
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
                int rounded = b.op(Op::Intersection, b.prim(cube(c, half), m),
                                   b.prim(Sphere{c, 1.3 * half}, m));
                int bore = b.prim(cylinderZ(0.45 * half, 2.4 * half), m,
                                  Transform::translate(c - Vec3(0, 0, 1.2 * half)));
                cells.push_back(b.op(Op::Difference, rounded, bore));
            }
    int slab = b.prim(Block{{-1.1, -1.1, -0.55}, {1.1, 1.1, 0.55}}, ma);
    return b.finishFramed(b.op(Op::Intersection, b.all(Op::Union, cells), slab), "lattice", n,
                          {0.1, 0.1, 0.12}, {-1.0, 2.0, -1.2});
}

// OpenSCAD's example024: a Menger sponge of `level` levels (a cube less three sets of bars,
// 3 (8^level - 1) / 7 of them), turned so that a diagonal stands up, then cut by the plane
// z = 0. Every primitive sits under one rotation, and none is aligned with the world's axes.
Scene spongeScene(int level) {
    SceneBuilder b;
    const double d = 2.0;
    const int m = b.material(mat({0.85, 0.75, 0.45}, 0.8, 0.3, 40.0));
    // OpenSCAD's rotate([45, atan(1 / sqrt(2)), 0]): about x, then about y.
    const Transform turn =
        Transform::rotate(std::atan(1.0 / std::sqrt(2.0)) * 180.0 / std::numbers::pi, {0, 1, 0}) *
        Transform::rotate(45.0, {1, 0, 0});
    std::vector<int> bars;
    // Bars along `axis` of side `side` centred at (u, v) on the other two axes, and the eight
    // around each at the next level, as OpenSCAD's menger_negative().
    std::function<void(int, double, double, double, int)> negative =
        [&](int axis, double side, double u, double v, int left) {
            const double l = side / 3.0;
            Vec3 c(0.0), h(0.0);
            c[(axis + 1) % 3] = u;
            c[(axis + 2) % 3] = v;
            h[axis] = 0.55 * d;
            h[(axis + 1) % 3] = h[(axis + 2) % 3] = 0.5 * l;
            bars.push_back(b.prim(Block{c - h, c + h}, m, turn));
            if (left > 1)
                for (int i = -1; i <= 1; ++i)
                    for (int j = -1; j <= 1; ++j)
                        if (i || j) negative(axis, l, u + i * l, v + j * l, left - 1);
        };
    for (int axis = 0; axis < 3; ++axis) negative(axis, d, 0.0, 0.0, level);
    const int sponge =
        b.op(Op::Difference, b.prim(cube(Vec3(0.0), 0.5 * d), m, turn), b.all(Op::Union, bars));
    const int below = b.prim(Block{{-d, -d, -2.0 * d}, {d, d, 0.0}}, m);
    return b.finishFramed(b.op(Op::Difference, sponge, below), "sponge", level, {0.1, 0.1, 0.12},
                          {-0.8, 1.6, -2.0});
}

// SPD-style "tetra": a Sierpinski tetrahedron of 4^SIZE triangles (surfaces in one union).
Scene tetraScene(int size) {
    SceneBuilder b;
    int m = b.material(mat({1.0, 0.2, 0.2}, 0.7, 0.3, 20.0));
    std::vector<int> leaves;
    std::function<void(const std::array<Vec3, 4>&, int)> split = [&](const std::array<Vec3, 4>& v,
                                                                     int depth) {
        if (depth == 0) {
            static const int faces[4][3] = {{0, 1, 2}, {0, 3, 1}, {0, 2, 3}, {1, 3, 2}};
            for (const auto& f : faces) {
                Triangle t;
                for (int i = 0; i < 3; ++i) t.p[i] = v[size_t(f[i])];
                leaves.push_back(b.prim(t, m));
            }
            return;
        }
        for (int corner = 0; corner < 4; ++corner) {
            std::array<Vec3, 4> w;
            for (int i = 0; i < 4; ++i) w[size_t(i)] = 0.5 * (v[size_t(corner)] + v[size_t(i)]);
            split(w, depth - 1);
        }
    };
    double r = 1.0;
    split({Vec3(r, r, r), Vec3(-r, -r, r), Vec3(-r, r, -r), Vec3(r, -r, -r)}, size - 1);
    return b.finishFramed(b.all(Op::Union, leaves), "tetra", size, {0.078, 0.361, 0.753},
                          {-0.45, 1.0, 0.35});
}

// SPD-style "rings": SIZE x SIZE rings, each a chain of spheres joined by open cylinders
// (surfaces), over a floor polygon: solids and surfaces in one union.
Scene ringsScene(int size) {
    SceneBuilder b;
    int ballM = b.material(mat({1.0, 0.9, 0.7}, 0.5, 0.5, 3.0827, 0.5));
    int rodM = b.material(mat({0.7, 0.7, 0.9}, 0.7, 0.3, 20.0));
    int floorM = b.material(mat({1.0, 0.75, 0.33}, 0.8, 0.0, 1.0));
    std::vector<int> leaves;
    const int beads = 10;
    const double ringR = 1.0, bead = 0.12, rod = 0.045;
    for (int i = 0; i < size; ++i)
        for (int j = 0; j < size; ++j) {
            Vec3 c(2.6 * (i - 0.5 * (size - 1)), 2.6 * (j - 0.5 * (size - 1)), 0.4 * ((i + j) % 2));
            // Tilt alternate rings so the chains interleave.
            Transform tilt =
                Transform::translate(c) * Transform::rotate(20.0 * ((i * 3 + j) % 4), {1, 1, 0});
            std::vector<Vec3> pts;
            for (int k = 0; k < beads; ++k) {
                double a = 2.0 * M_PI * k / beads;
                pts.push_back(tilt.point({ringR * std::cos(a), ringR * std::sin(a), 0.0}));
            }
            for (int k = 0; k < beads; ++k) {
                leaves.push_back(b.prim(Sphere{pts[size_t(k)], bead}, ballM));
                Vec3 p = pts[size_t(k)], q = pts[size_t((k + 1) % beads)];
                leaves.push_back(b.prim(Cone{rod, rod, glm::length(q - p), true}, rodM,
                                        Transform::alongAxis(p, glm::normalize(q - p))));
            }
        }
    double half = 1.3 * size + 1.5;
    Polygon floor;
    makePolygon(
        {{half, half, -1.2}, {-half, half, -1.2}, {-half, -half, -1.2}, {half, -half, -1.2}},
        floor);
    leaves.push_back(b.prim(floor, floorM));
    return b.finishFramed(b.all(Op::Union, leaves), "rings", size, {0.078, 0.361, 0.753},
                          {-1.0, 1.6, -1.1});
}

}  // namespace

const std::vector<BuiltinInfo>& builtinScenes() {
    static const std::vector<BuiltinInfo> list = {
        {"default", 1, 1, 1, "union, intersection and difference on a floor, with a glass ball"},
        {"balls", 3, 0, 6, "SPD sphereflake: 1 + 9 + ... + 9^SIZE spheres and a floor polygon"},
        {"drilled", 6, 1, 40, "a block minus SIZE^3 spheres (CSG stress)"},
        {"lattice", 6, 1, 30,
         "SIZE^3 cells of (cube ∩ sphere) − cylinder, cut by a slab (CSG stress)"},
        {"tetra", 3, 1, 7, "SPD-style Sierpinski tetrahedron: 4^SIZE triangles"},
        {"sponge", 3, 1, 5,
         "OpenSCAD's example024: a Menger sponge of SIZE levels turned on its diagonal, cut by "
         "a plane (turned CSG)"},
        {"rings", 3, 1, 20,
         "SPD-style rings: SIZE^2 chains of 10 spheres and 10 open cylinders, a floor"},
    };
    return list;
}

bool isBuiltinSpec(std::string_view spec) { return spec.substr(0, kPrefix.size()) == kPrefix; }

std::optional<BuiltinSpec> parseBuiltinSpec(const std::string& spec) {
    if (!isBuiltinSpec(spec)) return std::nullopt;
    std::string rest = spec.substr(kPrefix.size());
    size_t colon = rest.find(':');
    if (colon == std::string::npos) return BuiltinSpec{rest, std::nullopt};
    std::string num = rest.substr(colon + 1);
    int size = 0;
    auto r = std::from_chars(num.data(), num.data() + num.size(), size);
    if (r.ec != std::errc() || r.ptr != num.data() + num.size())
        throw SceneError(spec + ": the size after the second ':' must be an integer");
    return BuiltinSpec{rest.substr(0, colon), size};
}

std::string builtinSpec(const std::string& name, std::optional<int> size) {
    std::string spec = std::string(kPrefix) + name;
    if (size) {
        spec += ':';
        spec += std::to_string(*size);
    }
    return spec;
}

const BuiltinInfo* findBuiltin(std::string_view name) {
    for (const BuiltinInfo& info : builtinScenes())
        if (name == info.name) return &info;
    return nullptr;
}

Scene makeBuiltin(const BuiltinSpec& spec) {
    const BuiltinInfo* info = findBuiltin(spec.name);
    if (!info) {
        std::string names;
        for (const BuiltinInfo& b : builtinScenes())
            names += std::string(names.empty() ? "" : ", ") + b.name;
        throw SceneError(builtinSpec(spec.name) + ": unknown built-in scene (available: " + names +
                         ")");
    }
    const int size = spec.size.value_or(info->defaultSize);
    if (size < info->minSize || size > info->maxSize)
        throw SceneError(builtinSpec(spec.name) + ": size " + std::to_string(size) +
                         " is outside [" + std::to_string(info->minSize) + ", " +
                         std::to_string(info->maxSize) + "]");
    const std::string& name = spec.name;
    if (name == "default") return defaultScene();
    if (name == "balls") return ballsScene(size);
    if (name == "drilled") return drilledScene(size);
    if (name == "lattice") return latticeScene(size);
    if (name == "tetra") return tetraScene(size);
    if (name == "sponge") return spongeScene(size);
    return ringsScene(size);
}

Scene makeBuiltin(const std::string& name, int size) {
    return makeBuiltin(BuiltinSpec{name, size < 0 ? std::nullopt : std::optional<int>(size)});
}

}  // namespace lancer
