// The viewer's panels: a closed set of ImGui windows, each in a file of its own, each reading
// and acting on the ViewerState. The frame (viewer_app.cpp) calls drawPanels() once.
#pragma once

#include "app/viewer/playback/ray_player.h"
#include "app/viewer/viewer_state.h"

namespace lancer::viewer {

/// The main menu bar and every panel the settings show, in two columns (none while the panels
/// are hidden). The functions below draw a panel's content, between its Begin and End.
void drawPanels(ViewerState& st);

/// Which panels are shown, the scene, build and error notes.
void menuBar(ViewerState& st);
/// Scene, subdivision and rendering parameters.
void parametersPanel(ViewerState& st);
/// Projection, eye and target, reset, copy and paste as JSON.
void cameraPanel(ViewerState& st);
/// Passes, rays and work per ray, and the speedup over brute force.
void statisticsPanel(ViewerState& st);
/// Colour or heat map, its scale and colour bar, the pixel under the cursor, screenshots.
void viewPanel(ViewerState& st);
/// The picked pixel's ray tree and the playback of one ray: transport, speed, the step list
/// (the lines of `lancer trace`), old and new counts after a rebuild, copy as trace command.
void rayPanel(ViewerState& st, playback::RayPlayer& player, bool* open);

}  // namespace lancer::viewer
