#include "engine/scene/openscad/hull3d.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

namespace lancer::openscad {

namespace {

/// Drops the vertices of a closed convex polygon that lie on the segment between their
/// neighbours (within `tol`), so that faces and edges use extreme points only.
void dropCollinear(std::vector<int>& ring, const std::vector<Vec3>& p, double tol) {
    bool changed = true;
    while (changed && ring.size() > 3) {
        changed = false;
        for (size_t i = 0; i < ring.size() && ring.size() > 3; ++i) {
            const Vec3& a = p[size_t(ring[(i + ring.size() - 1) % ring.size()])];
            const Vec3& b = p[size_t(ring[i])];
            const Vec3& c = p[size_t(ring[(i + 1) % ring.size()])];
            const Vec3 ac = c - a;
            const double len = glm::length(ac);
            // Distance of b from the line a c.
            if (len > 0.0 && glm::length(glm::cross(b - a, ac)) / len <= tol) {
                ring.erase(ring.begin() + long(i));
                changed = true;
                break;
            }
        }
    }
}

/// Orders the points of a convex face counter-clockwise about `n`.
void orderAbout(std::vector<int>& face, const std::vector<Vec3>& p, const Vec3& n) {
    Vec3 c(0.0);
    for (int i : face) c += p[size_t(i)];
    c /= double(face.size());
    Vec3 u, v;
    orthonormalBasis(n, u, v);
    if (glm::dot(glm::cross(u, v), n) < 0.0) v = -v;
    std::sort(face.begin(), face.end(), [&](int a, int b) {
        const Vec3 da = p[size_t(a)] - c, db = p[size_t(b)] - c;
        return std::atan2(glm::dot(da, v), glm::dot(da, u)) <
               std::atan2(glm::dot(db, v), glm::dot(db, u));
    });
}

/// The supporting plane through the line a b that turning a plane about the directed line
/// a -> b reaches first (gift wrapping; the turn of a face whose boundary runs a -> b
/// counter-clockwise about its outward normal finds the face across that edge): false when every
/// point lies on the line or the plane found does not hold every point on one side.
bool wrapPlane(const std::vector<Vec3>& p, const Vec3& a, const Vec3& b, double tol,
               glm::dvec4& plane) {
    const Vec3 ab = b - a;
    const double lab = glm::length(ab);
    const Vec3* c = nullptr;
    for (const Vec3& q : p) {
        if (glm::length(glm::cross(ab, q - a)) <= tol * lab) continue;  // on the line
        if (!c) {
            c = &q;
            continue;
        }
        const Vec3 nc = glm::cross(a - b, *c - b);
        if (glm::dot(nc, q - b) > tol * glm::length(nc)) c = &q;  // beyond: turn on to it
    }
    if (!c) return false;
    const Vec3 nn = glm::normalize(glm::cross(a - b, *c - b));
    plane = glm::dvec4(nn, glm::dot(nn, a));
    for (const Vec3& q : p)
        if (glm::dot(nn, q) - plane.w > tol) return false;
    return true;
}

/// The faces of the hull of `p` (not flat): from a supporting plane at the lowest point, each
/// face's neighbours found by wrapping about its edges, O(points x edges). A face is every point
/// within `tol` of its plane, ordered about it, collinear points dropped.
void wrapFaces(const std::vector<Vec3>& p, double tol, std::vector<glm::dvec4>& planes,
               std::vector<std::vector<int>>& faces) {
    auto known = [&](const glm::dvec4& q) {
        for (const glm::dvec4& k : planes)
            if (glm::dot(Vec3(k), Vec3(q)) > 1.0 - 1e-12 && std::abs(k.w - q.w) <= tol) return true;
        return false;
    };
    std::vector<std::pair<int, int>> todo;  // directed edges whose neighbour is sought
    auto addFace = [&](const glm::dvec4& q) {
        if (known(q)) return;
        std::vector<int> face;
        for (size_t m = 0; m < p.size(); ++m)
            if (std::abs(glm::dot(Vec3(q), p[m]) - q.w) <= tol) face.push_back(int(m));
        orderAbout(face, p, Vec3(q));
        dropCollinear(face, p, tol);
        planes.push_back(q);
        for (size_t e = 0; e < face.size(); ++e)
            todo.push_back({face[e], face[(e + 1) % face.size()]});
        faces.push_back(std::move(face));
    };
    // p[0] is the lowest in x (then y, z): the plane x = p[0].x supports the hull. Turned about
    // a line through p[0] in it, it meets a face or an edge; about that edge, a face.
    glm::dvec4 first;
    const Vec3 a = p[0];
    bool found = false;
    for (const Vec3& d : {Vec3(0, 0, 1), Vec3(0, 0, -1), Vec3(0, 1, 0), Vec3(0, -1, 0)}) {
        if (!wrapPlane(p, a, a + d, tol, first)) continue;
        std::vector<int> on;
        for (size_t m = 0; m < p.size(); ++m)
            if (std::abs(glm::dot(Vec3(first), p[m]) - first.w) <= tol) on.push_back(int(m));
        // The points on the plane: a face, or (all on one line) an edge to turn about.
        size_t far = 0;
        for (size_t k = 0; k < on.size(); ++k)
            if (glm::length(p[size_t(on[k])] - a) > glm::length(p[size_t(on[far])] - a)) far = k;
        const Vec3 e = p[size_t(on[far])] - a;
        bool line = true;
        for (int m : on)
            line = line && glm::length(glm::cross(e, p[size_t(m)] - a)) <= tol * glm::length(e);
        if (!line) {
            found = true;
            break;
        }
        if (wrapPlane(p, a, a + e, tol, first) || wrapPlane(p, a + e, a, tol, first)) {
            found = true;
            break;
        }
    }
    if (!found) return;
    addFace(first);
    while (!todo.empty()) {
        const auto [i, j] = todo.back();
        todo.pop_back();
        glm::dvec4 q;
        if (wrapPlane(p, p[size_t(i)], p[size_t(j)], tol, q)) addFace(q);
    }
}

}  // namespace

ConvexHull3 convexHull3(std::vector<Vec3> pts) {
    ConvexHull3 h;
    std::sort(pts.begin(), pts.end(), [](const Vec3& a, const Vec3& b) {
        return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
    });
    pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
    if (pts.empty()) return h;
    double mag = 0.0;
    for (const Vec3& p : pts) mag = std::max({mag, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    const double tol = 1e-9 * std::max(mag, 1e-300);
    // The dimension: the farthest point from the first, from their line, from their plane.
    const Vec3 p0 = pts[0];
    size_t i1 = 0;
    for (size_t i = 0; i < pts.size(); ++i)
        if (glm::length(pts[i] - p0) > glm::length(pts[i1] - p0)) i1 = i;
    if (glm::length(pts[i1] - p0) <= tol) {
        h.dim = 0;
        h.vertices = {p0};
        return h;
    }
    const Vec3 dir = glm::normalize(pts[i1] - p0);
    auto fromLine = [&](const Vec3& p) { return glm::length(glm::cross(p - p0, dir)); };
    size_t i2 = 0;
    for (size_t i = 0; i < pts.size(); ++i)
        if (fromLine(pts[i]) > fromLine(pts[i2])) i2 = i;
    if (fromLine(pts[i2]) <= tol) {
        size_t lo = 0, hi = 0;
        for (size_t i = 0; i < pts.size(); ++i) {
            if (glm::dot(pts[i] - p0, dir) < glm::dot(pts[lo] - p0, dir)) lo = i;
            if (glm::dot(pts[i] - p0, dir) > glm::dot(pts[hi] - p0, dir)) hi = i;
        }
        h.dim = 1;
        h.vertices = {pts[lo], pts[hi]};
        h.edges = {{0, 1}};
        return h;
    }
    const Vec3 pn = glm::normalize(glm::cross(pts[i1] - p0, pts[i2] - p0));
    size_t i3 = 0;
    for (size_t i = 0; i < pts.size(); ++i)
        if (std::abs(glm::dot(pts[i] - p0, pn)) > std::abs(glm::dot(pts[i3] - p0, pn))) i3 = i;
    std::vector<std::vector<int>> faces;
    if (std::abs(glm::dot(pts[i3] - p0, pn)) <= tol) {
        // Flat: the 2D hull in the plane (Andrew's monotone chain), one face.
        Vec3 u = dir, v = glm::cross(pn, dir);
        std::vector<int> order(pts.size());
        for (size_t i = 0; i < order.size(); ++i) order[i] = int(i);
        auto uv = [&](int i) {
            return glm::dvec2(glm::dot(pts[size_t(i)] - p0, u), glm::dot(pts[size_t(i)] - p0, v));
        };
        std::sort(order.begin(), order.end(), [&](int a, int b) {
            const glm::dvec2 pa = uv(a), pb = uv(b);
            return std::tie(pa.x, pa.y) < std::tie(pb.x, pb.y);
        });
        auto turn = [&](int a, int b, int c) {
            const glm::dvec2 ab = uv(b) - uv(a), ac = uv(c) - uv(a);
            return ab.x * ac.y - ab.y * ac.x;
        };
        std::vector<int> ring;
        for (int pass = 0; pass < 2; ++pass) {
            const size_t base = ring.size();
            for (int i : order) {
                while (ring.size() >= base + 2 &&
                       turn(ring[ring.size() - 2], ring.back(), i) <= tol * mag)
                    ring.pop_back();
                ring.push_back(i);
            }
            ring.pop_back();
            std::reverse(order.begin(), order.end());
        }
        dropCollinear(ring, pts, tol);
        h.dim = 2;
        h.planes = {glm::dvec4(pn, glm::dot(pn, p0))};
        faces = {ring};
    } else {
        h.dim = 3;
        wrapFaces(pts, tol, h.planes, faces);
    }
    // Renumber the faces' points as the hull's vertices; collect the edges once each.
    std::map<int, int> index;
    std::map<std::pair<int, int>, bool> seen;
    for (std::vector<int>& f : faces) {
        for (int& i : f) {
            auto [it, fresh] = index.emplace(i, int(h.vertices.size()));
            if (fresh) h.vertices.push_back(pts[size_t(i)]);
            i = it->second;
        }
        for (size_t e = 0; e < f.size(); ++e) {
            int a = f[e], b = f[(e + 1) % f.size()];
            if (seen.emplace(std::minmax(a, b), true).second) h.edges.push_back(std::minmax(a, b));
        }
    }
    h.faces = std::move(faces);
    return h;
}

}  // namespace lancer::openscad
