// `lancer bench --scale`: the scale table and the defaults check (docs/scale.md). Each scene is
// measured scheme by scheme, each in a child process of its own, so that the process's peak
// resident memory (getrusage of the child) is the scheme's and a build that runs away is killed
// without taking the run with it: brute force (the oracle, on a lattice of pixels when the whole
// image would take too long), the regular and irregular schemes at their defaults, and Embree as a
// peer on union-only scenes at --bounces 0.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "engine/accel/build_params.h"

namespace lancer::bench {

struct ScaleOptions {
    // scenes to outDir: `lancer bench --scale` sets them from bench's own options (256x256, all
    // cores, 3 bounces, bench-out unless given); the defaults here are the scale table's.
    std::vector<std::string> scenes;
    int width = 512, height = 512;
    bool sceneSize = false;  ///< each scene's own image size instead of width x height
    int threads = 2;
    int bounces = 0;
    std::string outDir = "scale-out";
    size_t memoryBudget = 0;   ///< --memory-budget of the builds (0: the engine's default)
    double timeLimitS = 60.0;  ///< a scheme's load, build and render must end within it
    size_t memoryLimit = size_t(4) << 30;  ///< and its peak resident memory stay below it
    double bruteLimitS = 60.0;  ///< brute force renders every pixel when estimated below this
    /// A child is killed past this many seconds (0: max(2 x timeLimitS, bruteLimitS + 60)).
    double killAfterS = 0.0;
    bool peer = true;  ///< Embree on union-only scenes (at --bounces 0 only)
    /// The schemes measured (--schemes); without brute force no hits are compared.
    std::vector<std::string> schemes = schemeNames();  ///< every scheme of kSchemeTable
};

/// Measure every scene, write OUT/scale.md and OUT/scale.json, print the table and the list of
/// failures (a scheme refused, crashed, over a limit, or with hits other than brute force's).
/// Returns 0 when there is none, 1 when there are failures, 2 on bad options.
int runScale(const ScaleOptions& opt);

}  // namespace lancer::bench
