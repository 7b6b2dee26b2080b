#include "engine/model/mesh_solid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <numeric>
#include <tuple>
#include <unordered_map>

#include "engine/util/hash.h"

namespace lancer {

namespace {

using Tri = std::array<uint32_t, 3>;

Vec3 triNormal(const TriangleMesh& m, const Tri& t) {
    const Vec3 &a = m.points[t[0]], &b = m.points[t[1]], &c = m.points[t[2]];
    return glm::cross(b - a, c - a);
}

double orient(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
    return glm::dot(glm::cross(b - a, c - a), d - a);
}

/// The segment pq crosses the plane of triangle abc strictly (not at an end) at a point of the
/// closed triangle, in the signs of double orientation tests.
bool segmentCrosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
    const double sp = orient(a, b, c, p), sq = orient(a, b, c, q);
    if (!((sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0))) return false;
    // Through the closed triangle: a segment that pierces the surface on an edge between two
    // triangles (a box's face diagonal) crosses it too.
    const double s1 = orient(p, q, a, b), s2 = orient(p, q, b, c), s3 = orient(p, q, c, a);
    return (s1 >= 0.0 && s2 >= 0.0 && s3 >= 0.0) || (s1 <= 0.0 && s2 <= 0.0 && s3 <= 0.0);
}

/// A ray's crossings with the mesh's triangles, or -1 when it meets an edge or a corner within
/// a relative 1e-9 (then the parity is not to be trusted).
int crossings(const TriangleMesh& m, const Vec3& o, const Vec3& d) {
    int n = 0;
    for (const Tri& t : m.triangles) {
        const Vec3 &a = m.points[t[0]], &b = m.points[t[1]], &c = m.points[t[2]];
        const Vec3 e1 = b - a, e2 = c - a, pv = glm::cross(d, e2);
        const double det = glm::dot(e1, pv);
        if (std::abs(det) < 1e-300) continue;
        const Vec3 tv = o - a;
        const double u = glm::dot(tv, pv) / det;
        const Vec3 qv = glm::cross(tv, e1);
        const double v = glm::dot(d, qv) / det, tt = glm::dot(e2, qv) / det;
        constexpr double k = 1e-9;
        if (u < -k || v < -k || u + v > 1.0 + k || tt < 0.0) continue;
        if (u < k || v < k || u + v > 1.0 - k || tt < k * glm::length(e1)) return -1;
        ++n;
    }
    return n;
}

/// Parity from `o` along a few fixed directions, the first that meets no edge.
bool parityInside(const TriangleMesh& m, const Vec3& o, const Vec3& hint) {
    static const Vec3 dirs[] = {{0.5773, 0.5774, 0.5773},   {-0.3181, 0.8122, 0.4891},
                                {0.7071, -0.1213, -0.6965}, {-0.2687, -0.4472, 0.8534},
                                {0.9131, 0.3421, -0.2215},  {-0.6512, -0.7108, -0.2661}};
    for (const Vec3& d0 : dirs) {
        Vec3 d = d0;
        if (glm::dot(hint, hint) > 0.0) d = glm::normalize(hint) + 0.25 * d0;
        const int n = crossings(m, o, d);
        if (n >= 0) return n % 2 == 1;
    }
    return crossings(m, o, dirs[0]) % 2 != 0;  // every ray grazed: the first one's count
}

// ---- checks: closed, orientable, not self-intersecting ----

/// Each triangle's neighbour across edge k (from corner k to k + 1); throws on an open edge.
std::vector<std::array<uint32_t, 3>> neighbours(const TriangleMesh& m) {
    std::unordered_map<uint64_t, std::vector<uint32_t>> edges;  // key min << 32 | max: slots
    edges.reserve(m.triangles.size() * 2);
    auto key = [](uint32_t a, uint32_t b) {
        return uint64_t(std::min(a, b)) << 32 | std::max(a, b);
    };
    for (uint32_t t = 0; t < m.triangles.size(); ++t)
        for (uint32_t k = 0; k < 3; ++k)
            edges[key(m.triangles[t][k], m.triangles[t][(k + 1) % 3])].push_back(3 * t + k);
    std::vector<std::array<uint32_t, 3>> nb(m.triangles.size());
    // The open edge reported is the lowest one, so the message does not depend on hashing.
    std::pair<uint64_t, size_t> worst{~uint64_t(0), 2};
    for (const auto& [k, slots] : edges) {
        if (slots.size() != 2) {
            worst = std::min(worst, {k, slots.size()});
            continue;
        }
        nb[slots[0] / 3][slots[0] % 3] = slots[1] / 3;
        nb[slots[1] / 3][slots[1] % 3] = slots[0] / 3;
    }
    if (worst.second != 2)
        throw MeshError("not a closed mesh: the edge from point " +
                        std::to_string(worst.first >> 32) + " to point " +
                        std::to_string(worst.first & 0xffffffffu) + " belongs to " +
                        std::to_string(worst.second) + " triangle" +
                        (worst.second == 1 ? "" : "s") + " (two in a closed mesh)");
    return nb;
}

/// Whether triangle t runs from a to b (rather than b to a).
bool runs(const Tri& t, uint32_t a, uint32_t b) {
    for (int k = 0; k < 3; ++k)
        if (t[k] == a && t[(k + 1) % 3] == b) return true;
    return false;
}

/// Reverse a triangle: corners 0 and 1 swap, so its edges 1 and 2 (from corner k) swap too.
void flip(Tri& t, std::array<uint32_t, 3>& nb) {
    std::swap(t[0], t[1]);
    std::swap(nb[1], nb[2]);
}

/// Turn triangles so that neighbours cross their shared edge in opposite directions, then turn
/// each connected shell so that its triangles face away from the inside that parity gives (a
/// shell inside another faces its cavity). Throws when a shell cannot be oriented.
void orientShells(TriangleMesh& m, std::vector<std::array<uint32_t, 3>>& nb) {
    const size_t n = m.triangles.size();
    std::vector<int> shell(n, -1);
    std::vector<uint32_t> stack;
    int shells = 0;
    for (uint32_t s = 0; s < n; ++s) {
        if (shell[s] >= 0) continue;
        std::vector<uint32_t> members;
        shell[s] = shells;
        stack.push_back(s);
        while (!stack.empty()) {
            const uint32_t t = stack.back();
            stack.pop_back();
            members.push_back(t);
            for (int k = 0; k < 3; ++k) {
                const uint32_t a = m.triangles[t][k], b = m.triangles[t][(k + 1) % 3], u = nb[t][k];
                if (shell[u] == shells) {
                    if (runs(m.triangles[u], a, b))
                        throw MeshError("not orientable: triangles " + std::to_string(t) + " and " +
                                        std::to_string(u) +
                                        " cannot face the same side of their shell");
                    continue;
                }
                if (runs(m.triangles[u], a, b)) flip(m.triangles[u], nb[u]);
                shell[u] = shells;
                stack.push_back(u);
            }
        }
        // Parity from the largest triangle's centre, along its normal: outside means it faces out.
        uint32_t big = members.front();
        double area = -1.0;
        for (uint32_t t : members)
            if (double a = glm::length(triNormal(m, m.triangles[t])); a > area) area = a, big = t;
        const Tri& tb = m.triangles[big];
        const Vec3 c = (m.points[tb[0]] + m.points[tb[1]] + m.points[tb[2]]) / 3.0;
        TriangleMesh others;
        others.points = m.points;
        others.triangles.reserve(n - 1);
        for (uint32_t t = 0; t < n; ++t)
            if (t != big) others.triangles.push_back(m.triangles[t]);
        if (parityInside(others, c, triNormal(m, tb)))
            for (uint32_t t : members) flip(m.triangles[t], nb[t]);
        ++shells;
    }
}

/// Two triangles that share no point and cross, or two on an edge folded onto each other.
void checkSelfIntersection(const TriangleMesh& m, const std::vector<std::array<uint32_t, 3>>& nb,
                           const MeshLimits& limits, MeshSolid& out) {
    const size_t n = m.triangles.size();
    for (uint32_t t = 0; t < n; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t u = nb[t][k];
            if (u <= t) continue;
            const Vec3 a = glm::normalize(triNormal(m, m.triangles[t])),
                       b = glm::normalize(triNormal(m, m.triangles[u]));
            if (glm::dot(a, b) < -1.0 + 1e-12)
                throw MeshError("self-intersecting: triangles " + std::to_string(t) + " and " +
                                std::to_string(u) + " fold onto each other at their shared edge");
        }
    // Sweep along x: pairs whose boxes overlap, tested unless they share a point.
    std::vector<Box3> box(n);
    std::vector<uint32_t> order(n);
    for (uint32_t t = 0; t < n; ++t) {
        for (uint32_t i : m.triangles[t]) box[t].expand(m.points[i]);
        order[t] = t;
    }
    std::sort(order.begin(), order.end(),
              [&](uint32_t a, uint32_t b) { return box[a].lo.x < box[b].lo.x; });
    for (size_t i = 0; i < n; ++i) {
        const uint32_t t = order[i];
        const Tri& A = m.triangles[t];
        for (size_t j = i + 1; j < n && box[order[j]].lo.x <= box[t].hi.x; ++j) {
            const uint32_t u = order[j];
            if (!box[t].overlaps(box[u])) continue;
            const Tri& B = m.triangles[u];
            bool shared = false;
            for (uint32_t x : A)
                for (uint32_t y : B) shared = shared || x == y;
            if (shared) continue;
            if (++out.pairTests > limits.maxPairTests) {
                out.pairTestsCapped = true;
                return;
            }
            const Vec3 &a0 = m.points[A[0]], &a1 = m.points[A[1]], &a2 = m.points[A[2]];
            const Vec3 &b0 = m.points[B[0]], &b1 = m.points[B[1]], &b2 = m.points[B[2]];
            if (segmentCrosses(a0, a1, b0, b1, b2) || segmentCrosses(a1, a2, b0, b1, b2) ||
                segmentCrosses(a2, a0, b0, b1, b2) || segmentCrosses(b0, b1, a0, a1, a2) ||
                segmentCrosses(b1, b2, a0, a1, a2) || segmentCrosses(b2, b0, a0, a1, a2))
                throw MeshError("self-intersecting: triangles " + std::to_string(std::min(t, u)) +
                                " and " + std::to_string(std::max(t, u)) + " cross");
        }
    }
}

// ---- the solid BSP ----

/// A convex polygon with the plane of the triangle it came from (facing out of the solid).
struct Fragment {
    std::vector<Vec3> v;
    glm::dvec4 plane;
};

/// A face of a BSP cell: a convex polygon on one of the split planes, which faces out of it.
using CellFace = Fragment;
using Cell = std::vector<CellFace>;

/// -1 behind (dot(n, p) < w - eps), 0 on, 1 in front.
int side(const glm::dvec4& pl, const Vec3& p, double eps) {
    const double d = glm::dot(Vec3(pl), p) - pl.w;
    return d > eps ? 1 : d < -eps ? -1 : 0;
}

Vec3 crossing(const glm::dvec4& pl, const Vec3& a0, const Vec3& b0) {
    // From the lesser end, so that the two faces on an edge, which walk it in opposite
    // directions, compute the same point to the bit.
    const bool swap = std::tie(b0.x, b0.y, b0.z) < std::tie(a0.x, a0.y, a0.z);
    const Vec3 &a = swap ? b0 : a0, &b = swap ? a0 : b0;
    const double da = glm::dot(Vec3(pl), a) - pl.w, db = glm::dot(Vec3(pl), b) - pl.w;
    return a + (da / (da - db)) * (b - a);
}

/// Sutherland-Hodgman both ways: the polygon's parts behind and in front of the plane (points
/// within eps of it go to both); `cut` collects the points on the plane.
void splitPolygon(const std::vector<Vec3>& in, const glm::dvec4& pl, double eps,
                  std::vector<Vec3>& back, std::vector<Vec3>& front, std::vector<Vec3>* cut) {
    back.clear();
    front.clear();
    const size_t n = in.size();
    for (size_t i = 0; i < n; ++i) {
        const Vec3 &a = in[i], &b = in[(i + 1) % n];
        const int sa = side(pl, a, eps), sb = side(pl, b, eps);
        if (sa <= 0) back.push_back(a);
        if (sa >= 0) front.push_back(a);
        if (sa == 0 && cut) cut->push_back(a);
        if (sa * sb < 0) {
            const Vec3 x = crossing(pl, a, b);
            back.push_back(x);
            front.push_back(x);
            if (cut) cut->push_back(x);
        }
    }
}

/// The convex polygon through `pts` (points on the plane `pl`), counter-clockwise about its
/// normal; fewer than three points when they span no area.
std::vector<Vec3> capPolygon(std::vector<Vec3> pts, const glm::dvec4& pl, double eps) {
    // Points within eps of one another are one (an edge's crossing, or a vertex on the plane,
    // reached from each of its faces): the monotone chain needs distinct points.
    std::vector<Vec3> distinct;
    for (const Vec3& p : pts) {
        bool seen = false;
        for (const Vec3& q : distinct) seen = seen || glm::length(p - q) <= 4.0 * eps;
        if (!seen) distinct.push_back(p);
    }
    pts = std::move(distinct);
    if (pts.size() < 3) return {};
    const Vec3 n(pl);
    const Vec3 u = glm::normalize(std::abs(n.x) < 0.6 ? glm::cross(n, Vec3(1, 0, 0))
                                                      : glm::cross(n, Vec3(0, 1, 0)));
    const Vec3 w = glm::cross(n, u);
    // Andrew's monotone chain in (u, w): drops repeated and collinear points.
    std::sort(pts.begin(), pts.end(), [&](const Vec3& a, const Vec3& b) {
        const double ax = glm::dot(a, u), bx = glm::dot(b, u);
        return ax < bx || (ax == bx && glm::dot(a, w) < glm::dot(b, w));
    });
    auto cross2 = [&](const Vec3& o, const Vec3& a, const Vec3& b) {
        return glm::dot(glm::cross(a - o, b - o), n);
    };
    const double tiny = eps * eps;
    std::vector<Vec3> h(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {
        while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= tiny) --k;
        h[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross2(h[k - 2], h[k - 1], pts[i]) <= tiny) --k;
        h[k++] = pts[i];
    }
    h.resize(k > 0 ? k - 1 : 0);
    return h.size() >= 3 ? h : std::vector<Vec3>{};
}

/// The cell cut by `pl`: the part behind it (capped by `pl`) and in front (capped by -pl). A side
/// that holds no vertex of the cell beyond eps is empty.
void splitCell(const Cell& c, const glm::dvec4& pl, double eps, Cell& back, Cell& front) {
    back.clear();
    front.clear();
    bool anyBack = false, anyFront = false;
    for (const CellFace& f : c)
        for (const Vec3& p : f.v) {
            const int s = side(pl, p, eps);
            anyBack = anyBack || s < 0;
            anyFront = anyFront || s > 0;
        }
    if (!anyFront) {
        back = c;
        return;
    }
    if (!anyBack) {
        front = c;
        return;
    }
    std::vector<Vec3> cut, b, fr;
    for (const CellFace& f : c) {
        splitPolygon(f.v, pl, eps, b, fr, &cut);
        if (b.size() >= 3) back.push_back({b, f.plane});
        if (fr.size() >= 3) front.push_back({fr, f.plane});
    }
    std::vector<Vec3> cap = capPolygon(cut, pl, eps);
    if (cap.size() >= 3) {
        back.push_back({cap, pl});
        std::reverse(cap.begin(), cap.end());
        front.push_back({std::move(cap), -pl});  // negated exactly: the pieces meet bit for bit
    }
}

Vec3 cellCentre(const Cell& c) {
    Vec3 s(0.0);
    size_t n = 0;
    for (const CellFace& f : c)
        for (const Vec3& p : f.v) s += p, ++n;
    return n ? s / double(n) : s;
}

class SolidBsp {
  public:
    SolidBsp(const TriangleMesh& m, const MeshLimits& limits, MeshSolid& out)
        : mesh_(m), limits_(limits), out_(out) {}

