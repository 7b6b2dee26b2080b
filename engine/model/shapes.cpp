#include "engine/model/shapes.h"

#include <cmath>
#include <limits>

#include "engine/model/quartic.h"

namespace lancer {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
    using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // clang 14 lacks C++20 aggregate deduction

// Each test is written once over its ray's scalar T (double, or float for --precision float):
// the shape's parameters are rounded to T where they are read, and the spans' t widened back.
template <class R>
using ScalarOf = typename decltype(R::o)::value_type;
template <class T>
using V3 = glm::vec<3, T>;
template <class T>
constexpr T tInf = std::numeric_limits<T>::infinity();

template <class R, class T = ScalarOf<R>>
int blockSpans(const Block& b, const R& r, uint32_t prim, Span* out) {
    T t0 = -tInf<T>, t1 = tInf<T>;
    uint8_t p0 = 0, p1 = 0;
    for (int a = 0; a < 3; ++a) {
        const T lo = T(b.lo[a]), hi = T(b.hi[a]);
        if (r.d[a] == T(0)) {
            if (r.o[a] < lo || r.o[a] > hi) return 0;
            continue;
        }
        T inv = T(1) / r.d[a];
        T ta = (lo - r.o[a]) * inv, tb = (hi - r.o[a]) * inv;
        uint8_t pa = uint8_t(2 * a), pb = uint8_t(2 * a + 1);
        if (ta > tb) {
            std::swap(ta, tb);
            std::swap(pa, pb);
        }
        if (ta > t0) t0 = ta, p0 = pa;
        if (tb < t1) t1 = tb, p1 = pb;
    }
    if (!(t0 < t1)) return 0;
    out[0] = {{double(t0), prim, p0, false}, {double(t1), prim, p1, false}};
    return 1;
}

// Parametric interval where a*t^2 + b*t + c <= 0, as up to two pieces.
template <class T>
int quadricInside(T a, T b, T c, T* lo, T* hi) {
    if (a == T(0)) {
        if (b == T(0)) {
            if (c <= T(0)) {
                lo[0] = -tInf<T>;
                hi[0] = tInf<T>;
                return 1;
            }
            return 0;
        }
        T t = -c / b;
        if (b > T(0)) {
            lo[0] = -tInf<T>;
            hi[0] = t;
        } else {
            lo[0] = t;
            hi[0] = tInf<T>;
        }
        return 1;
    }
    T disc = b * b - T(4) * a * c;
    if (disc <= T(0)) {
        if (a < T(0)) {
            lo[0] = -tInf<T>;
            hi[0] = tInf<T>;
            return 1;
        }
        return 0;
    }
    T q = T(-0.5) * (b + std::copysign(std::sqrt(disc), b));
    T t0 = q / a, t1 = (q != T(0)) ? c / q : -t0;
    if (t0 > t1) std::swap(t0, t1);
    if (a > T(0)) {
        lo[0] = t0;
        hi[0] = t1;
        return 1;
    }
    lo[0] = -tInf<T>;
    hi[0] = t0;
    lo[1] = t1;
    hi[1] = tInf<T>;
    return 2;
}

template <class T>
struct ConeQuadric {
    T a, b, c;
};
template <class R, class T = ScalarOf<R>>
ConeQuadric<T> coneQuadric(const Cone& k, const R& r) {
    T s = T((k.r2 - k.r1) / k.h);  // radius slope
    T rz = T(k.r1) + s * r.o.z;    // radius at the origin's height
    T a = r.d.x * r.d.x + r.d.y * r.d.y - s * s * r.d.z * r.d.z;
    T b = T(2) * (r.o.x * r.d.x + r.o.y * r.d.y - s * r.d.z * rz);
    T c = r.o.x * r.o.x + r.o.y * r.o.y - rz * rz;
    return {a, b, c};
}

template <class R, class T = ScalarOf<R>>
int coneSpans(const Cone& k, const R& r, uint32_t prim, Span* out) {
    ConeQuadric<T> q = coneQuadric(k, r);
    const T h = T(k.h);
    // Slab 0 <= z <= h.
    T z0 = -tInf<T>, z1 = tInf<T>;
    uint8_t c0 = 0, c1 = 0;
    if (r.d.z == T(0)) {
        if (r.o.z < T(0) || r.o.z > h) return 0;
    } else {
        z0 = -r.o.z / r.d.z;
        z1 = (h - r.o.z) / r.d.z;
        c0 = 1, c1 = 2;
        if (z0 > z1) std::swap(z0, z1), std::swap(c0, c1);
    }
    if (k.open) {
        // The side surface only: roots of the quadric inside the slab.
        T disc = q.b * q.b - T(4) * q.a * q.c;
        if (q.a == T(0) || !(disc > T(0))) return 0;
        T qq = T(-0.5) * (q.b + std::copysign(std::sqrt(disc), q.b));
        T t[2] = {qq / q.a, qq != T(0) ? q.c / qq : -qq / q.a};
        if (t[0] > t[1]) std::swap(t[0], t[1]);
        int n = 0;
        for (T ti : t)
            if (ti >= z0 && ti <= z1)
                out[n++] = {{double(ti), prim, 0, false}, {double(ti), prim, 0, false}};
        return n;
    }
    T lo[2], hi[2];
    int pieces = quadricInside(q.a, q.b, q.c, lo, hi);
    // Within the slab the radius is non-negative, so only one nappe lies there and the solid is
    // convex: the hull of the pieces clipped to the slab is its one span.
    T t0 = tInf<T>, t1 = -tInf<T>;
    uint8_t p0 = 0, p1 = 0;
    for (int i = 0; i < pieces; ++i) {
        T a = std::max(lo[i], z0), b = std::min(hi[i], z1);
        if (!(a < b)) continue;
        if (a < t0) t0 = a, p0 = (lo[i] >= z0) ? 0 : c0;
        if (b > t1) t1 = b, p1 = (hi[i] <= z1) ? 0 : c1;
    }
    if (!(t0 < t1) || !std::isfinite(t0) || !std::isfinite(t1)) return 0;
    out[0] = {{double(t0), prim, p0, false}, {double(t1), prim, p1, false}};
    return 1;
}

template <class R, class T = ScalarOf<R>>
int triangleSpans(const Triangle& tr, const R& r, uint32_t prim, Span* out) {
    // Möller-Trumbore, both sides.
    const V3<T> p0(tr.p[0]);
    V3<T> e1 = V3<T>(tr.p[1]) - p0, e2 = V3<T>(tr.p[2]) - p0;
    V3<T> pv = glm::cross(r.d, e2);
    T det = glm::dot(e1, pv);
    if (det == T(0) || !std::isfinite(det)) return 0;
    T inv = T(1) / det;
    V3<T> tv = r.o - p0;
    T u = glm::dot(tv, pv) * inv;
    if (u < T(0) || u > T(1)) return 0;
    V3<T> qv = glm::cross(tv, e1);
    T v = glm::dot(r.d, qv) * inv;
    if (v < T(0) || u + v > T(1)) return 0;
    double t = double(glm::dot(e2, qv) * inv);
    out[0] = {{t, prim, 0, false}, {t, prim, 0, false}};
    return 1;
}

template <class R, class T = ScalarOf<R>>
int polygonSpans(const Polygon& pg, const R& r, uint32_t prim, Span* out) {
    const V3<T> pn(pg.n);
    T dn = glm::dot(pn, r.d);
    if (dn == T(0)) return 0;
    T t = (T(pg.d) - glm::dot(pn, r.o)) / dn;
    V3<T> p = r.o + t * r.d;
    int ax = (pg.drop + 1) % 3, ay = (pg.drop + 2) % 3;
    T px = p[ax], py = p[ay];
    bool inside = false;
    size_t n = pg.p.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        T xi = T(pg.p[i][ax]), yi = T(pg.p[i][ay]), xj = T(pg.p[j][ax]), yj = T(pg.p[j][ay]);
        if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi) inside = !inside;
    }
    if (!inside) return 0;
    out[0] = {{double(t), prim, 0, false}, {double(t), prim, 0, false}};
    return 1;
}

