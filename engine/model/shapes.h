// The primitives, each in its own local frame. `spans` returns the ray's spans over the whole
// line (any t), sorted; solids give at most one span of positive length (a torus up to two),
// surfaces give zero-length spans. `normal` is the outward (solids) or geometric (surfaces) normal.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <variant>
#include <vector>

#include "engine/model/span.h"

namespace lancer {

/// Sphere of centre `c` and radius `r` > 0.
struct Sphere {
    Vec3 c{0.0};
    double r = 1.0;
};

/// The arithmetic of a primitive's test (--precision): the line-shape computation, in the
/// primitive's own frame, in double (the reference) or in single precision (what a float
/// tracer such as Embree computes; the transform, the walk and the CSG stay in double).
enum class Precision : uint8_t { Double, Float };

/// How far a float test's t can stray from the double one at parameter t of `ray`: 1e-5 (some
/// 170 times single precision's rounding) of the magnitudes the test reads, the ray's origin
/// and the distance along the ray, in units of t. The bounds that double tests may meet exactly
/// (a region's window, a box's near depth) are widened by it under Precision::Float.
inline double floatSlack(const Ray& ray, double t) {
    const Vec3 ad = glm::abs(ray.d), ao = glm::abs(ray.o);
    const double d = std::max({ad.x, ad.y, ad.z}), o = std::max({ao.x, ao.y, ao.z});
    return d > 0.0 ? 1e-5 * (o / d + std::abs(t)) : 0.0;
}

/// A ray in single precision: what a primitive's float test reads.
struct RayF {
    glm::vec3 o{0.0f};
    glm::vec3 d{0.0f, 0.0f, 1.0f};
};

/// Spans of the sphere (c, r) along `ray`, in the ray's precision (Ray: double, RayF: float):
/// inline, for shapeSpans and for the scene's packed sphere table (Scene::primSpans), which
/// must give the same bits.
template <class R, class T = typename decltype(R::o)::value_type>
inline int sphereSpansOf(const glm::vec<3, T>& c, T r, const R& ray, uint32_t prim, Span* out) {
    // Robust form (Haines et al., Ray Tracing Gems ch. 7): the discriminant from the distance
    // between the centre and the line, which keeps precision for far or grazing rays.
    const glm::vec<3, T> f = ray.o - c;
    const T a = glm::dot(ray.d, ray.d);
    const T b = -glm::dot(f, ray.d);
    const glm::vec<3, T> l = f + (b / a) * ray.d;
    const T disc = a * (r * r - glm::dot(l, l));
    if (!(disc > T(0))) return 0;
    const T cc = glm::dot(f, f) - r * r;
    const T q = b + std::copysign(std::sqrt(disc), b);
    T t0, t1;
    if (q == T(0)) {
        t0 = t1 = b / a;
    } else {
        t0 = cc / q;
        t1 = q / a;
    }
    if (t0 > t1) std::swap(t0, t1);
    if (!(t0 < t1)) return 0;
    out[0] = {{double(t0), prim, 0, false}, {double(t1), prim, 0, false}};
    return 1;
}

/// sphereSpansOf in double precision.
inline int sphereSpans(const Vec3& c, double r, const Ray& ray, uint32_t prim, Span* out) {
    return sphereSpansOf(c, r, ray, prim, out);
}

/// Axis-aligned box [lo, hi] with lo < hi on every axis. Parts 0..5: -x, +x, -y, +y, -z, +z.
struct Block {
    Vec3 lo{-1.0}, hi{1.0};
};

/// Capped (truncated) cone along +z: radius r1 at z = 0, r2 at z = h. r1 = r2 is a cylinder.
/// Parts: 0 side, 1 bottom cap, 2 top cap. As a surface (`open`), no caps and no inside.
struct Cone {
    double r1 = 1.0, r2 = 1.0, h = 1.0;
    bool open = false;
};

/// Triangle; with `smooth`, vertex normals are interpolated for shading (NFF `pp`).
struct Triangle {
    Vec3 p[3];
    Vec3 n[3];
    bool smooth = false;
};

/// Planar polygon, convex or not (even-odd rule), at least three vertices.
struct Polygon {
    std::vector<Vec3> p;
    Vec3 n{0.0};     ///< unit plane normal (Newell)
    double d = 0.0;  ///< plane: dot(n, x) = d
    int drop = 2;    ///< axis dropped for the 2D inside test
};

/// Convex polyhedron: the points where dot(plane.xyz, x) <= plane.w for every plane (at most
/// 255 planes; part k is plane k). `bounds` holds it (the caller computes it from its vertices,
/// which a plane list alone does not give cheaply). OpenSCAD's linear extrusions are built of it.
struct Polytope {
    std::vector<glm::dvec4> planes;  ///< unit normal and offset of each face's plane
    Box3 bounds;                     ///< a box holding the solid
};

/// Torus about the z axis, centred at the origin: the points within `r` of the circle of radius
/// `R` in the plane z = 0 (OpenSCAD's rotate_extrude of a circle of radius r centred at x = R).
/// R >= r > 0: a ring torus, or a horn torus at R = r; a spindle torus (R < r, whose surface
/// crosses itself) is refused by the readers. One part (0).
struct Torus {
    double R = 2.0;  ///< major radius: the centre circle's
    double r = 1.0;  ///< minor radius: the tube's
};

using Shape = std::variant<Sphere, Block, Cone, Triangle, Polygon, Polytope, Torus>;

/// Spans of the line `r` (in the shape's frame) through the shape, written to `out` (capacity 2).
int shapeSpans(const Shape& s, const Ray& r, uint32_t prim, Span* out);
/// The same test in single precision (the shape's parameters rounded to float).
int shapeSpans(const Shape& s, const RayF& r, uint32_t prim, Span* out);
/// Normal at local point `p` on part `part` (not normalised for transformed shapes' sake).
Vec3 shapeNormal(const Shape& s, const Vec3& p, uint8_t part);
/// Local bounds.
Box3 shapeBounds(const Shape& s);
/// True for shapes with no inside (polygons, triangles, open cones).
bool shapeIsSurface(const Shape& s);
/// Whether `p` (in the shape's frame) lies strictly inside the solid, for the convex solids
/// (sphere, box, closed cone, polytope); false for every other shape. Points all held by a
/// convex solid hold their convex hull: a cell whose corners it holds lies inside it.
bool convexSolidHolds(const Shape& s, const Vec3& p);
const char* shapeName(const Shape& s);

/// Build a polygon (computes plane and projection axis). Returns false if degenerate.
bool makePolygon(std::vector<Vec3> pts, Polygon& out);

}  // namespace lancer
