// The irregular scheme's bounds of primitives as solids of the camera frame (docs/irregular.md,
// "Zones narrowed to each primitive's bound"). A zone is a screen rectangle and its slabs depth
// intervals, but a primitive's camera-frame box is a poor bound of it there: seen from a camera
// off the world's axes a flat world box (a gear's face) is as deep as the whole gear, and in a
// turned scene a bar along a diagonal of the view covers a large screen rectangle. Each
// primitive keeps its minimized world box and, where it has one, a box along axes of its own
// (the turn's, or a flat primitive's plane), as the convex solids they are in the camera frame,
// and a zone asks them two things: does the own box's outline on the screen meet the zone (the
// screen BSP's lists), and what depth range do the boxes together take over the zone's
// footprint (the depth slabs' cuts). The zones stay screen rectangles and the slabs depth
// intervals: only what each lists gets tighter.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "engine/accel/irregular/camera_frame.h"
#include "engine/accel/regular/grid_frame.h"

namespace lancer {

class BuildGuard;  // build_guard.h
struct ScreenBsp;  // screen_bsp.h

/// The rays a screen zone stands for: its rectangle swept along depth in the camera frame
/// (`Parallel`, the camera-frame structure), or the rays from the eye through it, a rectangle
/// of (u, v) = (x/z, y/z) (`FromEye`, the projective zones).
enum class ZoneColumn : uint8_t { Parallel, FromEye };

class PrimitiveHulls {
  public:
    /// The hulls of the primitives `live`: each one's minimized world box and its box along the
    /// turned frame of `turned` (chooseGridFrame) when it has one, else along its own plane for
    /// a triangle or polygon off the world's axes; each widened by `pad` on every side.
    /// `guard` (null: none) is polled for cancellation.
    /// Each hull with two boxes also keeps its faces clipped by the other box (they do not
    /// depend on the zone), within `maxFaceBytes` bytes in all (0: none); the hulls beyond
    /// clip them at each depthIn, to the same ranges.
    static PrimitiveHulls make(const Scene& scene, const CameraFrame& frame,
                               const FrameChoice& turned, const std::vector<uint32_t>& live,
                               double pad, const BuildGuard* guard = nullptr,
                               size_t maxFaceBytes = SIZE_MAX);

    /// Bytes the hulls of `prims` primitives take in a scene of `total` (the build's scratch,
    /// which the memory budget leaves room for before they are made).
    static size_t bytesFor(size_t prims, size_t total) {
        return prims * sizeof(Hull) + total * sizeof(int32_t);
    }
    /// No primitive has a hull: the zones keep their rectangles' lists.
    bool empty() const { return hulls_.empty(); }
    /// Hulls of two boxes whose faces clipped by the other box are kept (make's maxFaceBytes).
    size_t keptFaces() const { return keptFaces_; }
    /// Bytes of the kept faces.
    size_t faceBytes() const { return faceVerts_.capacity() * sizeof(FaceVertex); }
    /// Bytes of the hulls' buffer (one hull a live primitive, reserved once: what bytesFor()
    /// charges the budget for them).
    size_t hullBytes() const { return hulls_.capacity() * sizeof(Hull); }
    /// Primitive p's own box (its world box when it has none), seen along `column`, meets the
    /// screen rectangle [lo, hi] (a primitive without a hull always does; so does one reaching
    /// behind the eye, `FromEye`).
    bool touches(uint32_t p, ZoneColumn column, glm::dvec2 lo, glm::dvec2 hi) const;
    /// The depth range of primitive p's two boxes together within the column over [lo, hi],
    /// at z >= zNear for `FromEye` (lo > hi: they miss it); `whole` (its camera-frame box's
    /// depth range) for a primitive without a hull.
    glm::dvec2 depthIn(uint32_t p, ZoneColumn column, glm::dvec2 lo, glm::dvec2 hi, double zNear,
                       glm::dvec2 whole) const;

