// surface(): a heightmap (OpenSCAD's .dat text or a PNG image) as the closed mesh OpenSCAD
// 2021.01 makes of it (SurfaceNode::createGeometry), which mesh_solid.h makes a solid.
#pragma once

#include <string>
#include <vector>

#include "engine/model/mesh_solid.h"
#include "engine/scene/source_text.h"

namespace lancer::openscad {

/// Heights on a grid: `rows` lines of `columns` values, row i at y = i, column j at x = j.
struct HeightMap {
    int rows = 0, columns = 0;
    std::vector<double> z;  ///< row-major; values a short .dat line leaves out are 0, as OpenSCAD
    double at(int i, int j) const { return z[size_t(i) * size_t(columns) + size_t(j)]; }
};

/// The most values a heightmap may hold: its mesh (about 4 triangles a value) stays within
/// MeshLimits::maxTriangles.
constexpr size_t kMaxHeightValues = 49000;

/// A heightmap file's grid: a PNG (told by its signature) as OpenSCAD converts it (the height
/// of a pixel is 100/255 of its luminance 0.2126 R + 0.7152 G + 0.0722 B, or with `invert` of 1
/// minus it; the image's top row at the largest y), else OpenSCAD's .dat text (rows of numbers
/// separated by spaces or tabs; blank lines and lines starting with '#' skipped). Throws
/// SceneError naming the file (and for .dat the line and column) when it cannot be read, holds
/// something other than a finite number, or more than kMaxHeightValues values.
HeightMap readHeightMap(const SourceText& file, bool invert);

/// OpenSCAD's closed mesh of a heightmap: over each grid cell, four triangles meeting at the
/// cell's centre at the mean of its corners' heights; vertical walls around the border down to
/// the floor min(0, lowest height - 1); the floor (cut into triangles from its centre). With
/// `center`, the grid is shifted to centre x and y on the origin. Empty when the grid has fewer
/// than two rows or columns (OpenSCAD makes no solid of it).
TriangleMesh heightMapMesh(const HeightMap& map, bool center);

}  // namespace lancer::openscad
