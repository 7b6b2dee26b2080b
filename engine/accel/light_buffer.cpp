#include "engine/accel/light_buffer.h"

#include <algorithm>
#include <cmath>

#include "engine/scene/scene.h"

namespace lancer {

void LightBuffer::Map::project(const Box3& x, double& dNear, double& uLo, double& uHi,
                               double& vLo, double& vHi) const {
    dNear = s > 0.0 ? L[a] - x.hi[a] : x.lo[a] - L[a];
    const double dFar = s > 0.0 ? L[a] - x.lo[a] : x.hi[a] - L[a];
    uLo = vLo = kInf;
    uHi = vHi = -kInf;
    // n / d is monotone in n and in d (d > 0): the extremes are at the box's corners.
    for (double d : {dNear, dFar})
        for (int k = 0; k < 2; ++k) {
            const double u = ((k ? x.hi[b] : x.lo[b]) - L[b]) / d;
            const double v = ((k ? x.hi[c] : x.lo[c]) - L[c]) / d;
            uLo = std::min(uLo, u), uHi = std::max(uHi, u);
            vLo = std::min(vLo, v), vHi = std::max(vHi, v);
        }
}

namespace {

std::vector<Vec3> positions(const std::vector<Light>& lights) {
    std::vector<Vec3> out;
    for (const Light& l : lights) out.push_back(l.position);
    return out;
}

}  // namespace

LightBuffer::LightBuffer(const Scene& scene, int bins)
    : LightBuffer(scene.bounds, scene.minBox, positions(scene.lights), bins) {}

LightBuffer::LightBuffer(const Box3& bounds, const std::vector<Box3>& boxes,
                         const std::vector<Vec3>& points, int bins) {
    if (bounds.isEmpty() || !bounds.isBounded() || points.empty()) return;
    const Vec3 e = bounds.extent();
    const double largest = std::max({e.x, e.y, e.z});
    const double size = largest + std::max(glm::length(bounds.lo), glm::length(bounds.hi));
    // Depths are compared with an allowance far above their rounding (a few ulps) and far below
    // the tracer's offset of shadow-ray origins (1e-9 of the scene scale), so a lit surface's
    // shadow ray is found unblocked at its origin; boxes are widened sideways by more.
    hair_ = 1e-12 * size;
    const double side = 1e-9 * size;
    box_ = {bounds.lo - Vec3(hair_), bounds.hi + Vec3(hair_)};
    maps_.resize(points.size());
    for (size_t l = 0; l < points.size(); ++l) {
        Map& m = maps_[l];
        m.L = points[l];
        // The face of the box the light is farthest beyond; a light inside gets no map.
        double gap = 0.0;
        for (int a = 0; a < 3; ++a)
            for (double s : {1.0, -1.0}) {
                const double x = s > 0.0 ? m.L[a] - box_.hi[a] : box_.lo[a] - m.L[a];
                if (x > gap) gap = x, m.a = a, m.s = s;
            }
        // Well outside: a ray from the point that meets the box then runs steeply enough along the
        // axis that rounding of a grazing hit stays inside its box's depth range.
        if (!(gap > 1e-3 * largest) || !std::isfinite(gap)) continue;
        m.b = (m.a + 1) % 3;
        m.c = (m.a + 2) % 3;
        m.n = std::max(1, bins);
        double dn, u0, u1, v0, v1;
        m.project(box_, dn, u0, u1, v0, v1);
        if (!(u1 > u0) || !(v1 > v0)) continue;
        m.u0 = u0, m.v0 = v0;
        m.su = double(m.n) / (u1 - u0);
        m.sv = double(m.n) / (v1 - v0);
        const double pad = 1e-9 * std::max(u1 - u0, v1 - v0);
        m.near.assign(size_t(m.n) * size_t(m.n), kInf);
        for (const Box3& mb : boxes) {
            if (mb.isEmpty()) continue;  // a dropped primitive
            Box3 x{mb.lo - Vec3(side), mb.hi + Vec3(side)};  // widened across the view axis only
            x.lo[m.a] = mb.lo[m.a], x.hi[m.a] = mb.hi[m.a];
            m.project(x, dn, u0, u1, v0, v1);
            const int i0 = m.index(u0 - pad, m.u0, m.su), i1 = m.index(u1 + pad, m.u0, m.su);
            const int j0 = m.index(v0 - pad, m.v0, m.sv), j1 = m.index(v1 + pad, m.v0, m.sv);
            for (int j = j0; j <= j1; ++j) {
                double* row = m.near.data() + size_t(j) * size_t(m.n);
                for (int i = i0; i <= i1; ++i) row[i] = std::min(row[i], dn);
            }
        }
    }
}

size_t LightBuffer::memoryBytes() const {
    size_t bytes = maps_.size() * sizeof(Map);
    for (const Map& m : maps_) bytes += m.near.size() * sizeof(double);
    return bytes;
}

size_t LightBuffer::mappedLights() const {
    return size_t(std::count_if(maps_.begin(), maps_.end(), [](const Map& m) { return !m.near.empty(); }));
}

}  // namespace lancer
