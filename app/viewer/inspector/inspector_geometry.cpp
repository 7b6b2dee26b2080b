#include "app/viewer/inspector/inspector_geometry.h"

#include <algorithm>
#include <cmath>

#include "app/viewer/colormap.h"

namespace lancer::viewer::inspector {

const std::array<std::array<int, 2>, 12>& cornerEdges() {
    // Four edges along each axis: the pairs whose numbers differ in that axis's bit.
    static const std::array<std::array<int, 2>, 12> edges = {{{0, 1},
                                                              {2, 3},
                                                              {4, 5},
                                                              {6, 7},
                                                              {0, 2},
                                                              {1, 3},
                                                              {4, 6},
                                                              {5, 7},
                                                              {0, 4},
                                                              {1, 5},
                                                              {2, 6},
                                                              {3, 7}}};
    return edges;
}

Corners boxCorners(const Box3& b) {
    Corners c;
    for (int i = 0; i < 8; ++i)
        c[size_t(i)] = {i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z};
    return c;
}

std::array<glm::vec3, 8> toFloat(const Corners& c) {
    std::array<glm::vec3, 8> out;
    for (size_t i = 0; i < 8; ++i) out[i] = glm::vec3(c[i]);
    return out;
}

Box3 cornersBox(const Corners& c) {
    Box3 b;
    for (const Vec3& p : c) b.expand(p);
    return b;
}

namespace {

/// Half the image height on the image plane: at distance 1 (perspective) or in scene units.
double halfHeight(const Camera& cam) {
    return cam.projection == Projection::Orthographic ? 0.5 * cam.orthoHeight
                                                      : std::tan(glm::radians(cam.fov) * 0.5);
}

}  // namespace

Vec3 imagePoint(const Camera& cam, int w, int h, double x, double y, double depth) {
    Vec3 f, r, u;
    cam.basis(f, r, u);
    const double half = halfHeight(cam);
    // Camera::primaryRay's offsets, for continuous coordinates instead of pixel centres.
    const double sx = (x / w * 2.0 - 1.0) * double(w) / double(h) * half;
    const double sy = (1.0 - y / h * 2.0) * half;
    if (cam.projection == Projection::Orthographic) return cam.from + sx * r + sy * u + depth * f;
    return cam.from + depth * (f + sx * r + sy * u);
}

Corners frustumCorners(const Camera& cam, int w, int h, double near, double far) {
    Corners c;
    for (int i = 0; i < 8; ++i)
        c[size_t(i)] = imagePoint(cam, w, h, i & 1 ? w : 0, i & 2 ? 0 : h, i & 4 ? far : near);
    return c;
}

std::array<Vec3, 4> imagePlane(const Camera& cam, int w, int h) {
    const double d =
        cam.projection == Projection::Orthographic ? 0.0 : glm::length(cam.at - cam.from);
    return {imagePoint(cam, w, h, 0, 0, d), imagePoint(cam, w, h, w, 0, d),
            imagePoint(cam, w, h, w, h, d), imagePoint(cam, w, h, 0, h, d)};
}

double cameraDepth(const Camera& cam, const Vec3& p) {
    return glm::dot(p - cam.from, glm::normalize(cam.at - cam.from));
}

void depthRange(const Camera& cam, const Box3& b, double& near, double& far) {
    double lo = kInf, hi = -kInf;
    for (const Vec3& p : boxCorners(b)) {
        const double d = cameraDepth(cam, p);
        lo = std::min(lo, d);
        hi = std::max(hi, d);
    }
    const double margin = 0.01 * std::max(hi - lo, 1e-9);
    far = hi + margin;
    near = lo - margin;
    if (cam.projection == Projection::Perspective) near = std::max(near, 1e-3 * far);
    if (!(far > near)) far = near + 1.0;
}

float windowDepth(const Camera& cam, double near, double far, double depth) {
    // glm::perspective and glm::ortho map eye z = -near to NDC -1 and -far to +1; the window
    // depth is half of NDC + 1.
    double ndc;
    if (cam.projection == Projection::Orthographic)
        ndc = (2.0 * depth - far - near) / (far - near);
    else
        ndc = (far + near) / (far - near) - 2.0 * far * near / ((far - near) * depth);
    return float(0.5 * (ndc + 1.0));
}

Camera frameBox(const Box3& box, const Vec3& forward, double fov, double aspect) {
    Camera c;
    c.fov = fov;
    c.at = box.isEmpty() ? Vec3(0.0) : box.center();
    const double radius = box.isEmpty() ? 1.0 : std::max(0.5 * glm::length(box.extent()), 1e-6);
    const Vec3 f = glm::normalize(forward);
    c.up = std::abs(f.z) > 0.999 ? Vec3(0.0, 1.0, 0.0) : Vec3(0.0, 0.0, 1.0);
    // The sphere fits the narrower of the vertical and horizontal fields.
    const double half = std::tan(glm::radians(fov) * 0.5) * std::min(1.0, aspect);
    const double dist = radius / std::sin(std::atan(half));
    c.from = c.at - f * dist;
    return c;
}

Camera framedOn(const Camera& c, const Box3& box, double aspect) {
    if (box.isEmpty() || !box.isBounded()) return c;
    const Camera fit = frameBox(box, c.at - c.from, c.fov, aspect);
    Camera out = c;
    out.at = fit.at;
    out.from = fit.from;
    if (c.projection == Projection::Orthographic) {
        const double radius = std::max(0.5 * glm::length(box.extent()), 1e-6);
        out.orthoHeight = 2.0 * radius / std::min(1.0, aspect);
    }
    return out;
}

bool Slab::keeps(const Corners& c) const {
    if (!on) return true;
    double a = kInf, b = -kInf;
    for (const Vec3& p : c) {
        a = std::min(a, p[axis]);
        b = std::max(b, p[axis]);
    }
    return a <= hi && b >= lo;
}

const char* colorByName(ColorBy c) { return c == ColorBy::Prims ? "primitives" : "level"; }

glm::vec3 regionColor(double v, ColorBy by) {
    return by == ColorBy::Level ? levelColor(int(v)) : countColor(v);
}

std::optional<double> rayEnters(const Ray& ray, const Corners& c) {
    // Clip the ray by the six face planes (Cyrus-Beck), each face's outward normal from its
    // corners: the face "axis a, side s" holds the corners whose bit a is s.
    const Vec3 centre = 0.125 * (c[0] + c[1] + c[2] + c[3] + c[4] + c[5] + c[6] + c[7]);
    double t0 = -kInf, t1 = kInf;
    for (int a = 0; a < 3; ++a) {
        for (int s = 0; s < 2; ++s) {
            int idx[4], n = 0;
            for (int i = 0; i < 8; ++i)
                if (((i >> a) & 1) == s) idx[n++] = i;
            // Corners idx[0], idx[1], idx[3], idx[2] go round the face: the cross product of
            // its diagonals is normal to it.
            const Vec3& p0 = c[size_t(idx[0])];
            Vec3 normal = glm::cross(c[size_t(idx[3])] - p0, c[size_t(idx[2])] - c[size_t(idx[1])]);
            const double len = glm::length(normal);
            if (len == 0.0) continue;  // a face shrunk to a line or a point bounds nothing
            normal /= len;
            const Vec3 facePoint =
                0.25 * (p0 + c[size_t(idx[1])] + c[size_t(idx[2])] + c[size_t(idx[3])]);
            if (glm::dot(normal, centre - facePoint) > 0.0) normal = -normal;
            const double dist = glm::dot(normal, ray.o - facePoint);  // > 0: outside
            const double den = glm::dot(normal, ray.d);
            if (den == 0.0) {
                if (dist > 0.0) return std::nullopt;
                continue;
            }
            const double t = -dist / den;
            if (den < 0.0)
                t0 = std::max(t0, t);
            else
                t1 = std::min(t1, t);
        }
    }
    if (t0 > t1 || t1 < 0.0) return std::nullopt;
    return std::max(t0, 0.0);
}

int pickRegion(const Ray& ray, const std::vector<RegionView>& regions,
               const std::vector<uint32_t>& candidates) {
    int best = -1;
    double bestT = kInf, bestVolume = kInf;
    auto consider = [&](uint32_t i) {
        const RegionView& r = regions[i];
        std::optional<double> t = rayEnters(ray, r.corners);
        if (!t) return;
        const Vec3 e = cornersBox(r.corners).extent();
        const double volume = e.x * e.y * e.z;
        if (*t < bestT || (*t == bestT && volume < bestVolume)) {
            best = int(i);
            bestT = *t;
            bestVolume = volume;
        }
    };
    if (candidates.empty())
        for (uint32_t i = 0; i < regions.size(); ++i) consider(i);
    else
        for (uint32_t i : candidates) consider(i);
    return best;
}

}  // namespace lancer::viewer::inspector