    void build() {
        Box3 b;
        for (const Vec3& p : mesh_.points) b.expand(p);
        const Vec3 e = b.extent();
        const double size = std::max({e.x, e.y, e.z, 1e-300});
        double mag = 0.0;
        for (int a = 0; a < 3; ++a)
            mag = std::max({mag, std::abs(coord(b.lo, a)), std::abs(coord(b.hi, a))});
        // On-plane tolerance: a hair of the mesh's size, above the rounding of its coordinates.
        eps_ = std::max(1e-9 * size, 1e-14 * mag);
        Work root;
        for (const Tri& t : mesh_.triangles) {
            const Vec3 n = triNormal(mesh_, t);
            const double len = glm::length(n);
            if (!(len > 0.0)) continue;
            const Vec3 u = n / len;
            root.frags.push_back({{mesh_.points[t[0]], mesh_.points[t[1]], mesh_.points[t[2]]},
                                  glm::dvec4(u, glm::dot(u, mesh_.points[t[0]]))});
        }
        out_.triangles = root.frags.size();
        root.cell = boxCell(b.lo - Vec3(0.01 * size), b.hi + Vec3(0.01 * size));
        for (const CellFace& f : root.cell) root.path.push_back(f.plane);
        std::vector<Work> stack;
        stack.push_back(std::move(root));
        while (!stack.empty()) {
            Work w = std::move(stack.back());
            stack.pop_back();
            step(w, stack);
        }
    }

