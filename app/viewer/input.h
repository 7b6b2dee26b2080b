// The camera's mouse and key controls, read from ImGui's input state (which the window's
// platform backend, or a test, fills): drags and the wheel move the camera unless ImGui wants
// the mouse, keys act unless ImGui wants the keyboard.
#pragma once

#include "app/viewer/playback/playback.h"
#include "app/viewer/viewer_state.h"

namespace lancer::viewer {

/// Left drag orbits, middle drag pans, right drag and the wheel zoom.
void handleMouse(ViewerState& st, int fbHeight);
/// R resets the camera, O (or P) toggles perspective and orthographic, Tab hides or shows the
/// panels, I shows or hides the 3D inspector.
void handleKeys(ViewerState& st);
/// The ray playback's keys, once a ray is picked: Left / Right step back / forward (repeating
/// while held), Home / End go to the first / last step, Space plays or pauses, Up / Down choose
/// the previous / next ray of the tree. True when one of them acted.
bool handlePlaybackKeys(playback::RayPlayback& play);
/// The F key was pressed this frame (frame the selection).
bool frameKeyPressed();

}  // namespace lancer::viewer
