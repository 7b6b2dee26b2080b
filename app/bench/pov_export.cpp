#include "app/bench/pov_export.h"

#include <cmath>
#include <cstdio>
#include <ostream>
#include <stdexcept>
#include <vector>

#include "app/bench/export_tree.h"

namespace lancer::bench {

namespace {

/// A number as POV-Ray reads it back to the last bit.
std::string n(double v) { return shortest(v); }

std::string vec(const Vec3& v) {
    std::string s = "<";
    s += n(v.x);
    s += ", ";
    s += n(v.y);
    s += ", ";
    s += n(v.z);
    s += ">";
    return s;
}

/// `matrix <...>`: POV-Ray transforms row vectors, x' = x m00 + y m10 + z m20 + m30, so its
/// m_ij is the column-major glm matrix's m[i][j].
std::string matrix(const Mat4& m) {
    std::string s = "matrix <";
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 3; ++j) s += n(m[i][j]) + (i == 3 && j == 2 ? ">" : ", ");
    return s;
}

struct Writer {
    const Scene& scene;
    const PovOptions& opt;
    std::ostream& os;

    void primitive(uint32_t id, const std::string& indent) {
        const Primitive& p = scene.prims[id];
        std::string head;
        std::visit(
            [&](const auto& s) {
                using T = std::decay_t<decltype(s)>;
                if constexpr (std::is_same_v<T, Sphere>) {
                    head = "sphere { " + vec(s.c) + ", " + n(s.r);
                } else if constexpr (std::is_same_v<T, Block>) {
                    head = "box { " + vec(s.lo) + ", " + vec(s.hi);
                } else if constexpr (std::is_same_v<T, Cone>) {
                    if (s.r1 == s.r2)
                        head = "cylinder { <0, 0, 0>, <0, 0, " + n(s.h) + ">, " + n(s.r1);
                    else
                        head =
                            "cone { <0, 0, 0>, " + n(s.r1) + ", <0, 0, " + n(s.h) + ">, " + n(s.r2);
                    if (s.open) head += " open";
                } else if constexpr (std::is_same_v<T, Triangle>) {
                    if (s.smooth)
                        head = "smooth_triangle { " + vec(s.p[0]) + ", " + vec(s.n[0]) + ", " +
                               vec(s.p[1]) + ", " + vec(s.n[1]) + ", " + vec(s.p[2]) + ", " +
                               vec(s.n[2]);
                    else
                        head =
                            "triangle { " + vec(s.p[0]) + ", " + vec(s.p[1]) + ", " + vec(s.p[2]);
                } else if constexpr (std::is_same_v<T, Polytope>) {
                    // POV-Ray's plane {n, d} holds the points where dot(n, x) < d, as ours.
                    head = "intersection {";
                    for (const glm::dvec4& pl : s.planes)
                        head += " plane { " + vec(Vec3(pl)) + ", " + n(pl.w) + " }";
                } else if constexpr (std::is_same_v<T, Torus>) {
                    // POV-Ray's torus turns about y; ours about z. Its Sturm solver is the
                    // robust one on grazing rays.
                    head = "torus { " + n(s.R) + ", " + n(s.r) + " sturm rotate <90, 0, 0>";
                } else {
                    // Closed explicitly: the first point again (an even-odd polygon, as ours).
                    head = "polygon { " + std::to_string(s.p.size() + 1);
                    for (const Vec3& v : s.p) head += ", " + vec(v);
                    head += ", " + vec(s.p.front());
                }
            },
            p.shape);
        os << indent << head;
        if (p.hasXf) os << " " << matrix(p.xf.m);
        if (!opt.depth) os << " material { M" << p.material << " }";
        os << " }\n";
    }

    void node(int i, const std::string& indent) {
        const CsgNode& c = scene.tree.nodes[size_t(i)];
        if (c.op == Op::Primitive) {
            primitive(c.prim, indent);
            return;
        }
        const std::vector<int> parts = operands(scene.tree, i);
        os << indent
           << (c.op == Op::Union          ? "union"
               : c.op == Op::Intersection ? "intersection"
                                          : "difference")
           << " {\n";
        for (int p : parts) node(p, indent + "  ");
        os << indent << "}\n";
    }
};

}  // namespace

double depthRangeOf(const Scene& scene, const Camera& camera) {
    Vec3 f, r, u;
    camera.basis(f, r, u);
    double far = 0.0;
    for (int k = 0; k < 8; ++k) {
        const Vec3 c((k & 1) ? scene.bounds.hi.x : scene.bounds.lo.x,
                     (k & 2) ? scene.bounds.hi.y : scene.bounds.lo.y,
                     (k & 4) ? scene.bounds.hi.z : scene.bounds.lo.z);
        far = std::max(far, camera.projection == Projection::Orthographic
                                ? glm::dot(c - camera.from, f)
                                : glm::length(c - camera.from));
    }
    return std::isfinite(far) && far > 0.0 ? far * 1.01 : 1.0;
}

