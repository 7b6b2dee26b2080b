// OpenSCAD's CSG export (`openscad -o model.csg model.scad`): the tree of group, boolean,
// multmatrix, color and primitive nodes that OpenSCAD writes, in OpenSCAD syntax.
#pragma once

#include <string>
#include <vector>

#include "engine/scene/scene.h"
#include "engine/scene/source_text.h"

namespace lancer {

/// What a .csg file held, for tests and messages.
struct OpenScadCounts {
    int cubes = 0, spheres = 0, cylinders = 0, cones = 0;  ///< primitives modelled
    int tori = 0;        ///< tori modelled (rotate_extrude of a circle off the axis)
    int operators = 0;   ///< union/group/render, intersection, difference nodes read
    int transforms = 0;  ///< multmatrix/translate/rotate/scale/mirror nodes read
    int colors = 0;
    int leftOut = 0;  ///< subtrees dropped by the `*` or `%` modifier (or outside a `!` root)
    int empty = 0;    ///< zero-size primitives (OpenSCAD makes nothing of them)
    int squares = 0, circles = 0, polygons = 0;  ///< 2D nodes read inside extrusions
    int linearExtrudes = 0, rotateExtrudes = 0;  ///< extrusions modelled
    int polytopes = 0;        ///< convex polytopes made (extruded pieces, partial-sweep wedges)
    int polyhedra = 0;        ///< convex polyhedra modelled
    int hulls = 0;            ///< hull() nodes modelled
    int leftOut2D = 0;        ///< 2D nodes beside solids, not part of the solid model (as OpenSCAD)
    int dxfImports = 0;       ///< import() nodes of DXF drawings read
    int dxfOpenChains = 0;    ///< open paths among them, closed by their ends (as OpenSCAD)
    int meshes = 0;           ///< closed meshes (non-convex polyhedra, STL/OFF imports) modelled
    int meshPieces = 0;       ///< the convex pieces they were cut into (mesh_solid.h)
    int surfaces = 0;         ///< surface() heightmaps modelled (as closed meshes)
    int twistedExtrudes = 0;  ///< linear_extrude nodes with a twist, cut into slices
    int twistSlices = 0;      ///< OpenSCAD's slices for them, summed
    int twistSubSlices = 0;   ///< the most parts a slice of theirs is cut into
    /// The largest distance (model units) between a twisted extrusion's exact surface and its
    /// slices' walls, over all of them; 0 when nothing is twisted.
    double twistError = 0.0;
    /// The largest distance (model units) between a twisted extrusion's exact surface and
    /// OpenSCAD's own mesh of it (its walls triangulated between OpenSCAD's slices, circles as
    /// their polygons), beyond the facets' sagitta; for comparisons with that mesh.
    double openScadTwistMeshError = 0.0;
    int facetedShapes = 0;  ///< circles, spheres, cylinders, cones built as OpenSCAD's facets
    /// The largest sagitta (model units) of the facets of curved shapes modelled by them (with
    /// --facets openscad, and hull() of curved children): how far they stray inside the exact
    /// surface; 0 when none is.
    double facetError = 0.0;
};

/// Nodes the reader models exactly; every other node is refused naming the node and position.
const std::vector<std::string>& openScadSupportedNodes();

/// Read a .csg text. `camera` (optional) is the sidecar NAME.camera.json; without it the camera
/// is framed on the bounds from OpenSCAD's default view direction, with the default light rig.
/// Throws SceneError naming file, line and column.
/// `options.facets` OpenScad builds circles, spheres, cylinders and cones as OpenSCAD's polygons
/// and polyhedra (docs/scenes.md, "OpenSCAD's facets").
Scene readOpenScad(const SourceText& src, const SourceText* camera = nullptr,
                   OpenScadCounts* counts = nullptr, const ReadOptions& options = {});

/// Read `path` and, when it exists, its sidecar (path without ".csg" + ".camera.json").
Scene readOpenScadFile(const std::string& path, OpenScadCounts* counts = nullptr,
                       const ReadOptions& options = {});

/// The sidecar path of a .csg path: "dir/NAME.csg" -> "dir/NAME.camera.json".
std::string openScadCameraPath(const std::string& csgPath);

}  // namespace lancer
