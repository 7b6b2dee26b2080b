// The frame a regular grid is built in (docs/regular.md, "Turned scenes"). Axis-aligned cells
// cannot separate primitives turned off the world's axes: once OpenSCAD's example024 turns its
// Menger sponge so a diagonal stands up, every bar's world box spans much of the cube and the
// cost model keeps one region. Built along the turned subtree's own axes instead, the bars are
// thin boxes again. The walk maps the ray into the frame once (a rotation keeps t), walks the
// cells there and tests the primitives with the world ray, so only the cells move.
#pragma once

#include <vector>

#include "engine/scene/scene.h"

namespace lancer {

/// Surface area of a box: the surface area heuristic's measure of the rays that cross it.
inline double surfaceArea(const Box3& b) {
    const Vec3 e = b.extent();
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

/// Corner `c` of a box: bit 0 the high x, bit 1 the high y, bit 2 the high z (the order of
/// StructureView::regionCorners).
inline Vec3 boxCorner(const Box3& b, int c) {
    return {c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z};
}

/// An orthonormal frame: the world's axes, or those of a turned subtree.
struct GridFrame {
    Mat3 axes{1.0};       ///< columns: the frame's x, y, z axes in world coordinates
    Mat3 toFrameM{1.0};   ///< the transpose of `axes`: world to frame
    bool turned = false;  ///< false: the world's own axes, and nothing is mapped

    /// The frame whose axes are the columns of `m` (orthonormal).
    static GridFrame fromAxes(const Mat3& m);
    /// A world point or vector in frame coordinates (the identity when not turned).
    Vec3 toFrame(const Vec3& w) const { return turned ? toFrameM * w : w; }
    /// A frame point or vector in world coordinates.
    Vec3 toWorld(const Vec3& f) const { return turned ? axes * f : f; }
    /// The ray in frame coordinates: the same t gives the same point.
    Ray toFrame(const Ray& r) const { return {toFrame(r.o), toFrame(r.d)}; }
};

/// What chooseGridFrame found: the frame, the primitives' minimized boxes in it and the
/// figures the choice rests on.
struct FrameChoice {
    GridFrame frame;
    /// Per primitive, its minimized box in the frame (empty: dropped); empty when not turned,
    /// the scene's minBox then being the frame's boxes.
    std::vector<Box3> boxes;
    Box3 bounds = Box3::empty();  ///< the boxes' hull, the grid's box in the frame
    double worldArea = 0.0;       ///< total surface area of the scene's minimized boxes
    double frameArea = 0.0;       ///< the same for the chosen frame (worldArea when not turned)
    int candidates = 0;           ///< distinct turned frames found among the transforms
};

/// A turned frame is chosen when its boxes' total area is below this share of the world's.
inline constexpr double kTurnedAreaShare = 0.5;
/// Turned frames scored at most (the most frequent among the primitives' transforms, each the
/// rotation of 1% of the live primitives at least).
inline constexpr int kMaxFrameCandidates = 8;

/// The frame of least total minimized-box surface area (the surface area heuristic's cost of a
/// ray crossing every primitive's box), among the world's axes and the rotations of the
/// primitives' transforms (each orthonormalized; frames equal up to the order and sign of their
/// axes are one), chosen over the world's only below kTurnedAreaShare of its area. Its cost: a
/// pass over the transforms, and one minimization of the boxes per frame scored.
FrameChoice chooseGridFrame(const Scene& scene);

/// A primitive's box in `frame`: its shape's bounds (vertices for triangles and polygons, the
/// centre and radius for a sphere) mapped into the frame, widened by `hair` on every side.
Box3 frameBoxOf(const Primitive& p, const GridFrame& frame, double hair);

}  // namespace lancer