template <class R, class T = ScalarOf<R>>
int polytopeSpans(const Polytope& k, const R& r, uint32_t prim, Span* out) {
    // Kay and Kajiya's slab clipping, one plane at a time: the ray enters where it crosses a
    // plane whose normal faces it and leaves where it crosses one facing away.
    T t0 = -tInf<T>, t1 = tInf<T>;
    uint8_t p0 = 0, p1 = 0;
    for (size_t i = 0; i < k.planes.size(); ++i) {
        const glm::dvec4& pl = k.planes[i];
        const V3<T> n(pl);
        T dn = glm::dot(n, r.d);
        T dist = T(pl.w) - glm::dot(n, r.o);
        if (dn == T(0)) {
            if (dist < T(0)) return 0;
            continue;
        }
        T t = dist / dn;
        if (dn < T(0)) {
            if (t > t0) t0 = t, p0 = uint8_t(i);
        } else if (t < t1) {
            t1 = t, p1 = uint8_t(i);
        }
        if (!(t0 < t1)) return 0;
    }
    if (!std::isfinite(t0) || !std::isfinite(t1)) return 0;
    out[0] = {{double(t0), prim, p0, false}, {double(t1), prim, p1, false}};
    return 1;
}

// The torus's implicit function along the line, g(s) = ((rho - R)^2 + z^2 - r^2) ((rho + R)^2 +
// z^2 - r^2) = (|p|^2 + R^2 - r^2)^2 - 4 R^2 (x^2 + y^2) at p = o + s u, is a quartic in s. It is
// solved in a frame where it is well conditioned: the origin moved to the line's point closest
// to the torus's centre (a ray from 1e6 away would otherwise carry coefficients of 1e24 whose
// rounding swamps the roots), lengths divided by R + r (roots then lie in [-1, 1], so one
// absolute tolerance fits every torus). With the origin there, o is orthogonal to u and the
// quartic has no cubic term.
template <class T>
struct TorusLine {
    V3<T> o, u;  ///< closest point to the centre and unit direction, in units of R + r
    T R, r;      ///< radii in units of R + r
};

