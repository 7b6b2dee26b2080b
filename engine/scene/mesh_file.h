// Triangle meshes from files: STL (ASCII and binary) and OFF, as OpenSCAD's import() reads them
// and the bench's mesh peer writes them.
#pragma once

#include <string>

#include "engine/model/mesh_solid.h"
#include "engine/scene/source_text.h"

namespace lancer {

/// Whether `path` names a mesh file this reader takes (by extension: .stl or .off, any case).
bool isMeshFile(const std::string& path);

/// The triangles of the STL or OFF file at `path` (OFF polygons cut into triangles), not welded.
/// At most `maxTriangles`; a file that cannot be read or parsed throws SceneError naming its
/// path and line (binary STL: the facet).
TriangleMesh readMeshFile(const std::string& path, size_t maxTriangles = MeshLimits{}.maxTriangles);

/// readMeshFile's parse of text already read: OFF when `off`, else STL.
TriangleMesh readMeshText(const SourceText& src, bool off,
                          size_t maxTriangles = MeshLimits{}.maxTriangles);

}  // namespace lancer
