// Orbit, pan and zoom of the viewer's camera, and its JSON form (the .camera.json sidecar keys).
#pragma once

#include <string>

#include "engine/scene/camera.h"

namespace lancer::viewer {

/// Turn `from` about `at`: `yaw` radians around the camera's up vector, `pitch` radians around
/// its right vector, never past the up vector (the view direction stays off the up axis).
void orbit(Camera& c, double yaw, double pitch);
/// Slide `from` and `at` in the image plane so the scene follows a drag of (dx, dy) pixels
/// (y down) in a viewport `viewportHeight` pixels tall.
void pan(Camera& c, double dx, double dy, int viewportHeight);
/// Scale the distance to `at` (perspective) or the image height (orthographic) by `factor`.
void zoom(Camera& c, double factor);
/// Switch between perspective and orthographic, keeping the framing of the plane through `at`.
void toggleProjection(Camera& c);
/// Read a camera from JSON with the sidecar's keys ("from", "at", "up", "fov", "projection",
/// "ortho_height"; keys not given keep `base`'s values, a missing "projection" means
/// perspective). Throws SceneError naming line and column.
Camera cameraFromJson(const std::string& text, const Camera& base);

}  // namespace lancer::viewer
