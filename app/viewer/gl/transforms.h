// Matrices that put batches where the tracer's pixels are: image pixels to clip space, and a
// camera's world-to-clip (the primary ray through a pixel's centre and a world point on it land
// on the same pixel). Plain math, no GL calls.
#pragma once

#include <glm/glm.hpp>
#include <optional>

#include "engine/scene/camera.h"

namespace lancer::viewer::gl {

/// Continuous image coordinates of a width x height image (x to the right from the left edge,
/// y down from the top edge, pixel (i, j) covering [i, i+1] x [j, j+1]) to clip space, the image
/// filling the viewport.
glm::mat4 imagePixelsToClip(float width, float height);

/// The camera's world-to-clip matrix for a width x height image filling the viewport: the
/// tracer's projection (DESIGN.md section 6, perspective or orthographic). `nearDepth` and
/// `farDepth` bound the drawn depths along the forward axis (perspective: nearDepth > 0).
glm::mat4 worldToClip(const Camera& camera, int width, int height, double nearDepth,
                      double farDepth);

/// A world point's place in the image, for picking and culling on the CPU in double precision.
class ImageProjector {
  public:
    ImageProjector(const Camera& camera, int width, int height);
    /// Continuous image coordinates of p, or nothing when p is not in front of the camera
    /// (perspective: depth <= 0).
    std::optional<glm::dvec2> toImage(const Vec3& p) const;
    /// p's depth along the forward axis F (from the eye, or the plane through `from`).
    double depth(const Vec3& p) const { return glm::dot(p - from_, f_); }

  private:
    Vec3 from_, f_, r_, u_;
    double half_, w_, h_;
    bool ortho_;
};

}  // namespace lancer::viewer::gl
