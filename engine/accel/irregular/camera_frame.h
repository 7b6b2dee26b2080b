// The camera frame of the irregular subdivision: screen x along R, screen y along U, depth z
// along F, origin at the eye (docs/design.md section 4). The frame is orthonormal, so a ray keeps
// its parameter t when it is expressed in it: region intervals and world hits share one t.
#pragma once

#include "engine/scene/camera.h"

namespace lancer {

struct CameraFrame {
    Vec3 origin{0.0};
    Vec3 x{1, 0, 0}, y{0, 1, 0}, z{0, 0, 1};  ///< R, U, F of Camera::basis

    static CameraFrame of(const Camera& cam) {
        CameraFrame f;
        f.origin = cam.from;
        cam.basis(f.z, f.x, f.y);
        return f;
    }
    /// A world point in camera coordinates.
    Vec3 point(const Vec3& p) const {
        Vec3 v = p - origin;
        return {glm::dot(v, x), glm::dot(v, y), glm::dot(v, z)};
    }
    Vec3 vector(const Vec3& v) const { return {glm::dot(v, x), glm::dot(v, y), glm::dot(v, z)}; }
    /// A camera-frame point back in world coordinates.
    Vec3 toWorld(const Vec3& c) const { return origin + c.x * x + c.y * y + c.z * z; }
    Ray ray(const Ray& r) const { return {point(r.o), vector(r.d)}; }
    /// Bound in the camera frame of a world box (its eight corners).
    Box3 box(const Box3& b) const {
        Box3 out;
        if (b.isEmpty()) return out;
        for (int i = 0; i < 8; ++i)
            out.expand(point(
                {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z}));
        return out;
    }
};

}  // namespace lancer
