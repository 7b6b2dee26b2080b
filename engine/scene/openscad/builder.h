// The OpenSCAD .csg builder: the parsed node tree to primitives, a CSG tree and materials, as
// OpenSCAD models them (modifiers, empty children, argument defaults and precedences).
#pragma once

#include <vector>

#include "engine/scene/openscad/parser.h"
#include "engine/scene/openscad_reader.h"
#include "engine/scene/scene.h"
#include "engine/scene/source_text.h"

namespace lancer::openscad {

/// Add the model of `top` (the file's top-level nodes) to `scene`: its primitives, materials
/// (material 0 becomes OpenSCAD's default colour) and CSG tree, whose root is -1 when the model
/// is empty. Throws SceneError naming file:line:col.
void buildModel(const SourceText& src, const std::vector<Node>& top, Scene& scene,
                OpenScadCounts& counts, const ReadOptions& options = {});

}  // namespace lancer::openscad
