#include "engine/scene/camera.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace lancer {

void Camera::basis(Vec3& f, Vec3& r, Vec3& u) const {
    f = glm::normalize(at - from);
    r = glm::normalize(glm::cross(f, up));
    u = glm::cross(r, f);
}

Ray Camera::primaryRay(double x, double y, int w, int h) const {
    return PrimaryRays(*this, w, h)(x, y);
}

PrimaryRays::PrimaryRays(const Camera& cam, int w, int h)
    : from_(cam.from), w_(w), h_(h), ortho_(cam.projection == Projection::Orthographic) {
    cam.basis(f_, r_, u_);
    half_ = ortho_ ? 0.5 * cam.orthoHeight : std::tan(glm::radians(cam.fov) * 0.5);
}

Ray PrimaryRays::operator()(double x, double y) const {
    // Offsets of the pixel centre on the image plane, in units of the half height.
    double sx = ((x + 0.5) / w_ * 2.0 - 1.0) * w_ / h_;
    double sy = 1.0 - (y + 0.5) / h_ * 2.0;
    if (ortho_) return {from_ + (sx * half_) * r_ + (sy * half_) * u_, f_};
    return {from_, glm::normalize(f_ + (sx * half_) * r_ + (sy * half_) * u_)};
}

std::string Camera::validate() const {
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(from[a]) || !std::isfinite(at[a]) || !std::isfinite(up[a]))
            return "camera vectors must be finite";
    Vec3 f = at - from;
    if (glm::dot(f, f) == 0.0) return "camera 'from' and 'at' are the same point";
    Vec3 c = glm::cross(glm::normalize(f), up);
    if (glm::dot(c, c) < 1e-24) return "camera 'up' is parallel to the view direction";
    if (projection == Projection::Perspective && !(fov > 0.0 && fov < 180.0))
        return "camera 'fov' must be in (0, 180) degrees";
    if (projection == Projection::Orthographic &&
        !(orthoHeight > 0.0 && std::isfinite(orthoHeight)))
        return "camera 'ortho_height' must be positive";
    return "";
}

std::string Camera::toJson() const {
    nlohmann::json j;
    j["from"] = {from.x, from.y, from.z};
    j["at"] = {at.x, at.y, at.z};
    j["up"] = {up.x, up.y, up.z};
    j["fov"] = fov;
    if (projection == Projection::Orthographic) {
        j["projection"] = "orthographic";
        j["ortho_height"] = orthoHeight;
    }
    return j.dump();
}

}  // namespace lancer
