// `lancer bench`: the speed-against-error report (docs/design.md section 7). Every configuration is
// rendered and compared with the brute-force image of the same run: build time, memory, render
// time, speedup, work per ray, and error (pixels whose hit differs, largest depth difference).
#pragma once

#include <string>
#include <vector>

#include "engine/accel/build_params.h"
#include "engine/scene/scene.h"

namespace lancer::bench {

struct BenchOptions {
    std::vector<std::string> scenes{"builtin:balls:3", "builtin:drilled:6", "builtin:lattice:6",
                                    "builtin:sponge:3"};
    int width = 256, height = 256;
    int threads = 0;
    int bounces = 3;
    std::string outDir = "bench-out";
    bool quick = false;        ///< fewer knob values (used by the test suite)
    bool plots = true;         ///< run gnuplot on the CSV
    bool schemesOnly = false;  ///< default settings of each scheme (and the peer) only: the table
    /// The schemes measured. Without brute force (scenes too large for it; --schemes-only only)
    /// no reference is rendered and the rows have no speedup and no error.
    std::vector<std::string> schemes = schemeNames();  ///< every scheme of kSchemeTable
    /// Each configuration is built and rendered this many times, the configurations of a scene
    /// in turn (round-robin), so that a change in the machine's load falls on all of them; the
    /// figures are the medians, with their range.
    int repeats = 3;
    /// Write OUT/index.html, one self-contained page (plots inline as SVG) with the machine, the
    /// commit, the date and the command line.
    bool html = false;
    /// Scenes of the mesh axis (exact CSG against OpenSCAD's mesh of it, traced by Embree);
    /// measured beside `scenes`, not with --schemes-only. CGAL's time grows as $fn^2 and with the
    /// primitives, so these are small.
    std::vector<std::string> meshScenes{"builtin:lattice:2"};
    /// The $fn of each mesh; empty: 8, 16, 32, 64 (--quick: 8, 16).
    std::vector<int> meshFn;
    double meshTimeout = 120.0;
    ReadOptions read;  ///< --facets: how .csg scenes are read  ///< seconds an openscad run may
                       ///< take before it is stopped
    /// The command line that started the run (for the page), argv[0] first.
    std::vector<std::string> commandLine;
};

/// Create the output directory `dir` (and its parents); false, with an error naming --out on
/// stderr, when it cannot be made.
bool createOutDir(const std::string& dir);

/// Run the sweeps, write OUT/report.csv, OUT/schemes.md (the comparison table, markdown),
/// OUT/*.gp and the plots (OUT/*.png, or with `html` OUT/*.svg and OUT/index.html). Returns the
/// exit status.
int runBench(const BenchOptions& opt);

}  // namespace lancer::bench
