// OpenSCAD 2021.01's polygons and polyhedra of its round primitives (primitives.cc): the circle's
// polygon, the sphere's rings and the cylinder's two polygons, by get_fragments_from_r, for
// `--facets openscad` and for hull() of curved children.
#pragma once

#include <vector>

#include "engine/geometry/geometry.h"
#include "engine/scene/openscad/region2d.h"

namespace lancer::openscad {

/// $fn, $fa, $fs of a node (OpenSCAD's defaults 0, 12, 2).
struct FragmentRule {
    double fn = 0.0, fa = 12.0, fs = 2.0;
    /// get_fragments_from_r (fragmentsFromR) as a count, at most kMaxFragments.
    int fragments(double r) const;
};

/// The most fragments Lancer makes of one circle ($fn beyond it is refused by the builder).
constexpr int kMaxFragments = 10000;

/// generate_circle: n points on the circle of radius r, point i at 360 i / n degrees.
std::vector<Vec2> circlePolygon(double r, int n);

/// A sphere's polyhedron: `rings` rings of `n` points, ring i at the polar angle
/// 180 (i + 0.5) / rings degrees (radius r sin, height r cos), rings = (n + 1) / 2; the caps are
/// the first and last rings' polygons and the bands between rings are quads.
struct SphereRings {
    int n = 0;
    std::vector<double> radius, z;  ///< per ring, top first
};
SphereRings sphereRings(double r, int n);

/// Every point of a sphere's polyhedron (the rings' points).
std::vector<Vec3> spherePoints(double r, int n);
/// Every point of a cylinder's (or cone's) polyhedron: the circle of r1 at z = 0 and of r2 at
/// z = h, both of `n` points (one apex where a radius is 0).
std::vector<Vec3> cylinderPoints(double r1, double r2, double h, int n);

/// How far a sphere's polyhedron of n fragments strays inside the sphere of radius r: r minus
/// the smallest distance of a face's plane from the centre (every corner lies on the sphere).
double sphereFacetError(double r, int n);

/// The sagitta of n chords of a circle of radius r: r (1 - cos(pi / n)), how far the polygon's
/// edges stray inside the circle.
double sagitta(double r, int n);

/// sin and cos of an angle in degrees, exact at multiples of 90 (OpenSCAD's sin_degrees,
/// cos_degrees).
double sinDegrees(double a);
double cosDegrees(double a);

}  // namespace lancer::openscad
