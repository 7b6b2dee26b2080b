// A scene written as an OpenSCAD model (`lancer export SCENE --scad FILE.scad`, and the report's
// mesh axis): the primitives with their 4x4 transforms and the CSG tree, so that OpenSCAD's CGAL
// render of it is the tessellated mesh an OpenSCAD user would get of the same solid. Curved
// primitives are faceted by OpenSCAD at the file's `$fn` (overridden by `openscad -D '$fn=N'`).
#pragma once

#include <iosfwd>

#include "engine/scene/scene.h"

namespace lancer::bench {

/// Write `scene`'s solid as an OpenSCAD model faceted at `fn` segments a circle. Throws
/// std::invalid_argument for what OpenSCAD cannot model as a solid (an empty tree, a surface:
/// triangles, polygons, open cones), naming the primitive.
void writeScad(std::ostream& out, const Scene& scene, int fn = 32);

}  // namespace lancer::bench
