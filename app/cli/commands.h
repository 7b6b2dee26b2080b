// The subcommands of `lancer`.
#pragma once

#include <string>

#include "app/cli/options.h"

namespace lancer::cli {

/// Load, build, render and write the outputs. Returns the process exit status.
int runRender(const CommonOptions& o, const std::string& outPath, bool quiet);

struct TraceOptions {
    int x = 0, y = 0;
    bool json = false;
    bool shadows = false;  ///< also walk the primary hit's shadow rays
};
int runTrace(const CommonOptions& o, const TraceOptions& t);

struct StructureOptions {
    std::string output;  ///< -o FILE.json
    bool all = false;    ///< list every region even over the summary limit
    bool quiet = false;
};
/// Build the structure and write its dump (docs/design.md section 6, "Structure dump").
int runStructure(const CommonOptions& o, const StructureOptions& s);

struct ExportOptions {
    std::string pov;     ///< --pov FILE.pov
    std::string scad;    ///< --scad FILE.scad
    int fn = 32;         ///< --fn: the OpenSCAD model's $fn
    bool depth = false;  ///< --pov-depth: surfaces emit their distance (a depth image)
    bool quiet = false;
};
/// Write the scene for POV-Ray 3.7 with the same camera, and/or as an OpenSCAD model
/// (docs/design.md section 6, "Export and report").
int runExport(const CommonOptions& o, const ExportOptions& e);

}  // namespace lancer::cli
