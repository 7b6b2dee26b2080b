#include "engine/scene/openscad/region2d.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace lancer::openscad {

namespace {

double cross(const Vec2& a, const Vec2& b) { return a.x * b.y - a.y * b.x; }

bool lexLess(const Vec2& a, const Vec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); }

std::vector<Vec2> cleaned(const std::vector<Vec2>& path) {
    std::vector<Vec2> out;
    for (const Vec2& p : path)
        if (out.empty() || p != out.back()) out.push_back(p);
    while (out.size() > 1 && out.front() == out.back()) out.pop_back();
    return out;
}

/// The path as a counter-clockwise convex polygon without collinear vertices, if it is one that
/// winds once.
bool asConvex(std::vector<Vec2> p, ConvexPiece& out) {
    // Drop collinear vertices (the exact cross product is zero), until none is left.
    for (bool changed = true; changed && p.size() >= 3;) {
        changed = false;
        for (size_t i = 0; i < p.size() && p.size() >= 3; ++i) {
            const Vec2& a = p[(i + p.size() - 1) % p.size()];
            const Vec2& c = p[(i + 1) % p.size()];
            if (cross(p[i] - a, c - p[i]) == 0.0) {
                p.erase(p.begin() + long(i));
                changed = true;
            }
        }
    }
    size_t n = p.size();
    if (n < 3 || n > kMaxPieceSides) return false;
    int sign = 0;
    double turning = 0.0;
    for (size_t i = 0; i < n; ++i) {
        Vec2 d0 = p[i] - p[(i + n - 1) % n], d1 = p[(i + 1) % n] - p[i];
        double c = cross(d0, d1);
        int s = c > 0.0 ? 1 : -1;
        if (sign == 0) sign = s;
        if (s != sign) return false;
        turning += std::atan2(c, glm::dot(d0, d1));
    }
    // A convex polygon turns once; a pentagram turns twice with every turn the same way.
    if (std::abs(std::abs(turning) - 2.0 * std::numbers::pi) > 1.0) return false;
    if (sign < 0) std::reverse(p.begin(), p.end());
    out.vertices = p;
    out.sides.clear();
    for (size_t i = 0; i < n; ++i) out.sides.push_back(leftOf(p[i], p[(i + 1) % n]));
    return true;
}

/// A non-vertical edge with p.x < q.x.
struct Edge {
    Vec2 p, q;
    double yAt(double x) const { return p.y + (q.y - p.y) * ((x - p.x) / (q.x - p.x)); }
};

std::vector<ConvexPiece> trapezoids(const std::vector<std::vector<Vec2>>& paths) {
    std::vector<Edge> edges;
    std::vector<double> xs;
    for (const auto& path : paths)
        for (size_t i = 0; i < path.size(); ++i) {
            Vec2 a = path[i], b = path[(i + 1) % path.size()];
            xs.push_back(a.x);
            if (a.x == b.x) continue;  // vertical edges bound no slab's inside
            if (a.x > b.x) std::swap(a, b);
            edges.push_back({a, b});
        }
    // Crossings of two edges inside both: the slabs must not hold any, so edges keep their order
    // within a slab.
    for (size_t i = 0; i < edges.size(); ++i)
        for (size_t j = i + 1; j < edges.size(); ++j) {
            const Edge &e = edges[i], &f = edges[j];
            if (e.q.x <= f.p.x || f.q.x <= e.p.x) continue;
            Vec2 r = e.q - e.p, s = f.q - f.p;
            double den = cross(r, s);
            if (den == 0.0) continue;
            double t = cross(f.p - e.p, s) / den, u = cross(f.p - e.p, r) / den;
            if (t > 0.0 && t < 1.0 && u > 0.0 && u < 1.0) xs.push_back(e.p.x + t * r.x);
        }
    std::sort(xs.begin(), xs.end());
    xs.erase(std::unique(xs.begin(), xs.end()), xs.end());

    struct Open {
        size_t lo, hi;
        double x0, x1;
    };
    std::vector<Open> done, open;
    for (size_t k = 0; k + 1 < xs.size(); ++k) {
        double x0 = xs[k], x1 = xs[k + 1], xm = 0.5 * (x0 + x1);
        std::vector<std::pair<double, size_t>> at;
        for (size_t i = 0; i < edges.size(); ++i)
            if (edges[i].p.x <= x0 && edges[i].q.x >= x1) at.push_back({edges[i].yAt(xm), i});
        std::sort(at.begin(), at.end());
        std::vector<Open> next;
        for (size_t i = 0; i + 1 < at.size(); i += 2) {
            if (!(at[i].first < at[i + 1].first)) continue;  // coincident edges: nothing between
            size_t lo = at[i].second, hi = at[i + 1].second;
            auto it = std::find_if(open.begin(), open.end(), [&](const Open& o) {
                return o.lo == lo && o.hi == hi && o.x1 == x0;
            });
            if (it != open.end()) {
                Open o = *it;
                o.x1 = x1;
                open.erase(it);
                next.push_back(o);
            } else {
                next.push_back({lo, hi, x0, x1});
            }
        }
        done.insert(done.end(), open.begin(), open.end());
        open = std::move(next);
    }
    done.insert(done.end(), open.begin(), open.end());

    std::vector<ConvexPiece> pieces;
    for (const Open& o : done) {
        const Edge &lo = edges[o.lo], &hi = edges[o.hi];
        ConvexPiece pc;
        // The walls from the original edges, not from the cut corners, so that every piece
        // along an edge has the same plane.
        pc.sides.push_back(leftOf(lo.p, lo.q));
        pc.sides.push_back({1.0, 0.0, o.x1});
        pc.sides.push_back(leftOf(hi.q, hi.p));
        pc.sides.push_back({-1.0, 0.0, -o.x0});
        pc.vertices = {
            {o.x0, lo.yAt(o.x0)}, {o.x1, lo.yAt(o.x1)}, {o.x1, hi.yAt(o.x1)}, {o.x0, hi.yAt(o.x0)}};
        pieces.push_back(std::move(pc));
    }
    return pieces;
}

}  // namespace

HalfPlane leftOf(const Vec2& p, const Vec2& q) {
    bool forward = lexLess(p, q);
    const Vec2& u = forward ? p : q;
    const Vec2& v = forward ? q : p;
    HalfPlane h{v.y - u.y, u.x - v.x, 0.0};
    h.c = h.a * u.x + h.b * u.y;
    if (!forward) h = {-h.a, -h.b, -h.c};
    return h;
}

std::vector<ConvexPiece> convexPieces(const std::vector<std::vector<Vec2>>& pathsIn) {
    std::vector<std::vector<Vec2>> paths;
    for (const auto& p : pathsIn) {
        std::vector<Vec2> c = cleaned(p);
        if (c.size() >= 3) paths.push_back(std::move(c));
    }
    if (paths.empty()) return {};
    ConvexPiece one;
    if (paths.size() == 1 && asConvex(paths[0], one)) return {one};
    return trapezoids(paths);
}

double fragmentsFromR(double r, double fn, double fa, double fs) {
    double f = 3.0;
    if (r < kGridFine || !std::isfinite(fn))
        f = 3.0;
    else if (fn > 0.0)
        f = std::floor(fn >= 3.0 ? fn : 3.0);
    else
        f = std::ceil(std::fmax(std::fmin(360.0 / fa, r * 2.0 * M_PI / fs), 5.0));
    return std::isfinite(f) ? f : 5.0;
}

}  // namespace lancer::openscad
