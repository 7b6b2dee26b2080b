// What the viewer remembers between runs, kept in the ImGui ini file under [Lancer][Settings].
#pragma once

#include <optional>
#include <string>

#include "app/cli/options.h"
#include "app/viewer/colormap.h"
#include "app/viewer/inspector/inspector_model.h"
#include "app/viewer/overlay/overlays.h"
#include "engine/accel/accelerator.h"
#include "engine/render/tracer.h"

namespace lancer::viewer {

struct ViewerSettings {
    std::string scene = "builtin:default";   ///< last scene opened
    BuildParams build = cli::Knobs{}.build;  ///< the command line's default
    ShadingOptions shading;
    /// --camera FILE: replaces the camera of the first scene opened (not saved in the ini).
    std::string cameraPath;
    /// --facets: how .csg files are read (not saved in the ini).
    ReadOptions read;
    int threads = 0;  ///< render threads (0: all cores)
    int windowWidth = 1280, windowHeight = 720;
    /// The panel columns' widths as last dragged (0: automatic) and, with the inspector
    /// shown, the image's share of the width they leave (panels/layout.h).
    float leftColumn = 0.0f, rightColumn = 0.0f, imageShare = 0.5f;
    bool showParameters = true, showStatistics = true, showCamera = true, showView = true;
    bool showOverlays = true;
    bool showSelection = false;  ///< opened by a pick or --select
    /// The structure tree (opened from the Panels menu or `--show tree`; not saved).
    bool showTree = false;
    /// The 3D inspector, beside the image (the right half of what the panels leave).
    bool showInspector = false;
    /// The Ray panel (not saved: it opens with the first pick).
    bool showRay = false;
    /// The overlays and the inspector draw only the regions the played ray visits (the Ray
    /// panel, `--show visited`; not saved).
    bool rayRegionsOnly = false;
    ViewMode mode = ViewMode::Color;
    bool autoScale = true;     ///< heat scale follows the image's largest value
    float heatScale = 100.0f;  ///< counter value at the top of the colour map
    bool logScale = false;     ///< heat maps on a log scale (log(1 + count))
    /// The overlays' layers and choices (cap, level range, colours), and how they are drawn
    /// (opacities, tooltip; not the cut replay, which is the structure's).
    overlay::OverlayOptions overlays;
    overlay::OverlayLook overlayLook;
    /// The inspector's layers and filters (`show` is showInspector).
    inspector::InspectorOptions inspector;
    /// The inspector's camera, kept for the scene it was last on (`inspectorScene`): a run that
    /// opens that scene first restores it instead of framing the structure afresh.
    std::optional<Camera> inspectorCamera;
    std::string inspectorScene;
    /// The knobs' format of the ini read: 1 (no `knob_format` line) before max-objects took
    /// "auto", when every ini wrote its default as max_objects=4 (read as auto, the same build);
    /// 2 since, written first.
    int knobFormat = 1;
};

/// Register the [Lancer][Settings] ini handler of the current ImGui context, reading into and
/// writing from `*s` (which must outlive the context). Call before the ini is loaded.
void registerSettingsHandler(ViewerSettings* s);
/// The settings as the parameter table's values, and back (the window size is width, height).
cli::Knobs knobsOf(const ViewerSettings& s);
void setKnobs(ViewerSettings& s, const cli::Knobs& k);

/// Serialise as the ini lines the handler writes ("key=value"), and parse one such line
/// (unknown keys and bad values are ignored: an old ini must never stop the viewer).
std::string settingsLines(const ViewerSettings& s);
void readSettingsLine(ViewerSettings& s, const std::string& line);

}  // namespace lancer::viewer
