// The viewer's panels: a closed set of ImGui windows, each in a file of its own, each reading
// and acting on the ViewerState. The frame (viewer_app.cpp) calls drawPanels() once.
#pragma once

#include <functional>

#include "app/viewer/panels/layout.h"
#include "app/viewer/playback/ray_player.h"
#include "app/viewer/viewer_state.h"

namespace lancer::viewer {

/// What the layout remembers of each panel from one frame to the next: the height its content
/// asked for and whether it is folded.
using PanelHeights = std::array<PanelRequest, kPanelCount>;

/// The panels of the viewer's other rooms, each drawing its own window (Begin to End) when
/// called with its open flag: the overlays', the selection's, the inspector's, the structure
/// tree's, the ray's.
struct PanelContents {
    std::function<void(bool*)> overlays, selection, inspector, tree, ray;
};

/// What the layout is given for a width x height window: the panels `s` shows, at `heights`.
LayoutInput layoutInputOf(const ViewerSettings& s, bool panelsHidden, const PanelHeights& heights,
                          float width, float height);
/// This frame's layout (layout.h) of a width x height window (display units): the panels the
/// settings show, at the heights they asked for last frame.
PanelLayout planPanels(const ViewerState& st, const PanelHeights& heights, float width,
                       float height);
/// The main menu bar and every panel the settings show where `layout` puts them (none while the
/// panels are hidden), and the heights they ask for next. The functions below draw a panel's
/// content, between its Begin and End.
void drawPanels(ViewerState& st, const PanelLayout& layout, PanelHeights& heights,
                const PanelContents& more);

/// Which panels are shown, the scene, build and error notes.
void menuBar(ViewerState& st);
/// Scene, subdivision and rendering parameters.
void parametersPanel(ViewerState& st);
/// The Parameters panel's line of a structure's stop reasons (`--stats` "stop_reasons" in its
/// `extra`): "leaves stopped by max-objects 3, max-level 0, cost 12, memory 0" ("zones" for
/// the irregular scheme); "" when it has none (brute force).
std::string stopReasonsLine(const nlohmann::json& extra, SchemeKind scheme);
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
