#include "engine/model/shapes.h"

#include <cmath>

namespace lancer {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
    using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // clang 14 lacks C++20 aggregate deduction

int blockSpans(const Block& b, const Ray& r, uint32_t prim, Span* out) {
    double t0 = -kInf, t1 = kInf;
    uint8_t p0 = 0, p1 = 0;
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0.0) {
            if (r.o[a] < b.lo[a] || r.o[a] > b.hi[a]) return 0;
            continue;
        }
        double inv = 1.0 / r.d[a];
        double ta = (b.lo[a] - r.o[a]) * inv, tb = (b.hi[a] - r.o[a]) * inv;
        uint8_t pa = uint8_t(2 * a), pb = uint8_t(2 * a + 1);
        if (ta > tb) {
            std::swap(ta, tb);
            std::swap(pa, pb);
        }
        if (ta > t0) t0 = ta, p0 = pa;
        if (tb < t1) t1 = tb, p1 = pb;
    }
    if (!(t0 < t1)) return 0;
    out[0] = {{t0, prim, p0, false}, {t1, prim, p1, false}};
    return 1;
}

// Parametric interval where a*t^2 + b*t + c <= 0, as up to two pieces.
int quadricInside(double a, double b, double c, double* lo, double* hi) {
    if (a == 0.0) {
        if (b == 0.0) {
            if (c <= 0.0) {
                lo[0] = -kInf;
                hi[0] = kInf;
                return 1;
            }
            return 0;
        }
        double t = -c / b;
        if (b > 0.0) {
            lo[0] = -kInf;
            hi[0] = t;
        } else {
            lo[0] = t;
            hi[0] = kInf;
        }
        return 1;
    }
    double disc = b * b - 4.0 * a * c;
    if (disc <= 0.0) {
        if (a < 0.0) {
            lo[0] = -kInf;
            hi[0] = kInf;
            return 1;
        }
        return 0;
    }
    double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
    double t0 = q / a, t1 = (q != 0.0) ? c / q : -t0;
    if (t0 > t1) std::swap(t0, t1);
    if (a > 0.0) {
        lo[0] = t0;
        hi[0] = t1;
        return 1;
    }
    lo[0] = -kInf;
    hi[0] = t0;
    lo[1] = t1;
    hi[1] = kInf;
    return 2;
}

struct ConeQuadric {
    double a, b, c;
};
ConeQuadric coneQuadric(const Cone& k, const Ray& r) {
    double s = (k.r2 - k.r1) / k.h;  // radius slope
    double rz = k.r1 + s * r.o.z;    // radius at the origin's height
    double a = r.d.x * r.d.x + r.d.y * r.d.y - s * s * r.d.z * r.d.z;
    double b = 2.0 * (r.o.x * r.d.x + r.o.y * r.d.y - s * r.d.z * rz);
    double c = r.o.x * r.o.x + r.o.y * r.o.y - rz * rz;
    return {a, b, c};
}

int coneSpans(const Cone& k, const Ray& r, uint32_t prim, Span* out) {
    ConeQuadric q = coneQuadric(k, r);
    // Slab 0 <= z <= h.
    double z0 = -kInf, z1 = kInf;
    uint8_t c0 = 0, c1 = 0;
    if (r.d.z == 0.0) {
        if (r.o.z < 0.0 || r.o.z > k.h) return 0;
    } else {
        z0 = -r.o.z / r.d.z;
        z1 = (k.h - r.o.z) / r.d.z;
        c0 = 1, c1 = 2;
        if (z0 > z1) std::swap(z0, z1), std::swap(c0, c1);
    }
    if (k.open) {
        // The side surface only: roots of the quadric inside the slab.
        double disc = q.b * q.b - 4.0 * q.a * q.c;
        if (q.a == 0.0 || !(disc > 0.0)) return 0;
        double qq = -0.5 * (q.b + std::copysign(std::sqrt(disc), q.b));
        double t[2] = {qq / q.a, qq != 0.0 ? q.c / qq : -qq / q.a};
        if (t[0] > t[1]) std::swap(t[0], t[1]);
        int n = 0;
        for (double ti : t)
            if (ti >= z0 && ti <= z1) out[n++] = {{ti, prim, 0, false}, {ti, prim, 0, false}};
        return n;
    }
    double lo[2], hi[2];
    int pieces = quadricInside(q.a, q.b, q.c, lo, hi);
    // Within the slab the radius is non-negative, so only one nappe lies there and the solid is
    // convex: the hull of the pieces clipped to the slab is its one span.
    double t0 = kInf, t1 = -kInf;
    uint8_t p0 = 0, p1 = 0;
    for (int i = 0; i < pieces; ++i) {
        double a = std::max(lo[i], z0), b = std::min(hi[i], z1);
        if (!(a < b)) continue;
        if (a < t0) t0 = a, p0 = (lo[i] >= z0) ? 0 : c0;
        if (b > t1) t1 = b, p1 = (hi[i] <= z1) ? 0 : c1;
    }
    if (!(t0 < t1) || !std::isfinite(t0) || !std::isfinite(t1)) return 0;
    out[0] = {{t0, prim, p0, false}, {t1, prim, p1, false}};
    return 1;
}

