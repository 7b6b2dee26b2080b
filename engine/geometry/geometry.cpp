#include "engine/geometry/geometry.h"

#include <algorithm>
#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>

namespace lancer {

std::string toString(const Vec3& v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.17g, %.17g, %.17g)", v.x, v.y, v.z);
    return buf;
}

std::string Ray::toString() const {
    return "Ray{o=" + lancer::toString(o) + " d=" + lancer::toString(d) + "}";
}

std::string Box3::toString() const {
    if (isEmpty()) return "Box3{empty}";
    return "Box3{" + lancer::toString(lo) + " .. " + lancer::toString(hi) + "}";
}

bool Box3::isBounded() const {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(lo[a]) || !std::isfinite(hi[a])) return false;
    return !isEmpty();
}

bool clipLine(const Ray& r, const Box3& b, double& t0, double& t1) {
    if (b.isEmpty()) return false;
    t0 = -kInf;
    t1 = kInf;
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0.0) {
            if (r.o[a] < b.lo[a] || r.o[a] > b.hi[a]) return false;
            continue;
        }
        double inv = 1.0 / r.d[a];
        double ta = (b.lo[a] - r.o[a]) * inv;
        double tb = (b.hi[a] - r.o[a]) * inv;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
    }
    return true;
}

Transform::Transform(const Mat4& matrix) : m(matrix), inv(glm::inverse(matrix)) {
    normal = glm::transpose(Mat3(inv));
}

Transform Transform::translate(const Vec3& t) { return Transform(glm::translate(Mat4(1.0), t)); }
Transform Transform::scale(const Vec3& s) { return Transform(glm::scale(Mat4(1.0), s)); }
Transform Transform::rotate(double degrees, const Vec3& axis) {
    return Transform(glm::rotate(Mat4(1.0), glm::radians(degrees), glm::normalize(axis)));
}

Transform Transform::alongAxis(const Vec3& origin, const Vec3& w) {
    Vec3 u, v;
    orthonormalBasis(w, u, v);
    Mat4 m(1.0);
    m[0] = glm::dvec4(u, 0.0);
    m[1] = glm::dvec4(v, 0.0);
    m[2] = glm::dvec4(w, 0.0);
    m[3] = glm::dvec4(origin, 1.0);
    return Transform(m);
}

Box3 Transform::box(const Box3& local) const {
    if (local.isEmpty()) return local;
    Box3 out;
    for (int c = 0; c < 8; ++c) {
        Vec3 p((c & 1) ? local.hi.x : local.lo.x, (c & 2) ? local.hi.y : local.lo.y,
               (c & 4) ? local.hi.z : local.lo.z);
        out.expand(point(p));
    }
    return out;
}

bool Transform::isInvertible() const {
    double det = glm::determinant(Mat3(m));
    if (!std::isfinite(det) || det == 0.0) return false;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            if (!std::isfinite(inv[i][j])) return false;
    return true;
}

void orthonormalBasis(const Vec3& w, Vec3& u, Vec3& v) {
    Vec3 a = std::abs(w.x) > 0.9 ? Vec3(0, 1, 0) : Vec3(1, 0, 0);
    u = glm::normalize(glm::cross(a, w));
    v = glm::cross(w, u);
}

std::vector<glm::dvec2> convexHull2(std::vector<glm::dvec2> pts) {
    std::sort(pts.begin(), pts.end(),
              [](glm::dvec2 a, glm::dvec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    if (pts.size() < 3) return pts;
    auto cross = [](glm::dvec2 o, glm::dvec2 a, glm::dvec2 b) {
        return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    };
    std::vector<glm::dvec2> h(2 * pts.size());
    size_t k = 0;
    for (size_t i = 0; i < pts.size(); ++i) {  // the lower chain
        while (k >= 2 && cross(h[k - 2], h[k - 1], pts[i]) <= 0.0) --k;
        h[k++] = pts[i];
    }
    for (size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {  // the upper chain
        while (k >= t && cross(h[k - 2], h[k - 1], pts[i - 1]) <= 0.0) --k;
        h[k++] = pts[i - 1];
    }
    h.resize(k - 1);
    return h;
}

}  // namespace lancer
