#include "app/viewer/camera_control.h"

#include <algorithm>
#include <cmath>

#include "engine/scene/json_reader.h"

namespace lancer::viewer {

namespace {

/// Rodrigues' rotation of v about the unit axis k.
Vec3 rotate(const Vec3& v, const Vec3& k, double angle) {
    double c = std::cos(angle), s = std::sin(angle);
    return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1.0 - c);
}

}  // namespace

void orbit(Camera& c, double yaw, double pitch) {
    Vec3 f, r, u;
    c.basis(f, r, u);
    Vec3 up = glm::normalize(c.up);
    Vec3 offset = c.from - c.at;
    offset = rotate(offset, up, yaw);
    r = rotate(r, up, yaw);
    // Keep the angle between the offset and the up axis within [1, 179] degrees.
    double len = glm::length(offset);
    double angle = std::acos(std::clamp(glm::dot(offset / len, up), -1.0, 1.0));
    const double lo = glm::radians(1.0), hi = glm::radians(179.0);
    double target = std::clamp(angle - pitch, lo, hi);
    offset = rotate(offset, r, angle - target);
    c.from = c.at + offset;
}

void pan(Camera& c, double dx, double dy, int viewportHeight) {
    Vec3 f, r, u;
    c.basis(f, r, u);
    double unitsPerPixel = c.projection == Projection::Orthographic
                               ? c.orthoHeight / viewportHeight
                               : 2.0 * glm::length(c.at - c.from) *
                                     std::tan(glm::radians(c.fov) * 0.5) / viewportHeight;
    Vec3 move = (-dx * r + dy * u) * unitsPerPixel;
    c.from += move;
    c.at += move;
}

void zoom(Camera& c, double factor) {
    if (c.projection == Projection::Orthographic) {
        c.orthoHeight *= factor;
        return;
    }
    Vec3 offset = (c.from - c.at) * factor;
    if (glm::length(offset) > 1e-9 * std::max(1.0, glm::length(c.at))) c.from = c.at + offset;
}

void toggleProjection(Camera& c) {
    double dist = glm::length(c.at - c.from);
    double half = std::tan(glm::radians(c.fov) * 0.5);
    if (c.projection == Projection::Perspective) {
        c.projection = Projection::Orthographic;
        c.orthoHeight = 2.0 * dist * half;
    } else {
        c.projection = Projection::Perspective;
        // Move `from` so the plane through `at` shows the same height.
        Vec3 dir = glm::normalize(c.from - c.at);
        c.from = c.at + dir * (0.5 * c.orthoHeight / half);
    }
}

Camera cameraFromJson(const std::string& text, const Camera& base) {
    SourceText src("camera JSON", text);
    LocatedJson doc(src);
    JsonAt root{doc, doc.root(), ""};
    if (!root.value.is_object())
        root.fail("expected a JSON object with \"from\", \"at\", \"up\", \"fov\"");
    // The sidecar's reader; lights, background and size land in a scratch scene, ignored here.
    // As in a sidecar, a camera without "projection" is a perspective one.
    Scene holder;
    holder.camera = base;
    holder.camera.projection = Projection::Perspective;
    applyCameraJson(root, holder, false);
    Camera c = holder.camera;
    return c;
}

}  // namespace lancer::viewer
