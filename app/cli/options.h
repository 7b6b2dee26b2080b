// The option table shared by every subcommand (and the viewer's defaults).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "engine/accel/accelerator.h"
#include "engine/render/renderer.h"
#include "engine/scene/scene.h"

namespace lancer::cli {

struct CommonOptions {
    /// The command line's default scheme is the fastest one measured (README, "Speed against
    /// error"); BuildParams itself defaults to brute force, the reference.
    static BuildParams defaultBuild() {
        BuildParams b;
        b.scheme = SchemeKind::Regular;
        return b;
    }
    std::string scene = "builtin:default";
    int width = 0, height = 0;  ///< 0: the scene's own size (the other follows its aspect)
    BuildParams build = defaultBuild();
    RenderOptions render;
    std::string statsPath, depthPath;
};

/// Add the common options (DESIGN.md section 6) to a subcommand.
void addCommonOptions(CLI::App& app, CommonOptions& o);
/// A build's progress, one line on stderr a second once it takes more than a second.
BuildControl buildProgressOnStderr();
/// The image size from the options and the scene's default size.
void resolveSize(const CommonOptions& o, const Scene& scene, int& w, int& h);

}  // namespace lancer::cli