  private:
    struct Work {
        std::vector<Fragment> frags;
        Cell cell;
        std::vector<glm::dvec4> path;  ///< the half-spaces whose intersection is the cell
    };

    static Cell boxCell(const Vec3& lo, const Vec3& hi) {
        Cell c;
        for (int a = 0; a < 3; ++a)
            for (int s = 0; s < 2; ++s) {
                Vec3 n(0.0);
                n[a] = s ? 1.0 : -1.0;
                const double w = s ? coord(hi, a) : -coord(lo, a);
                const int u = (a + 1) % 3, v = (a + 2) % 3;
                std::vector<Vec3> q;
                for (int k = 0; k < 4; ++k) {
                    Vec3 p = s ? hi : lo;
                    p[u] = (k == 1 || k == 2) ? coord(hi, u) : coord(lo, u);
                    p[v] = (k >= 2) ? coord(hi, v) : coord(lo, v);
                    q.push_back(p);
                }
                c.push_back({q, glm::dvec4(n, w)});
            }
        return c;
    }

    /// The split of one node: an empty side becomes a leaf, the others go on the stack.
    void step(Work& w, std::vector<Work>& stack) {
        out_.fragments += w.frags.size();
        if (out_.fragments > limits_.maxFragments)
            throw MeshError("too complex to cut into convex pieces (over " +
                            std::to_string(limits_.maxFragments) + " polygon fragments)");
        ++out_.bspNodes;
        bool facePlane = true;
        const glm::dvec4 pl = chooseSplit(w.frags, facePlane);
        Work back, front;
        std::vector<Vec3> b, f;
        for (Fragment& g : w.frags) {
            int lo = 1, hi = -1;
            for (const Vec3& p : g.v) {
                const int s = side(pl, p, eps_);
                lo = std::min(lo, s), hi = std::max(hi, s);
            }
            if (lo == 0 && hi == 0) {
                // On the plane: a face splitter's own side bounds the children; on an axis plane
                // the fragment bounds the child behind its face, where it is the solid's surface.
                if (!facePlane)
                    (glm::dot(Vec3(g.plane), Vec3(pl)) > 0.0 ? back : front)
                        .frags.push_back(std::move(g));
            } else if (hi <= 0) {
                back.frags.push_back(std::move(g));
            } else if (lo >= 0) {
                front.frags.push_back(std::move(g));
            } else {
                splitPolygon(g.v, pl, eps_, b, f, nullptr);
                if (b.size() >= 3) back.frags.push_back({b, g.plane});
                if (f.size() >= 3) front.frags.push_back({f, g.plane});
            }
        }
        w.frags = {};
        splitCell(w.cell, pl, eps_, back.cell, front.cell);
        w.cell = {};
        back.path = w.path;
        back.path.push_back(pl);
        front.path = std::move(w.path);
        front.path.push_back(-pl);
        leafOrPush(std::move(back), facePlane ? 1 : 0, stack);
        leafOrPush(std::move(front), facePlane ? -1 : 0, stack);
    }

