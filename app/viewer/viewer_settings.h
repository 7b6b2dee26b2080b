// What the viewer remembers between runs, kept in the ImGui ini file under [Lancer][Settings].
#pragma once

#include <string>

#include "app/cli/options.h"
#include "app/viewer/colormap.h"
#include "engine/accel/accelerator.h"
#include "engine/render/tracer.h"

namespace lancer::viewer {

struct ViewerSettings {
    std::string scene = "builtin:default";                   ///< last scene opened
    BuildParams build = cli::CommonOptions::defaultBuild();  ///< the command line's default
    ShadingOptions shading;
    int threads = 0;  ///< render threads (0: all cores)
    int windowWidth = 1280, windowHeight = 720;
    bool showParameters = true, showStatistics = true, showCamera = true, showView = true;
    /// The 3D inspector over the right half of the window (not saved: it starts hidden).
    bool showInspector = false;
    /// The Ray panel (not saved: it opens with the first pick).
    bool showRay = false;
    ViewMode mode = ViewMode::Color;
    bool autoScale = true;     ///< heat scale follows the image's largest value
    float heatScale = 100.0f;  ///< counter value at the top of the colour map
};

/// Register the [Lancer][Settings] ini handler of the current ImGui context, reading into and
/// writing from `*s` (which must outlive the context). Call before the ini is loaded.
void registerSettingsHandler(ViewerSettings* s);
/// Serialise as the ini lines the handler writes ("key=value"), and parse one such line
/// (unknown keys and bad values are ignored: an old ini must never stop the viewer).
std::string settingsLines(const ViewerSettings& s);
void readSettingsLine(ViewerSettings& s, const std::string& line);

}  // namespace lancer::viewer