// Signed distance to the torus surface at parameter s of the line, and its derivative along
// u (the cosine between u and the outward normal); false on the axis, where the surface's
// nearest point is not unique.
template <class T>
bool torusDistance(const TorusLine<T>& L, T s, T& dist, T& slope) {
    const V3<T> p = L.o + s * L.u;
    const T rho = std::sqrt(p.x * p.x + p.y * p.y);
    if (!(rho > T(0))) return false;
    const T dr = rho - L.R, len = std::sqrt(dr * dr + p.z * p.z);
    if (!(len > T(0))) return false;
    dist = len - L.r;
    slope = (dr * (p.x * L.u.x + p.y * L.u.y) / rho + p.z * L.u.z) / len;
    return true;
}

// Newton steps on the distance itself (not the expanded quartic): it is exact to rounding near
// the surface even for a thin tube, where the expanded coefficients cancel down to r^2. A step
// is kept only while it shrinks the distance and moves less than a quarter of the gap to the
// neighbouring roots, so that roots keep their order and a grazing pair is left as isolated.
template <class T>
void polishTorusRoots(const TorusLine<T>& L, T* s, int n) {
    for (int i = 0; i < n; ++i) {
        T gap = tInf<T>;
        if (i > 0) gap = std::min(gap, s[i] - s[i - 1]);
        if (i + 1 < n) gap = std::min(gap, s[i + 1] - s[i]);
        for (int step = 0; step < 2; ++step) {
            T d0, k0, d1, k1;
            if (!torusDistance(L, s[i], d0, k0) || d0 == T(0)) break;
            const T next = s[i] - d0 / k0;
            if (!(std::abs(next - s[i]) < T(0.25) * gap)) break;
            if (!torusDistance(L, next, d1, k1) || !(std::abs(d1) < std::abs(d0))) break;
            s[i] = next;
        }
    }
}

