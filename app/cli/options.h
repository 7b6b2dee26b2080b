// The common options of every subcommand (docs/design.md section 6), registered from the parameter
// table (param_table.h), and the command line's error messages.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "app/cli/param_table.h"
#include "engine/accel/accelerator.h"
#include "engine/render/renderer.h"
#include "engine/scene/scene.h"

namespace lancer::cli {

struct CommonOptions {
    std::string scene = "builtin:default";
    Knobs knobs;  ///< every option of the table
};

/// Add the common options (docs/design.md section 6; every entry of paramTable()) to a subcommand.
void addCommonOptions(CLI::App& app, CommonOptions& o);
/// A build's progress, one line on stderr a second once it takes more than a second.
BuildControl buildProgressOnStderr();
/// The image size from the options and the scene's default size.
void resolveSize(const CommonOptions& o, const Scene& scene, int& w, int& h);
/// The render options the knobs ask for, at the size resolveSize gives.
RenderOptions renderOptions(const CommonOptions& o, const Scene& scene);
/// Load the scene of `o`, with the camera of --camera when given. Throws SceneError.
Scene loadSceneWithCamera(const CommonOptions& o);

/// The message a parse error prints: "error: ..." and, for an option or subcommand that does
/// not exist, the nearest one that does ("did you mean --max-level?"). `args` are the
/// command line's arguments after the program name.
std::string parseErrorMessage(const CLI::App& app, const CLI::ParseError& e,
                              const std::vector<std::string>& args);

}  // namespace lancer::cli