    /// A copy whose depthIn computes the column planes' distances by glm::dot, as for hulls with
    /// a corner not finite (tests: the reference of the distances written out).
    PrimitiveHulls withDotPlanes() const {
        PrimitiveHulls h = *this;
        h.finite_ = false;
        return h;
    }

  private:
    /// A box of the camera frame along axes of its own: its eight corners (bit 0 the high
    /// side of the first axis, ..) and its planes, axis[a] . x between lo[a] and hi[a].
    struct Solid {
        std::array<Vec3, 8> corner;
        std::array<Vec3, 3> axis;
        Vec3 lo, hi;
    };
    struct Hull {
        /// The box along its own axes, and the world box; when `single`, `world` holds the
        /// hull's one box: the world box, or its own box where that lies within the world box
        /// (make).
        Solid turned, world;
        bool single = false;  ///< one box: `world` alone (`turned` unused)
        /// `single`, in a frame whose axes are the world's (a light's, lightFrame): the world box
        /// is `box` there, and its outline and depths over a column come in closed form
        /// (alignedDepth) instead of by clipping its faces.
        bool aligned = false;
        Box3 box;
        /// The turned box's outline (`world`'s when `single`), a convex polygon
        /// counterclockwise, along each column (`FromEye`: none when a corner is not in front
        /// of the eye), and its bounding rectangle.
        std::array<glm::dvec2, 8> outline[2];
        int outlineSize[2] = {0, 0};
        glm::dvec2 outlineLo[2], outlineHi[2];
        /// Not `single`: its twelve faces (the world box's six, then the turned box's) clipped by
        /// the other box, at faceVerts_[faceFirst ..], faceSize[f] vertices each (faceFirst
        /// UINT32_MAX: not kept, clipped at each depthIn).
        uint32_t faceFirst = UINT32_MAX;
        std::array<uint8_t, 12> faceSize{};
    };
    /// A vertex of a clipped face: which corner of its box it is (-1: a point clipping made).
    struct FaceVertex {
        Vec3 p;
        int corner;
    };
    /// The depth range of an `aligned` hull's box within the column over [lo, hi] at
    /// z >= zNear (lo > hi: it misses the column).
    static glm::dvec2 alignedDepth(const Box3& b, ZoneColumn column, glm::dvec2 lo, glm::dvec2 hi,
                                   double zNear);

    /// depthIn for a `single` hull (its one box `b`), from its corners' distances to the
    /// column's planes (`dist`, the fifth z = zNear from the eye) and which planes cut it.
    static glm::dvec2 singleBoxDepth(const Solid& b, ZoneColumn column, glm::dvec2 lo,
                                     glm::dvec2 hi, double zNear, const double (&dist)[5][8],
                                     const std::array<bool, 5>& cuts, glm::dvec2 whole);

    std::vector<int32_t> index_;  ///< per primitive: its hull, or -1
    std::vector<Hull> hulls_;
    std::vector<FaceVertex> faceVerts_;  ///< the kept faces' vertices (Hull::faceFirst)
    size_t keptFaces_ = 0;
    /// Every corner is finite: depthIn writes the column planes' distances out (a product by
    /// 0 of an infinite coordinate would be NaN in glm::dot).
    bool finite_ = true;
};

/// Narrows the zones of `bsp` to what the hulls hold: drops from each zone the primitives whose
/// hull misses its column, and gives each remaining reference (bsp.zonePrims' order) its depth
/// range there, padded by `pad` and within the primitive's `box` depths clamped to [zlo, zhi].
/// Empty hulls: every reference keeps its box's depths. `guard` (null: none) is polled for
/// cancellation.
std::vector<glm::dvec2> narrowZones(ScreenBsp& bsp, const PrimitiveHulls& hulls, ZoneColumn column,
                                    const std::vector<Box3>& box, double zlo, double zhi,
                                    double pad, const BuildGuard* guard = nullptr);

}  // namespace lancer
