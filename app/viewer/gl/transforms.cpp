#include "app/viewer/gl/transforms.h"

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

namespace lancer::viewer::gl {

glm::mat4 imagePixelsToClip(float width, float height) {
    glm::mat4 m(1.0f);
    m[0][0] = 2.0f / width;
    m[1][1] = -2.0f / height;
    m[3][0] = -1.0f;
    m[3][1] = 1.0f;
    return m;
}

glm::mat4 worldToClip(const Camera& camera, int width, int height, double nearDepth,
                      double farDepth) {
    // glm::lookAt builds the same basis as Camera::basis (R = F x up, U = R x F).
    const glm::dmat4 view = glm::lookAt(camera.from, camera.at, camera.up);
    const double aspect = double(width) / double(height);
    glm::dmat4 proj;
    if (camera.projection == Projection::Orthographic) {
        const double half = 0.5 * camera.orthoHeight;
        proj = glm::ortho(-half * aspect, half * aspect, -half, half, nearDepth, farDepth);
    } else {
        proj = glm::perspective(glm::radians(camera.fov), aspect, nearDepth, farDepth);
    }
    return glm::mat4(proj * view);
}

ImageProjector::ImageProjector(const Camera& camera, int width, int height)
    : from_(camera.from),
      w_(width),
      h_(height),
      ortho_(camera.projection == Projection::Orthographic) {
    camera.basis(f_, r_, u_);
    half_ = ortho_ ? 0.5 * camera.orthoHeight : std::tan(glm::radians(camera.fov) * 0.5);
}

std::optional<glm::dvec2> ImageProjector::toImage(const Vec3& p) const {
    const Vec3 d = p - from_;
    double sx = glm::dot(d, r_), sy = glm::dot(d, u_);
    if (!ortho_) {
        const double z = glm::dot(d, f_);
        if (!(z > 0.0)) return std::nullopt;
        sx /= z;
        sy /= z;
    }
    // Inverse of PrimaryRays: sx = (2x/w - 1) * w/h * half, sy = (1 - 2y/h) * half.
    const double x = (sx / half_ * h_ / w_ + 1.0) * 0.5 * w_;
    const double y = (1.0 - sy / half_) * 0.5 * h_;
    return glm::dvec2(x, y);
}

}  // namespace lancer::viewer::gl
