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

/// The outlines of an even-odd region of non-crossing paths: each path (repeated points
/// dropped) turned so that the region lies on its left (outer outlines counter-clockwise, holes
/// clockwise), and the index of the innermost other path that encloses it (-1: none). Paths of
/// fewer than three distinct points are dropped. Returns false, leaving `out` unspecified, when
/// two edges cross, touch or overlap (the region's outline is then not its paths).
struct Outline {
    std::vector<Vec2> points;  ///< the region on the left
    int parent = -1;           ///< the innermost enclosing outline, or -1
    int source = 0;            ///< the index of the input path it came from
};
bool regionOutlines(const std::vector<std::vector<Vec2>>& paths, std::vector<Outline>& out);

/// What OpenSCAD's offset(delta = d) (Clipper's jtMiter with OpenSCAD's miter limit of 10^6, or
/// jtSquare with `chamfer`) adds to a region whose outlines have the region on their left, d > 0:
/// per edge the rectangle of width d outward of it, per convex corner the mitre (the corner of
/// the two edges' lines moved out by d) or, chamfered, the mitre cut square to the corner's
/// bisector at distance d from the corner. The region grown is the region and these convex
/// polygons (Clipper's offset path winds once around each point of that union and of nothing
/// else). Shrinking by d is growing the complement: the outlines reversed give the polygons to
/// take away.
std::vector<std::vector<Vec2>> offsetAdditions(const std::vector<std::vector<Vec2>>& outlines,
                                               double d, bool chamfer);

/// OpenSCAD's GRID_FINE: a circle of smaller radius is cut into 3 segments.
constexpr double kGridFine = 0.00000095367431640625;

/// OpenSCAD 2021.01's get_fragments_from_r (calc.cc): the segments of a full circle of radius
/// r by $fn, $fa, $fs, as a double (a $fn of 1e20 stays one); 5 where it is not finite.
double fragmentsFromR(double r, double fn, double fa, double fs);

}  // namespace lancer::openscad
