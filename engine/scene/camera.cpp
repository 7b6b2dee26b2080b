#include "engine/scene/camera.h"

#include <cmath>
#include <nlohmann/json.hpp>

namespace lancer {

void Camera::basis(Vec3& f, Vec3& r, Vec3& u) const {
    f = glm::normalize(at - from);
    r = glm::normalize(glm::cross(f, up));
    u = glm::cross(r, f);
}

namespace {

// Offsets of a pixel centre on the image plane, in units of the half height.
double offsetX(double x, double w, double h) { return ((x + 0.5) / w * 2.0 - 1.0) * w / h; }
double offsetY(double y, double h) { return 1.0 - (y + 0.5) / h * 2.0; }

}  // namespace

Ray Camera::primaryRay(double x, double y, int w, int h) const {
    return PrimaryRays(*this, 0, 0, w, h)(x, y);
}

PrimaryRays::PrimaryRays(const Camera& cam, int w, int h) : PrimaryRays(cam, w, h, w, h) {}

PrimaryRays::PrimaryRays(const Camera& cam, int columns, int rows, int w, int h)
    : from_(cam.from), w_(w), h_(h), ortho_(cam.projection == Projection::Orthographic) {
    cam.basis(f_, r_, u_);
    half_ = ortho_ ? 0.5 * cam.orthoHeight : std::tan(glm::radians(cam.fov) * 0.5);
    column_.resize(size_t(std::max(columns, 0)));
    row_.resize(size_t(std::max(rows, 0)));
    for (size_t x = 0; x < column_.size(); ++x) column_[x] = columnTerm(double(x));
    for (size_t y = 0; y < row_.size(); ++y) row_[y] = rowTerm(double(y));
}

Vec3 PrimaryRays::columnTerm(double x) const {
    return (ortho_ ? from_ : f_) + (offsetX(x, w_, h_) * half_) * r_;
}

Vec3 PrimaryRays::rowTerm(double y) const { return (offsetY(y, h_) * half_) * u_; }

Ray PrimaryRays::operator()(double x, double y) const {
    return through(columnTerm(x) + rowTerm(y));
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
