#include "app/bench/scad_export.h"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/bench/export_tree.h"

namespace lancer::bench {

namespace {

std::string vec(const Vec3& v) {
    return std::string("[")
        .append(shortest(v.x))
        .append(", ")
        .append(shortest(v.y))
        .append(", ")
        .append(shortest(v.z))
        .append("]");
}

/// OpenSCAD's multmatrix takes rows; glm's matrix is column-major, so row i is m[.][i].
std::string multmatrix(const Mat4& m) {
    std::string s = "multmatrix([";
    for (int i = 0; i < 4; ++i) {
        s += "[";
        for (int j = 0; j < 4; ++j) s += shortest(m[j][i]) + (j < 3 ? ", " : "]");
        s += i < 3 ? ", " : "])";
    }
    return s;
}

/// A convex polytope's vertices and faces (each face's vertices clockwise seen from outside, as
/// OpenSCAD's polyhedron wants them), from its planes: every three planes' meeting point that
/// lies inside all of them, and on each plane the vertices within a tolerance of it.
std::string polyhedron(const Polytope& t) {
    const double tol = 1e-9 * std::max(1.0, glm::length(t.bounds.hi - t.bounds.lo));
    std::vector<Vec3> pts;
    const size_t n = t.planes.size();
    for (size_t a = 0; a < n; ++a)
        for (size_t b = a + 1; b < n; ++b)
            for (size_t c = b + 1; c < n; ++c) {
                const Mat3 m =
                    glm::transpose(Mat3(Vec3(t.planes[a]), Vec3(t.planes[b]), Vec3(t.planes[c])));
                if (std::abs(glm::determinant(m)) < 1e-12) continue;
                const Vec3 p = glm::inverse(m) * Vec3(t.planes[a].w, t.planes[b].w, t.planes[c].w);
                bool inside = true;
                for (const glm::dvec4& pl : t.planes)
                    inside = inside && glm::dot(Vec3(pl), p) <= pl.w + tol;
                if (!inside) continue;
                bool known = false;
                for (const Vec3& q : pts) known = known || glm::length(q - p) <= tol;
                if (!known) pts.push_back(p);
            }
    std::string faces;
    for (const glm::dvec4& pl : t.planes) {
        const Vec3 nrm(pl);
        std::vector<int> on;
        Vec3 centre(0.0);
        for (size_t i = 0; i < pts.size(); ++i)
            if (std::abs(glm::dot(nrm, pts[i]) - pl.w) <= tol) {
                on.push_back(int(i));
                centre += pts[i];
            }
        if (on.size() < 3) continue;  // a plane that only touches the solid
        centre /= double(on.size());
        const Vec3 u = glm::normalize(pts[size_t(on[0])] - centre);
        const Vec3 v = glm::cross(nrm, u);
        // Decreasing angle about the outward normal: clockwise seen from outside.
        std::sort(on.begin(), on.end(), [&](int i, int j) {
            const Vec3 pi = pts[size_t(i)] - centre, pj = pts[size_t(j)] - centre;
            return std::atan2(glm::dot(pi, v), glm::dot(pi, u)) >
                   std::atan2(glm::dot(pj, v), glm::dot(pj, u));
        });
        faces += faces.empty() ? "[" : ", [";
        for (size_t k = 0; k < on.size(); ++k)
            faces.append(k ? ", " : "").append(std::to_string(on[k]));
        faces += "]";
    }
    std::string s = "polyhedron(points = [";
    for (size_t i = 0; i < pts.size(); ++i) s.append(i ? ", " : "").append(vec(pts[i]));
    return s + "], faces = [" + faces + "])";
}

struct ScadWriter {
    const Scene& scene;
    std::ostream& os;

    void primitive(uint32_t id, const std::string& indent) {
        const Primitive& p = scene.prims[id];
        if (p.isSurface())
            throw std::invalid_argument("primitive " + std::to_string(id) + " (" +
                                        shapeName(p.shape) + (p.origin.empty() ? "" : ", ") +
                                        p.origin + ") is a surface; OpenSCAD models solids only");
        std::string s;
        std::visit(
            [&](const auto& shape) {
                using T = std::decay_t<decltype(shape)>;
                if constexpr (std::is_same_v<T, Sphere>)
                    s = "translate(" + vec(shape.c) + ") sphere(r = " + shortest(shape.r) + ")";
                else if constexpr (std::is_same_v<T, Block>)
                    s = "translate(" + vec(shape.lo) + ") cube(" + vec(shape.hi - shape.lo) + ")";
                else if constexpr (std::is_same_v<T, Cone>)
                    s = "cylinder(h = " + shortest(shape.h) + ", r1 = " + shortest(shape.r1) +
                        ", r2 = " + shortest(shape.r2) + ")";
                else if constexpr (std::is_same_v<T, Polytope>)
                    s = polyhedron(shape);
                else if constexpr (std::is_same_v<T, Torus>)
                    s = "rotate_extrude() translate([" + shortest(shape.R) +
                        ", 0]) circle(r = " + shortest(shape.r) + ")";
            },
            p.shape);
        os << indent << (p.hasXf ? multmatrix(p.xf.m) + " " : "") << s << ";\n";
    }

    void node(int i, const std::string& indent) {
        const CsgNode& c = scene.tree.nodes[size_t(i)];
        if (c.op == Op::Primitive) {
            primitive(c.prim, indent);
            return;
        }
        os << indent
           << (c.op == Op::Union          ? "union"
               : c.op == Op::Intersection ? "intersection"
                                          : "difference")
           << "() {\n";
        for (int k : operands(scene.tree, i)) node(k, indent + "  ");
        os << indent << "}\n";
    }
};

}  // namespace

void writeScad(std::ostream& os, const Scene& scene, int fn) {
    if (scene.tree.empty()) throw std::invalid_argument("the scene has no primitives");
    os << "// Written by `lancer export --scad`: " << scene.name << "\n"
       << "// Curved primitives are faceted at $fn segments a circle (openscad -D '$fn=N').\n"
       << "$fn = " << fn << ";\n";
    ScadWriter{scene, os}.node(scene.tree.root, "");
}

}  // namespace lancer::bench
