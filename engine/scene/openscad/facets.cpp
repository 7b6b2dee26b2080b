#include "engine/scene/openscad/facets.h"

#include <algorithm>
#include <cmath>

namespace lancer::openscad {

int FragmentRule::fragments(double r) const {
    return int(std::min(fragmentsFromR(r, fn, fa, fs), double(kMaxFragments)));
}

double sinDegrees(double a) {
    a = std::fmod(a, 360.0);
    if (a < 0.0) a += 360.0;
    if (a == 0.0 || a == 180.0) return 0.0;
    if (a == 90.0) return 1.0;
    if (a == 270.0) return -1.0;
    return std::sin(a * M_PI / 180.0);
}

double cosDegrees(double a) { return sinDegrees(a + 90.0); }

std::vector<Vec2> circlePolygon(double r, int n) {
    std::vector<Vec2> p(size_t(std::max(n, 0)));
    for (int i = 0; i < n; ++i) {
        const double phi = 360.0 * i / n;
        p[size_t(i)] = {r * cosDegrees(phi), r * sinDegrees(phi)};
    }
    return p;
}

SphereRings sphereRings(double r, int n) {
    SphereRings s;
    s.n = n;
    const int rings = (n + 1) / 2;
    for (int i = 0; i < rings; ++i) {
        const double phi = 180.0 * (i + 0.5) / rings;
        s.radius.push_back(r * sinDegrees(phi));
        s.z.push_back(r * cosDegrees(phi));
    }
    return s;
}

std::vector<Vec3> spherePoints(double r, int n) {
    const SphereRings s = sphereRings(r, n);
    std::vector<Vec3> out;
    for (size_t i = 0; i < s.z.size(); ++i)
        for (const Vec2& p : circlePolygon(s.radius[i], n)) out.push_back(Vec3(p, s.z[i]));
    return out;
}

std::vector<Vec3> cylinderPoints(double r1, double r2, double h, int n) {
    std::vector<Vec3> out;
    auto ring = [&](double r, double z) {
        if (r == 0.0) {
            out.push_back({0.0, 0.0, z});
            return;
        }
        for (const Vec2& p : circlePolygon(r, n)) out.push_back(Vec3(p, z));
    };
    ring(r1, 0.0);
    ring(r2, h);
    return out;
}

double sphereFacetError(double r, int n) {
    const SphereRings s = sphereRings(r, n);
    double nearest = std::abs(s.z.front());  // the caps
    // Each band's faces are alike about the axis: the first one's plane stands for all.
    for (size_t i = 0; i + 1 < s.z.size(); ++i) {
        const Vec3 p0(s.radius[i], 0.0, s.z[i]), q0(s.radius[i + 1], 0.0, s.z[i + 1]);
        const Vec3 p1(s.radius[i] * cosDegrees(360.0 / n), s.radius[i] * sinDegrees(360.0 / n),
                      s.z[i]);
        const Vec3 q1(s.radius[i + 1] * cosDegrees(360.0 / n),
                      s.radius[i + 1] * sinDegrees(360.0 / n), s.z[i + 1]);
        const Vec3 nn = s.radius[i] >= s.radius[i + 1] ? glm::cross(p1 - p0, q0 - p0)
                                                       : glm::cross(q1 - q0, p0 - q0);
        nearest = std::min(nearest, std::abs(glm::dot(glm::normalize(nn),
                                                      s.radius[i] >= s.radius[i + 1] ? p0 : q0)));
    }
    return r - nearest;
}

double sagitta(double r, int n) { return r * (1.0 - std::cos(M_PI / std::max(n, 3))); }

}  // namespace lancer::openscad
