// `lancer view`: the GLFW window around ViewerApp.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "app/cli/options.h"

namespace lancer::viewer {

struct ViewOptions {
    int frames = 0;           ///< > 0: run this many frames, wait for the render, then exit
    std::string screenshot;   ///< with frames: save the window here before exiting
    bool logTimings = false;  ///< print pass latencies to stderr
    bool replayChange =
        false;  ///< after the first complete image, rebuild once (timed like a parameter change)
    /// With frames: after the first complete image, call the window's drop callback with this
    /// path, as GLFW does when a file is dropped on the window (a scripted drop).
    std::string drop;
    std::string ini;  ///< settings file; empty: the default one ("none": no file)
    /// Redraw every frame (at most 60 per second), as while the user keeps interacting; else
    /// only on input, on a worker's result and at 10 Hz while rendering.
    bool continuous = false;
    bool hidePanels = false;  ///< start with the panels hidden (Tab shows them)
    /// `--orbit DEG`: once the structure is ready, turn the camera DEG degrees about its target
    /// in each of the first `frames` frames, as a drag would (to time frames while it moves).
    double orbit = 0.0;
    /// The layers shown (DESIGN.md section 6: a comma list, "none" for none); empty: the
    /// saved ones.
    int64_t select = -1;  ///< a region id to select once the structure is built; -1: none
    /// `--pick X Y`: the pixel whose ray tree is played (empty: none).
    std::vector<int> pick;
    int pickRay = 0;  ///< `--ray K`: the ray of the tree played
    /// `--step first|last|N` with --pick: the step the playback stops at (kLastStep: last).
    int pickStep = 0;
    /// `--show LIST` (docs/design.md section 6: a comma list, "none" for none); empty: the
    /// saved ones.
    std::string show;
    std::string view;  ///< `--view MODE`: colour or a heat map (viewModeWord); empty: the saved one
    std::string ab;    ///< `--ab new|old|diff`: the rebuild A/B the heat map shows
    std::string change;  ///< `--change LIST`: NAME=VALUE changes applied after the first image
};

/// ViewOptions::pickStep of `--step last`: the ray's final step.
inline constexpr int kLastStep = -1;

/// What runViewer returns when no window can be opened (no display, no OpenGL 3.3).
inline constexpr int kNoDisplay = -1;

/// Open the viewer on the options; `given(name)` tells which options the user set explicitly
/// (they override the saved settings). Returns the exit status, or kNoDisplay with `why` set.
int runViewer(const cli::CommonOptions& o, const ViewOptions& v,
              const std::function<bool(const std::string&)>& given, std::string& why);

}  // namespace lancer::viewer
