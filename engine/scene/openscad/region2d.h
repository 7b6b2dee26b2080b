// OpenSCAD's 2D regions as convex pieces: a polygon's paths (even-odd) cut into convex polygons,
// each kept as the half-planes of its edges so that extrusions make exact planes from them.
#pragma once

#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer::openscad {

using Vec2 = glm::dvec2;

/// The half-plane a x + b y <= c.
struct HalfPlane {
    double a = 0.0, b = 0.0, c = 0.0;
};

/// A convex polygon: the half-planes that bound it and its vertices (counter-clockwise).
struct ConvexPiece {
    std::vector<HalfPlane> sides;
    std::vector<Vec2> vertices;
};

/// The half-plane left of the line p -> q, computed from p and q in lexicographic order, so that
/// the two pieces on either side of a shared edge get bit-for-bit opposite half-planes (their
/// walls then meet exactly: a union merges their spans, a difference leaves no sliver).
HalfPlane leftOf(const Vec2& p, const Vec2& q);

/// Convex polygons with at most this many sides stay whole; larger ones are cut (a polytope's
/// part number is one byte).
constexpr size_t kMaxPieceSides = 250;

/// The even-odd region of `paths` (closed; repeated points and paths of fewer than three
/// distinct points are dropped) as disjoint convex pieces. One simple convex path is one piece;
/// anything else (non-convex, holes, crossing paths) is cut into trapezoids between the
/// x-coordinates of the vertices and crossings, merged along each pair of edges.
std::vector<ConvexPiece> convexPieces(const std::vector<std::vector<Vec2>>& paths);

/// OpenSCAD's GRID_FINE: a circle of smaller radius is cut into 3 segments.
constexpr double kGridFine = 0.00000095367431640625;

/// OpenSCAD 2021.01's get_fragments_from_r (calc.cc): the segments of a full circle of radius
/// r by $fn, $fa, $fs, as a double (a $fn of 1e20 stays one); 5 where it is not finite.
double fragmentsFromR(double r, double fn, double fa, double fs);

}  // namespace lancer::openscad
