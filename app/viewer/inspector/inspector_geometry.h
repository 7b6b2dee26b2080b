// The inspector's geometry, pure (no GL): where a camera's frustum and image plane lie, the
// inspector camera's matrices and projection, which regions the level range and the slice slab
// keep, their colours, and the pick ray against them. The GL drawing and the tests read these.
#pragma once

#include <array>
#include <cstdint>
#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <optional>
#include <vector>

#include "engine/scene/camera.h"

namespace lancer::viewer::inspector {

/// A region's volume: 8 world-space corners, corner c = i + 2j + 4k with i, j, k the low (0)
/// or high (1) side along the region's own three axes (the trace contract's order).
using Corners = std::array<Vec3, 8>;

/// The 12 edges of a Corners volume, as pairs of corner numbers.
const std::array<std::array<int, 2>, 12>& cornerEdges();
/// The corners in single precision, as gl::Batch::box takes them.
std::array<glm::vec3, 8> toFloat(const Corners& c);
/// The corners of an axis-aligned box, in that order.
Corners boxCorners(const Box3& b);
/// The axis-aligned box around the corners.
Box3 cornersBox(const Corners& c);

/// The world point of continuous image coordinates (x right from the left edge, y down from
/// the top edge, pixel (i, j) covering [i, i+1] x [j, j+1]) of a w x h image of `cam`, at
/// depth `depth` along the camera's forward axis F (perspective: from the eye; orthographic:
/// from the plane through `from`). Pixel centres give points of Camera::primaryRay.
Vec3 imagePoint(const Camera& cam, int w, int h, double x, double y, double depth);
/// The frustum of a w x h image of `cam` between depths `near` and `far` along F: corner
/// c = i + 2j + 4k with i = 1 on the right edge, j = 1 on the top edge, k = 1 at `far`. An
/// orthographic camera's is a box.
Corners frustumCorners(const Camera& cam, int w, int h, double near, double far);
/// The image plane of a w x h image of `cam`: its corners at image (0, 0), (w, 0), (w, h),
/// (0, h), at depth |at - from| (perspective: the plane of `at`, where the view is framed) or 0
/// (orthographic: the plane the rays start on).
std::array<Vec3, 4> imagePlane(const Camera& cam, int w, int h);

/// Depth of a point along the camera's forward axis (as imagePoint's `depth`).
double cameraDepth(const Camera& cam, const Vec3& p);

/// Near and far depths that hold every point of `b` in view of `cam`, with a margin; near
/// stays positive for a perspective camera (a small fraction of far when the box holds the eye).
void depthRange(const Camera& cam, const Box3& b, double& near, double& far);
/// The window depth in [0, 1] that gl::worldToClip(cam, w, h, near, far) gives a point at
/// depth `depth` along F (shaders/inspector_surface.frag computes the same).
float windowDepth(const Camera& cam, double near, double far, double depth);

/// Frame `box` in a camera looking along `forward` (up +z unless forward is vertical): its
/// whole bounding sphere in view of a perspective camera with a `fov`-degree vertical field
/// and a w / h image `aspect` (a narrow image narrows the horizontal field).
Camera frameBox(const Box3& box, const Vec3& forward, double fov, double aspect = 1.0);
/// Camera `c` moved to frame `box` (the F key): the same direction, up, field and projection,
/// aimed at the box's centre from where its bounding sphere just fills the narrower field of
/// a w / h image `aspect` (orthographic: the image height made the sphere's diameter).
Camera framedOn(const Camera& c, const Box3& box, double aspect);

/// What the inspector draws a regular leaf (or any region) with, for filtering and colouring.
struct RegionView {
    Corners corners;
    uint32_t id = 0;     ///< region number in its structure
    int level = 0;       ///< depth in its tree (regular: BSP level); 0 when it has none
    uint32_t prims = 0;  ///< primitives listed in the region
};

/// The level range keeps regions with lo <= level <= hi.
inline bool inLevelRange(int level, int lo, int hi) { return level >= lo && level <= hi; }
/// An axis-aligned slice slab [lo, hi] across `axis` (0 x, 1 y, 2 z) keeps the regions whose
/// volume crosses it (closed: a region touching the slab is kept), whole.
struct Slab {
    bool on = false;
    int axis = 0;
    double lo = 0.0, hi = 0.0;
    bool keeps(const Corners& c) const;
    bool operator==(const Slab&) const = default;
};

/// What colours a region.
enum class ColorBy : uint8_t { Prims, Level };
const char* colorByName(ColorBy c);
/// The colour of a region whose value is `v`: by level, the overlays' fixed level palette
/// (levelColor); by primitives, their fixed log scale of counts (countColor). The same colour
/// means the same value in every build, and the image's key reads for the inspector too.
glm::vec3 regionColor(double v, ColorBy by);

/// Distance along the ray (o, d) to where it enters the convex volume of `c` (0 when o is
/// inside); nullopt when it misses. The faces of `c` must be planar (boxes, boxes of the camera
/// frame, pieces of projective zones).
std::optional<double> rayEnters(const Ray& ray, const Corners& c);
/// The region the pick ray meets first among `regions` (by its entry distance; inside several,
/// the smallest volume), or -1. `candidates` lists the indices to consider (all when empty).
int pickRegion(const Ray& ray, const std::vector<RegionView>& regions,
               const std::vector<uint32_t>& candidates = {});

}  // namespace lancer::viewer::inspector