template <class R, class T = ScalarOf<R>>
int torusSpans(const Torus& k, const R& ray, uint32_t prim, Span* out) {
    const T len = glm::length(ray.d);
    if (!(len > T(0)) || !std::isfinite(len)) return 0;
    const T B = T(k.R) + T(k.r);
    TorusLine<T> L;
    L.u = ray.d / len;
    const T s0 = -glm::dot(ray.o, L.u);
    L.o = (ray.o + s0 * L.u) / B;
    L.R = T(k.R) / B, L.r = T(k.r) / B;
    const T oo = glm::dot(L.o, L.o);
    if (!(oo < T(1))) return 0;  // the line misses the bounding sphere (or is NaN)
    const T R2 = L.R * L.R, q = oo + L.R * L.R - L.r * L.r;
    const T c[5] = {q * q - T(4) * R2 * (L.o.x * L.o.x + L.o.y * L.o.y),
                    T(-8) * R2 * (L.o.x * L.u.x + L.o.y * L.u.y),
                    T(2) * q - T(4) * R2 * (L.u.x * L.u.x + L.u.y * L.u.y), T(0), T(1)};
    // Where |p|^2 = 1.01, g >= (|p|^2 - (R + r)^2)(|p|^2 - (R - r)^2) >= 1e-4 > 0: both ends lie
    // outside, so the sign changes pair up into spans.
    const T h = std::sqrt(T(1.01) - oo);
    T s[4];
    const int n =
        poly::signChangeRoots(c, 4, -h, h, s) & ~1;  // an odd count is a rounding artefact
    polishTorusRoots(L, s, n);
    int spans = 0;
    for (int i = 0; i + 1 < n; i += 2) {
        const double t0 = double((s0 + B * s[i]) / len), t1 = double((s0 + B * s[i + 1]) / len);
        if (t0 < t1) out[spans++] = {{t0, prim, 0, false}, {t1, prim, 0, false}};
    }
    return spans;
}

template <class R, class T = ScalarOf<R>>
int spansOf(const Shape& s, const R& r, uint32_t prim, Span* out) {
    return std::visit(
        Overloaded{[&](const Sphere& x) { return sphereSpansOf(V3<T>(x.c), T(x.r), r, prim, out); },
                   [&](const Block& x) { return blockSpans(x, r, prim, out); },
                   [&](const Cone& x) { return coneSpans(x, r, prim, out); },
                   [&](const Triangle& x) { return triangleSpans(x, r, prim, out); },
                   [&](const Polygon& x) { return polygonSpans(x, r, prim, out); },
                   [&](const Polytope& x) { return polytopeSpans(x, r, prim, out); },
                   [&](const Torus& x) { return torusSpans(x, r, prim, out); }},
        s);
}

}  // namespace

int shapeSpans(const Shape& s, const Ray& r, uint32_t prim, Span* out) {
    return spansOf(s, r, prim, out);
}

int shapeSpans(const Shape& s, const RayF& r, uint32_t prim, Span* out) {
    return spansOf(s, r, prim, out);
}

Vec3 shapeNormal(const Shape& s, const Vec3& p, uint8_t part) {
    return std::visit(
        Overloaded{[&](const Sphere& x) { return (p - x.c) / x.r; },
                   [&](const Block&) {
                       Vec3 n(0.0);
                       n[part / 2] = (part & 1) ? 1.0 : -1.0;
                       return n;
                   },
                   [&](const Cone& x) {
                       if (part == 1) return Vec3(0, 0, -1);
                       if (part == 2) return Vec3(0, 0, 1);
                       double s = (x.r2 - x.r1) / x.h;
                       double rz = x.r1 + s * p.z;
                       Vec3 n(p.x, p.y, -s * rz);
                       if (glm::dot(n, n) == 0.0) return Vec3(0, 0, x.r2 > x.r1 ? -1.0 : 1.0);
                       return glm::normalize(n);
                   },
                   [&](const Triangle& x) {
                       Vec3 g = glm::cross(x.p[1] - x.p[0], x.p[2] - x.p[0]);
                       if (!x.smooth) return glm::normalize(g);
                       // Barycentric weights of p; shading normal oriented like the geometric one.
                       double area = glm::dot(g, g);
                       double w1 = glm::dot(glm::cross(x.p[2] - p, x.p[0] - p), g) / area;
                       double w2 = glm::dot(glm::cross(x.p[0] - p, x.p[1] - p), g) / area;
                       double w0 = 1.0 - w1 - w2;
                       Vec3 n = w0 * x.n[0] + w1 * x.n[1] + w2 * x.n[2];
                       if (glm::dot(n, n) == 0.0) return glm::normalize(g);
                       n = glm::normalize(n);
                       return glm::dot(n, g) < 0.0 ? -n : n;
                   },
                   [&](const Polygon& x) { return x.n; },
                   [&](const Polytope& x) { return Vec3(x.planes[part]); },
                   [&](const Torus& x) {
                       // Away from the tube's centre circle, towards p: the gradient's direction.
                       const double rho = std::hypot(p.x, p.y);
                       // The horn torus's point on the axis: the tangent cone's axis.
                       if (rho == 0.0) return Vec3(0.0, 0.0, p.z >= 0.0 ? 1.0 : -1.0);
                       const Vec3 n = p - x.R * Vec3(p.x / rho, p.y / rho, 0.0);
                       return glm::dot(n, n) > 0.0 ? glm::normalize(n) : Vec3(0.0, 0.0, 1.0);
                   }},
        s);
}