    /// `known`: 1 inside, -1 outside, 0 by parity from the cell's centre.
    void leafOrPush(Work&& w, int known, std::vector<Work>& stack) {
        if (w.cell.size() < 4) return;  // no volume
        if (!w.frags.empty()) {
            stack.push_back(std::move(w));
            return;
        }
        if (known == 0) known = parityInside(mesh_, cellCentre(w.cell), Vec3(0.0)) ? 1 : -1;
        if (known < 0) return;
        // The cell is the intersection of its path's half-spaces: every one that a vertex of
        // the cell lies on (within eps) bounds it, the others are redundant. The faces' own
        // planes would do as well in exact arithmetic, but a face thinner than eps is dropped
        // by the clipping, and the piece without its plane would reach beyond the cell.
        Polytope p;
        for (const CellFace& f : w.cell)
            for (const Vec3& v : f.v) p.bounds.expand(v);
        for (const glm::dvec4& pl : w.path) {
            double most = -kInf;
            for (const CellFace& f : w.cell)
                for (const Vec3& v : f.v) most = std::max(most, glm::dot(Vec3(pl), v) - pl.w);
            if (most >= -4.0 * eps_ &&
                std::find(p.planes.begin(), p.planes.end(), pl) == p.planes.end())
                p.planes.push_back(pl);
        }
        if (p.planes.size() > 255)
            throw MeshError("a convex piece has " + std::to_string(p.planes.size()) +
                            " faces, over the 255 a polytope holds");
        const Vec3 pad(eps_);
        p.bounds.lo -= pad;
        p.bounds.hi += pad;
        out_.pieces.push_back(std::move(p));
        if (out_.pieces.size() > limits_.maxPieces)
            throw MeshError("cuts into more than " + std::to_string(limits_.maxPieces) +
                            " convex pieces");
    }