void writePov(std::ostream& os, const Scene& scene, const Camera& cam, const PovOptions& opt) {
    if (scene.tree.empty()) throw std::invalid_argument("the scene has no primitives");
    Vec3 f, r, u;
    cam.basis(f, r, u);
    const bool ortho = cam.projection == Projection::Orthographic;
    // Lancer's pixel centre (x + 0.5, y + 0.5) of a w x h image is at sx = (2 (x + 0.5) / w - 1)
    // w / h, sy = 1 - 2 (y + 0.5) / h in units of the half height `half` of the image plane at
    // distance 1 (orthographic: of the image), along R and U. POV-Ray 3.7's perspective and
    // orthographic cameras (tracepixel.cpp) put pixel (x, y), y = 0 on top, at x0 = (x + 0.5) /
    // w - 0.5 and y0 = 0.5 - (y + 0.5) / h along `right` and `up`: so right = 2 half (w / h) R
    // and up = 2 half U, with direction F (perspective: the image plane at distance 1).
    const double half = ortho ? 0.5 * cam.orthoHeight : std::tan(glm::radians(cam.fov) * 0.5);
    os << "// Written by `lancer export` for POV-Ray 3.7: " << scene.name << "\n"
       << "// Lancer's camera: from " << vec(cam.from) << ", at " << vec(cam.at) << ", up "
       << vec(cam.up)
       << (ortho ? ", orthographic height " + n(cam.orthoHeight)
                 : ", vertical field of view " + n(cam.fov) + " degrees")
       << ".\n"
       << "// Pixel (x, y), y = 0 on top, is traced through its centre along Lancer's ray.\n"
       << "#version 3.7;\n"
       << "global_settings { assumed_gamma 1.0 max_trace_level " << opt.bounces + 1
       << " ambient_light rgb <1, 1, 1> }\n"
       << "camera {\n  " << (ortho ? "orthographic" : "perspective") << "\n  location "
       << vec(cam.from) << "\n  direction " << vec(f) << "\n  right " << vec(r) << " * "
       << n(2.0 * half) << " * image_width / image_height\n  up " << vec(u) << " * "
       << n(2.0 * half) << "\n}\n";
    if (opt.depth) {
        const double range = opt.depthRange > 0.0 ? opt.depthRange : depthRangeOf(scene, cam);
        const std::string d =
            ortho ? "((x - " + n(cam.from.x) + ") * " + n(f.x) + " + (y - " + n(cam.from.y) +
                        ") * " + n(f.y) + " + (z - " + n(cam.from.z) + ") * " + n(f.z) + ")"
                  : "sqrt((x - " + n(cam.from.x) + ") * (x - " + n(cam.from.x) + ") + (y - " +
                        n(cam.from.y) + ") * (y - " + n(cam.from.y) + ") + (z - " + n(cam.from.z) +
                        ") * (z - " + n(cam.from.z) + "))";
        os << "// Depth: grey 1 - distance / " << n(range) << ", black where nothing is hit.\n"
           << "#declare LancerDepthRange = " << n(range) << ";\n"
           << "background { color rgb <0, 0, 0> }\n"
           << "#declare LancerDepth = texture {\n  pigment { function { 1 - " << d
           << " / LancerDepthRange }\n    color_map { [0 color rgb <0, 0, 0>] [1 color rgb <1, "
              "1, 1>] } }\n  finish { ambient 0 diffuse 0 emission 1 }\n}\n"
           << "object {\n";
        Writer{scene, opt, os}.node(scene.tree.root, "  ");
        os << "  texture { LancerDepth }\n}\n";
        return;
    }
    os << "background { color rgb " << vec(scene.background) << " }\n";
    for (const Light& l : scene.lights)
        os << "light_source { " << vec(l.position) << " color rgb " << vec(l.color) << " }\n";
    // Whitted's terms: ambient and diffuse times the colour, Phong's highlight, mirror
    // reflection; the transmitted share as the pigment's transmit, with the index of refraction.
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const Material& m = scene.materials[i];
        os << "#declare M" << i << " = material {\n  texture {\n    pigment { color rgb "
           << vec(m.color);
        if (m.transmit > 0.0) os << " transmit " << n(std::min(1.0, m.transmit));
        os << " }\n    finish { ambient " << n(m.ambient) << " diffuse " << n(m.diffuse);
        if (m.specular > 0.0) os << " phong " << n(m.specular) << " phong_size " << n(m.shininess);
        if (m.reflect > 0.0) os << " reflection " << n(m.reflect);
        os << " }\n  }\n";
        if (m.transmit > 0.0) os << "  interior { ior " << n(m.ior) << " }\n";
        os << "}\n";
    }
    Writer{scene, opt, os}.node(scene.tree.root, "");
}

}  // namespace lancer::bench
