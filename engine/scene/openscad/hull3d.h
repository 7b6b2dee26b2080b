// Convex hulls of small point sets in 3D, for OpenSCAD's hull(): the hull's dimension, its
// extreme points, faces (with their planes) and edges, from which the builder makes exact solids
// (a polytope, and for a hull of spheres the hull of their centres grown by their radius).
#pragma once

#include <utility>
#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer::openscad {

/// Hulls of more points than this are refused (gift wrapping takes points times edges).
constexpr size_t kMaxHullPoints = 20000;

/// The convex hull of a point set.
struct ConvexHull3 {
    int dim = -1;                ///< -1 no points, 0 a point, 1 a segment, 2 a polygon, 3 a solid
    std::vector<Vec3> vertices;  ///< the extreme points (dim 0: one, dim 1: both ends)
    std::vector<glm::dvec4> planes;          ///< per face: outward unit normal and offset
    std::vector<std::vector<int>> faces;     ///< per face: vertices, counter-clockwise about it
    std::vector<std::pair<int, int>> edges;  ///< each edge once (dim >= 1)
};

/// The hull of `pts` (at most kMaxHullPoints distinct points). Points closer than a relative
/// 1e-9 of the coordinates' magnitude to a face's plane count as on it. A flat set (dim 2) has
/// one face, its plane's normal chosen by the first three points that span it.
ConvexHull3 convexHull3(std::vector<Vec3> pts);

}  // namespace lancer::openscad