    /// A face plane that splits the fragments evenly with few cuts; when none divides a large
    /// set (a convex one), a plane across the fragments' longest axis at their median, so that
    /// no chain of splits grows longer than kChain and no piece gathers hundreds of faces.
    glm::dvec4 chooseSplit(const std::vector<Fragment>& frags, bool& facePlane) const {
        constexpr size_t kCandidates = 12, kSample = 160, kChain = 24;
        const size_t n = frags.size();
        const size_t step = std::max<size_t>(1, n / kSample);
        glm::dvec4 best = frags.front().plane;
        double bestScore = kInf;
        bool divides = false;
        for (size_t c = 0; c < std::min(n, kCandidates); ++c) {
            const glm::dvec4& pl = frags[c * n / std::min(n, kCandidates)].plane;
            size_t fr = 0, bk = 0, cut = 0;
            for (size_t i = 0; i < n; i += step) {
                int lo = 1, hi = -1;
                for (const Vec3& p : frags[i].v) {
                    const int s = side(pl, p, eps_);
                    lo = std::min(lo, s), hi = std::max(hi, s);
                }
                if (lo < 0 && hi > 0)
                    ++cut;
                else if (hi > 0)
                    ++fr;
                else if (lo < 0)
                    ++bk;
            }
            const double score = 4.0 * double(cut) + std::abs(double(fr) - double(bk));
            if (score < bestScore) {
                bestScore = score;
                best = pl;
                divides = fr + cut > 0 && bk + cut > 0;
            }
        }
        facePlane = true;
        if (divides || n <= kChain) return best;
        // Median plane: between two distinct fragment centres, more than eps apart.
        Box3 extent;
        for (const Fragment& g : frags)
            for (const Vec3& p : g.v) extent.expand(p);
        int axes[3] = {0, 1, 2};
        const Vec3 e = extent.extent();
        std::sort(axes, axes + 3, [&](int a, int b) { return coord(e, a) > coord(e, b); });
        std::vector<double> c(n);
        for (int a : axes) {
            for (size_t i = 0; i < n; ++i) {
                double s = 0.0;
                for (const Vec3& p : frags[i].v) s += coord(p, a);
                c[i] = s / double(frags[i].v.size());
            }
            std::sort(c.begin(), c.end());
            for (size_t d = 0; d < n / 2; ++d)
                for (size_t m : {n / 2 - d, n / 2 + d})
                    if (m >= 1 && m < n && c[m] - c[m - 1] > 4.0 * eps_) {
                        glm::dvec4 pl(0.0);
                        pl[a] = 1.0;
                        pl.w = 0.5 * (c[m] + c[m - 1]);
                        facePlane = false;
                        return pl;
                    }
        }
        return best;
    }

