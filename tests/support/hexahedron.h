// A region's corners as the structure description gives them (a hexahedron with planar faces,
// corner i + 2j + 4k): how far a point lies outside it, measured so that the measure's own
// rounding stays near the corners' rounding whatever the faces' aspect (sliver regions too).
#pragma once

#include <array>
#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer::test {

/// A face plane of a hexahedron: unit normal n, a point fc of the face, and the sign of n
/// toward the outside (0: the hexahedron is flat across it).
struct FacePlane {
    Vec3 n, fc;
    double outward;
};

/// The six face planes of the hexahedron `c` (corner i + 2j + 4k; faces planar). A face that
/// has collapsed to a point or a segment (a projective region's apex at the eye) bounds nothing
/// and is left out.
///
/// A face's normal is the cross product of its two edges at one of its corners (the corner
/// where that product is largest, so a triangle's apex is passed over), not Newell's sum. The
/// camera frame's border slabs are slivers: the structure's box is padded by 2e-9 of the largest
/// coordinate involved and the primitives' boxes by 1e-9, so the first and last slabs of a border
/// zone are about 1e-9 of the coordinates deep (7.2e-9 against a 1.9 x 3.3 face on a random scene
/// of scale 3.6). Newell's
/// normal of a face L long and h thin is half the cross product of its diagonals, two vectors L
/// long at an angle h / L: each world component is a difference of products of size L^2 whose
/// roundings (eps L^2, eps = 1.1e-16) remain in a result of size L h, so the normal tilts by up to
/// about eps L / h in any direction (1.2e-8 along the face's length measured), and at L / 2 from
/// the face's centre a point inside reads up to 2e-8 to 5e-8 outside, over the 1e-9 x scale
/// tolerance. The edge vectors are L and h long, each off by the corners' rounding delta (a few
/// ulps of the corners' coordinates); the long edge's error tilts the normal toward the long edge
/// by delta / L, the thin edge's toward the thin edge by delta / h, and a point within the face's
/// span moves by at most L / 2 and h / 2 along them: the distance is off by about delta, whatever
/// the aspect (1.1e-14 at worst over the border-grazing rays, against 7e-15 by the camera frame's
/// own box tests in long double).
std::vector<FacePlane> facePlanes(const std::array<Vec3, 8>& c);

/// How far `p` lies outside the hexahedron of `c`, 0 inside: the largest distance beyond one
/// of its face planes.
double outside(const std::array<Vec3, 8>& c, const Vec3& p);

/// Distance from `p` to the nearest face plane of the hexahedron of `c`.
double toBoundary(const std::array<Vec3, 8>& c, const Vec3& p);

}  // namespace lancer::test
