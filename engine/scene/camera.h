// Pinhole perspective and orthographic cameras (docs/design.md section 6 conventions).
#pragma once

#include <string>

#include "engine/geometry/geometry.h"

namespace lancer {

enum class Projection : uint8_t { Perspective, Orthographic };

struct Camera {
    Vec3 from{0.0, -10.0, 0.0};
    Vec3 at{0.0};
    Vec3 up{0.0, 0.0, 1.0};
    double fov = 45.0;  ///< full vertical field of view, degrees, edge to edge
    Projection projection = Projection::Perspective;
    double orthoHeight = 10.0;  ///< full image height in scene units (orthographic)

    /// docs/design.md section 6: F = normalize(at - from), R = normalize(F x up), U = R x F.
    void basis(Vec3& f, Vec3& r, Vec3& u) const;
    /// Primary ray through the centre of pixel (x, y) of a w x h image, y = 0 on the top row.
    /// The direction is unit length, so t is a distance.
    Ray primaryRay(double x, double y, int w, int h) const;
    /// Empty string when valid, else what is wrong.
    std::string validate() const;
    std::string toJson() const;
};

/// Camera::primaryRay with the basis and the lens factor computed once for a whole image.
class PrimaryRays {
  public:
    PrimaryRays(const Camera& cam, int w, int h);
    /// The ray Camera::primaryRay(x, y, w, h) gives, bit for bit.
    Ray operator()(double x, double y) const;

  private:
    Vec3 from_, f_, r_, u_;
    double half_;  ///< half the image height on the image plane (perspective: at distance 1)
    double w_, h_;
    bool ortho_;
};

}  // namespace lancer