int triangleSpans(const Triangle& tr, const Ray& r, uint32_t prim, Span* out) {
    // Möller-Trumbore, both sides.
    Vec3 e1 = tr.p[1] - tr.p[0], e2 = tr.p[2] - tr.p[0];
    Vec3 pv = glm::cross(r.d, e2);
    double det = glm::dot(e1, pv);
    if (det == 0.0 || !std::isfinite(det)) return 0;
    double inv = 1.0 / det;
    Vec3 tv = r.o - tr.p[0];
    double u = glm::dot(tv, pv) * inv;
    if (u < 0.0 || u > 1.0) return 0;
    Vec3 qv = glm::cross(tv, e1);
    double v = glm::dot(r.d, qv) * inv;
    if (v < 0.0 || u + v > 1.0) return 0;
    double t = glm::dot(e2, qv) * inv;
    out[0] = {{t, prim, 0, false}, {t, prim, 0, false}};
    return 1;
}

int polygonSpans(const Polygon& pg, const Ray& r, uint32_t prim, Span* out) {
    double dn = glm::dot(pg.n, r.d);
    if (dn == 0.0) return 0;
    double t = (pg.d - glm::dot(pg.n, r.o)) / dn;
    Vec3 p = r.at(t);
    int ax = (pg.drop + 1) % 3, ay = (pg.drop + 2) % 3;
    double px = p[ax], py = p[ay];
    bool inside = false;
    size_t n = pg.p.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        double xi = pg.p[i][ax], yi = pg.p[i][ay], xj = pg.p[j][ax], yj = pg.p[j][ay];
        if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi) inside = !inside;
    }
    if (!inside) return 0;
    out[0] = {{t, prim, 0, false}, {t, prim, 0, false}};
    return 1;
}

int polytopeSpans(const Polytope& k, const Ray& r, uint32_t prim, Span* out) {
    // Kay and Kajiya's slab clipping, one plane at a time: the ray enters where it crosses a
    // plane whose normal faces it and leaves where it crosses one facing away.
    double t0 = -kInf, t1 = kInf;
    uint8_t p0 = 0, p1 = 0;
    for (size_t i = 0; i < k.planes.size(); ++i) {
        const glm::dvec4& pl = k.planes[i];
        const Vec3 n(pl);
        double dn = glm::dot(n, r.d);
        double dist = pl.w - glm::dot(n, r.o);
        if (dn == 0.0) {
            if (dist < 0.0) return 0;
            continue;
        }
        double t = dist / dn;
        if (dn < 0.0) {
            if (t > t0) t0 = t, p0 = uint8_t(i);
        } else if (t < t1) {
            t1 = t, p1 = uint8_t(i);
        }
        if (!(t0 < t1)) return 0;
    }
    if (!std::isfinite(t0) || !std::isfinite(t1)) return 0;
    out[0] = {{t0, prim, p0, false}, {t1, prim, p1, false}};
    return 1;
}

}  // namespace

int shapeSpans(const Shape& s, const Ray& r, uint32_t prim, Span* out) {
    return std::visit(
        Overloaded{[&](const Sphere& x) { return sphereSpans(x.c, x.r, r, prim, out); },
                   [&](const Block& x) { return blockSpans(x, r, prim, out); },
                   [&](const Cone& x) { return coneSpans(x, r, prim, out); },
                   [&](const Triangle& x) { return triangleSpans(x, r, prim, out); },
                   [&](const Polygon& x) { return polygonSpans(x, r, prim, out); },
                   [&](const Polytope& x) { return polytopeSpans(x, r, prim, out); }},
        s);
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
                   [&](const Polytope& x) { return Vec3(x.planes[part]); }},
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
                                 [](const Polytope& x) { return x.bounds; }},
                      s);
}

bool shapeIsSurface(const Shape& s) {
    if (const Cone* c = std::get_if<Cone>(&s)) return c->open;
    return std::holds_alternative<Triangle>(s) || std::holds_alternative<Polygon>(s);
}

const char* shapeName(const Shape& s) {
    static const char* names[] = {"sphere", "box", "cone", "triangle", "polygon", "polytope"};
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
