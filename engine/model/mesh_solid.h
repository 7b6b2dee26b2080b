// Closed triangle meshes as CSG solids: the mesh checked (closed, not self-intersecting), then
// cut by a solid BSP (Thibault and Naylor, 1987) into convex pieces, each an exact Polytope. The
// solid is the union of the pieces: a ray's spans through it are the parity of its crossings
// with the surface, and every scheme distributes the pieces to its regions like any primitive.
#pragma once

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/model/shapes.h"

namespace lancer {

/// A triangle mesh: points and triangles as indices into them.
struct TriangleMesh {
    std::vector<Vec3> points;
    std::vector<std::array<uint32_t, 3>> triangles;

    /// Merge points with equal coordinates (STL repeats every corner per facet) and drop
    /// triangles that repeat a point.
    void weld();
    /// Add a planar polygon (its points' indices, in order) as triangles (ear clipping in the
    /// plane that its Newell normal is most nearly perpendicular to). False when it has no area.
    bool addPolygon(const std::vector<uint32_t>& loop);
};

/// Why a mesh is not a solid: thrown by meshSolid with a message that names the edge, the
/// triangles or the limit (the caller prefixes the file or node).
struct MeshError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// Bounds on the work a mesh can ask for.
struct MeshLimits {
    size_t maxTriangles = 200000;      ///< triangles read
    size_t maxPieces = 200000;         ///< convex pieces made
    size_t maxFragments = 20000000;    ///< polygon fragments classified over the whole BSP
    uint64_t maxPairTests = 50000000;  ///< triangle pairs the self-intersection check tests
};

/// What the decomposition made, for --stats and the docs.
struct MeshSolid {
    std::vector<Polytope> pieces;  ///< the solid is their union (disjoint interiors)
    size_t triangles = 0;          ///< after welding, of positive area
    size_t bspNodes = 0;           ///< splits made
    size_t fragments = 0;          ///< polygon fragments classified
    uint64_t pairTests = 0;        ///< self-intersection tests done
    bool pairTestsCapped = false;  ///< the self-intersection check stopped at its limit
};

/// The solid bounded by `mesh` (welded, in its own frame). Throws MeshError when the mesh is
/// open (an edge not in exactly two triangles), not orientable, self-intersecting (two triangles
/// that share no point and cross, or two on one edge folded onto each other), or past `limits`.
MeshSolid meshSolid(TriangleMesh mesh, const MeshLimits& limits = {});

/// Whether `p` is inside the closed mesh by the parity of a ray's crossings (for tests and the
/// decomposition's own classification); a ray that meets an edge is cast again elsewhere.
bool meshContains(const TriangleMesh& mesh, const Vec3& p);

}  // namespace lancer