Box3 shapeBounds(const Shape& s) {
    return std::visit(Overloaded{[](const Sphere& x) {
                                     return Box3{x.c - Vec3(x.r), x.c + Vec3(x.r)};
                                 },
                                 [](const Block& x) {
                                     return Box3{x.lo, x.hi};
                                 },
                                 [](const Cone& x) {
                                     double r = std::max(x.r1, x.r2);
                                     return Box3{Vec3(-r, -r, 0.0), Vec3(r, r, x.h)};
                                 },
                                 [](const Triangle& x) {
                                     Box3 b;
                                     for (const Vec3& p : x.p) b.expand(p);
                                     return b;
                                 },
                                 [](const Polygon& x) {
                                     Box3 b;
                                     for (const Vec3& p : x.p) b.expand(p);
                                     return b;
                                 },
                                 [](const Polytope& x) { return x.bounds; },
                                 [](const Torus& x) {
                                     const double b = x.R + x.r;
                                     return Box3{Vec3(-b, -b, -x.r), Vec3(b, b, x.r)};
                                 }},
                      s);
}

bool shapeIsSurface(const Shape& s) {
    if (const Cone* c = std::get_if<Cone>(&s)) return c->open;
    return std::holds_alternative<Triangle>(s) || std::holds_alternative<Polygon>(s);
}

bool convexSolidHolds(const Shape& s, const Vec3& p) {
    return std::visit(
        Overloaded{[&](const Sphere& x) { return glm::dot(p - x.c, p - x.c) < x.r * x.r; },
                   [&](const Block& x) {
                       return glm::all(glm::lessThan(x.lo, p)) && glm::all(glm::lessThan(p, x.hi));
                   },
                   [&](const Cone& x) {
                       if (x.open || !(x.r1 >= 0.0 && x.r2 >= 0.0) || !(0.0 < p.z && p.z < x.h))
                           return false;  // a frustum with both radii >= 0 is convex
                       const double r = x.r1 + (x.r2 - x.r1) * (p.z / x.h);
                       return p.x * p.x + p.y * p.y < r * r;
                   },
                   [&](const Polytope& x) {
                       for (const glm::dvec4& pl : x.planes)
                           if (!(glm::dot(Vec3(pl), p) < pl.w)) return false;
                       return !x.planes.empty();
                   },
                   [](const auto&) { return false; }},
        s);
}

const char* shapeName(const Shape& s) {
    static const char* names[] = {"sphere",  "box",      "cone", "triangle",
                                  "polygon", "polytope", "torus"};
    if (const Cone* c = std::get_if<Cone>(&s)) {
        if (c->open) return "open cone";
        if (c->r1 == c->r2) return "cylinder";
    }
    return names[s.index()];
}

bool makePolygon(std::vector<Vec3> pts, Polygon& out) {
    // Newell's normal: robust for non-convex and slightly non-planar input.
    Vec3 n(0.0);
    size_t k = pts.size();
    if (k < 3) return false;
    Vec3 centroid(0.0);
    for (size_t i = 0; i < k; ++i) {
        const Vec3& a = pts[i];
        const Vec3& b = pts[(i + 1) % k];
        n += Vec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y));
        centroid += a;
    }
    double len = glm::length(n);
    if (!(len > 0.0) || !std::isfinite(len)) return false;
    out.n = n / len;
    out.d = glm::dot(out.n, centroid / double(k));
    Vec3 an = glm::abs(out.n);
    out.drop = (an.x >= an.y && an.x >= an.z) ? 0 : (an.y >= an.z ? 1 : 2);
    out.p = std::move(pts);
    return true;
}

}  // namespace lancer
