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

namespace {

/// The sign of the turn a -> b -> c: 1 left, -1 right, 0 on a line.
int turnSign(const Vec2& a, const Vec2& b, const Vec2& c) {
    const double t = cross(b - a, c - a);
    return t > 0.0 ? 1 : t < 0.0 ? -1 : 0;
}

/// Whether the closed segments ab and cd share a point.
bool segmentsMeet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
    const int o1 = turnSign(a, b, c), o2 = turnSign(a, b, d);
    const int o3 = turnSign(c, d, a), o4 = turnSign(c, d, b);
    if (o1 == 0 && o2 == 0) {  // on one line: do their extents overlap?
        const bool alongX = std::abs(b.x - a.x) >= std::abs(b.y - a.y);
        auto key = [&](const Vec2& p) { return alongX ? p.x : p.y; };
        return std::max(std::min(key(a), key(b)), std::min(key(c), key(d))) <=
               std::min(std::max(key(a), key(b)), std::max(key(c), key(d)));
    }
    return o1 * o2 <= 0 && o3 * o4 <= 0;
}

/// Even-odd containment of the point p by the closed path q (p on no edge of q).
bool encloses(const std::vector<Vec2>& q, const Vec2& p) {
    bool in = false;
    for (size_t i = 0, j = q.size() - 1; i < q.size(); j = i++)
        if ((q[i].y > p.y) != (q[j].y > p.y) &&
            p.x < q[j].x + (q[i].x - q[j].x) * ((p.y - q[j].y) / (q[i].y - q[j].y)))
            in = !in;
    return in;
}

double signedArea2(const std::vector<Vec2>& q) {
    double a = 0.0;
    for (size_t i = 0; i < q.size(); ++i) a += cross(q[i], q[(i + 1) % q.size()]);
    return a;
}

}  // namespace

bool regionOutlines(const std::vector<std::vector<Vec2>>& paths, std::vector<Outline>& out) {
    out.clear();
    for (size_t i = 0; i < paths.size(); ++i) {
        std::vector<Vec2> c = cleaned(paths[i]);
        if (c.size() >= 3) out.push_back({std::move(c), -1, int(i)});
    }
    // Every pair of edges that are not neighbours on one path, swept by their x extents.
    struct Seg {
        Vec2 a, b;
        size_t path, index;
        double x0, x1;
    };
    std::vector<Seg> segs;
    for (size_t k = 0; k < out.size(); ++k) {
        const std::vector<Vec2>& q = out[k].points;
        for (size_t i = 0; i < q.size(); ++i) {
            const Vec2 &a = q[i], &b = q[(i + 1) % q.size()];
            segs.push_back({a, b, k, i, std::min(a.x, b.x), std::max(a.x, b.x)});
        }
    }
    std::sort(segs.begin(), segs.end(), [](const Seg& s, const Seg& t) { return s.x0 < t.x0; });
    for (size_t i = 0; i < segs.size(); ++i)
        for (size_t j = i + 1; j < segs.size() && segs[j].x0 <= segs[i].x1; ++j) {
            const Seg &s = segs[i], &t = segs[j];
            if (s.path == t.path) {
                const size_t n = out[s.path].points.size();
                if ((s.index + 1) % n == t.index || (t.index + 1) % n == s.index) {
                    // Neighbours share their corner; they meet elsewhere only folding back.
                    const Vec2& c = (s.index + 1) % n == t.index ? t.a : s.a;
                    const Vec2& u = (s.index + 1) % n == t.index ? s.a : t.a;
                    const Vec2& v = (s.index + 1) % n == t.index ? t.b : s.b;
                    if (turnSign(u, c, v) == 0 && glm::dot(u - c, v - c) > 0.0) return false;
                    continue;
                }
            }
            if (segmentsMeet(s.a, s.b, t.a, t.b)) return false;
        }
    // No edges meet: each path lies wholly inside or outside each other one.
    for (size_t k = 0; k < out.size(); ++k) {
        double best = kInf;
        for (size_t m = 0; m < out.size(); ++m) {
            if (m == k || !encloses(out[m].points, out[k].points[0])) continue;
            const double a = std::abs(signedArea2(out[m].points));
            if (a < best) best = a, out[k].parent = int(m);
        }
    }
    for (Outline& o : out) {
        int depth = 0;
        for (int p = o.parent; p >= 0; p = out[size_t(p)].parent) ++depth;
        if ((signedArea2(o.points) > 0.0) != (depth % 2 == 0))
            std::reverse(o.points.begin(), o.points.end());
    }
    return true;
}

std::vector<std::vector<Vec2>> offsetAdditions(const std::vector<std::vector<Vec2>>& outlines,
                                               double d, bool chamfer) {
    // Clipper squares a mitre whose 1 + cos(turn) is under 2 / limit^2.
    constexpr double kMiterLimit = 1e6, kSquareBelow = 2.0 / (kMiterLimit * kMiterLimit);
    std::vector<std::vector<Vec2>> out;
    for (const std::vector<Vec2>& q : outlines) {
        const size_t n = q.size();
        // Each edge's outward normal (the region is on the left), computed once so that the
        // rectangles and the corners share their points bit for bit.
        std::vector<Vec2> normal(n), dir(n);
        for (size_t i = 0; i < n; ++i) {
            const Vec2 e = q[(i + 1) % n] - q[i];
            const double len = glm::length(e);
            dir[i] = e / len;
            normal[i] = Vec2(dir[i].y, -dir[i].x);
            out.push_back(
                {q[i], q[(i + 1) % n], q[(i + 1) % n] + d * normal[i], q[i] + d * normal[i]});
        }
        for (size_t i = 0; i < n; ++i) {
            const size_t in = (i + n - 1) % n;  // the edge into corner i
            const Vec2 &v = q[i], &n1 = normal[in], &n2 = normal[i];
            const double s = cross(n1, n2), c = glm::dot(n1, n2);
            // Convex: a left turn (or folding straight back); a reflex corner's rectangles
            // overlap and need nothing more.
            if (!(s > 0.0 || (s == 0.0 && c < 0.0))) continue;
            const Vec2 a = v + d * n1, b = v + d * n2;
            if (!chamfer && 1.0 + c >= kSquareBelow) {
                out.push_back({v, a, v + d * (n1 + n2) / (1.0 + c), b});
            } else {
                // Square to the bisector at distance d from the corner: along each moved edge
                // by d tan(turn / 4) past its end.
                const double t = d * std::tan(std::atan2(s, c) / 4.0);
                out.push_back({v, a, a + t * dir[in], b - t * dir[i], b});
            }
        }
    }
    return out;
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