    const TriangleMesh& mesh_;
    const MeshLimits& limits_;
    MeshSolid& out_;
    double eps_ = 0.0;
};

}  // namespace

void TriangleMesh::weld() {
    std::unordered_map<uint64_t, std::vector<uint32_t>> seen;
    std::vector<Vec3> kept;
    std::vector<uint32_t> remap(points.size());
    for (size_t i = 0; i < points.size(); ++i) {
        points[i] += Vec3(0.0);  // -0 becomes +0: equal points hash alike
        const uint64_t h = hashBytes(&points[i], sizeof(Vec3));
        uint32_t id = uint32_t(kept.size());
        for (uint32_t k : seen[h])
            if (kept[k] == points[i]) id = k;
        if (id == kept.size()) {
            seen[h].push_back(id);
            kept.push_back(points[i]);
        }
        remap[i] = id;
    }
    points = std::move(kept);
    size_t k = 0;
    for (Tri t : triangles) {
        for (uint32_t& i : t) i = remap[i];
        if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) triangles[k++] = t;
    }
    triangles.resize(k);
}

bool TriangleMesh::addPolygon(const std::vector<uint32_t>& loop) {
    if (loop.size() < 3) return false;
    if (loop.size() == 3) {
        triangles.push_back({loop[0], loop[1], loop[2]});
        return true;
    }
    Vec3 n(0.0);
    for (size_t i = 0; i < loop.size(); ++i) {
        const Vec3 &a = points[loop[i]], &b = points[loop[(i + 1) % loop.size()]];
        n += glm::cross(a, b);
    }
    if (!(glm::length(n) > 0.0)) return false;
    // Ear clipping in the plane of the Newell normal: a corner is an ear when it turns the way
    // the polygon does and no other corner lies in its triangle.
    std::vector<uint32_t> v = loop;
    auto turn = [&](uint32_t a, uint32_t b, uint32_t c) {
        return glm::dot(glm::cross(points[b] - points[a], points[c] - points[b]), n);
    };
    auto inside = [&](uint32_t p, uint32_t a, uint32_t b, uint32_t c) {
        return turn(a, b, p) >= 0.0 && turn(b, c, p) >= 0.0 && turn(c, a, p) >= 0.0;
    };
    while (v.size() > 3) {
        bool clipped = false;
        for (size_t i = 0; i < v.size() && !clipped; ++i) {
            const uint32_t a = v[(i + v.size() - 1) % v.size()], b = v[i],
                           c = v[(i + 1) % v.size()];
            if (!(turn(a, b, c) > 0.0)) continue;
            bool ear = true;
            for (uint32_t p : v)
                if (p != a && p != b && p != c && points[p] != points[a] &&
                    points[p] != points[b] && points[p] != points[c] && inside(p, a, b, c))
                    ear = false;
            if (!ear) continue;
            triangles.push_back({a, b, c});
            v.erase(v.begin() + std::ptrdiff_t(i));
            clipped = true;
        }
        if (!clipped) {  // only straight or repeated corners left: a fan closes the edges
            for (size_t i = 1; i + 1 < v.size(); ++i) triangles.push_back({v[0], v[i], v[i + 1]});
            return true;
        }
    }
    triangles.push_back({v[0], v[1], v[2]});
    return true;
}

bool meshContains(const TriangleMesh& mesh, const Vec3& p) {
    return parityInside(mesh, p, Vec3(0.0));
}

MeshSolid meshSolid(TriangleMesh mesh, const MeshLimits& limits) {
    MeshSolid out;
    if (mesh.triangles.size() > limits.maxTriangles)
        throw MeshError("has " + std::to_string(mesh.triangles.size()) + " triangles, over the " +
                        std::to_string(limits.maxTriangles) + " Lancer reads of a mesh");
    for (const Vec3& p : mesh.points)
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
            throw MeshError("has a point that is not a finite number");
    mesh.weld();
    if (mesh.triangles.empty()) return out;
    auto nb = neighbours(mesh);
    orientShells(mesh, nb);
    checkSelfIntersection(mesh, nb, limits, out);
    SolidBsp(mesh, limits, out).build();
    return out;
}

}  // namespace lancer
