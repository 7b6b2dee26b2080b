// The camera's mouse and key controls, read from ImGui's input state (which the window's
// platform backend, or a test, fills): drags and the wheel move the camera unless ImGui wants
// the mouse, keys act unless ImGui wants the keyboard.
#pragma once

#include "app/viewer/viewer_state.h"

namespace lancer::viewer {

/// Left drag orbits, middle drag pans, right drag and the wheel zoom.
void handleMouse(ViewerState& st, int fbHeight);
/// R resets the camera, O (or P) toggles perspective and orthographic, I shows or hides the
/// 3D inspector.
void handleKeys(ViewerState& st);

}  // namespace lancer::viewer
