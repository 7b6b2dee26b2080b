// Pinhole perspective and orthographic cameras (docs/design.md section 6 conventions).
#pragma once

#include <string>
#include <vector>

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
    /// The ray through the centre of pixel (x, y), 0 <= x < w, 0 <= y < h: operator()(x, y)
    /// bit for bit, from the column's and the row's terms computed once.
    Ray pixel(int x, int y) const { return through(column_[size_t(x)] + row_[size_t(y)]); }

  private:
    friend struct Camera;  // primaryRay: one ray, no terms
    /// The rays of a w x h image, with the terms of pixel() for `columns` x `rows` pixels.
    PrimaryRays(const Camera& cam, int columns, int rows, int w, int h);

    /// The sum's terms of a pixel's column x and row y (the per-pixel rays' tables hold them).
    Vec3 columnTerm(double x) const;
    Vec3 rowTerm(double y) const;
    /// The ray whose sum of terms is `s`: from `s` along f (orthographic), or from the eye
    /// towards it (perspective, f at distance 1).
    Ray through(const Vec3& s) const { return ortho_ ? Ray{s, f_} : Ray{from_, glm::normalize(s)}; }

    Vec3 from_, f_, r_, u_;
    double half_;  ///< half the image height on the image plane (perspective: at distance 1)
    double w_, h_;
    bool ortho_;
    /// columnTerm and rowTerm of every column and row, made once: a render spent a third of its
    /// time outside the walk, much of it in these divisions per pixel.
    std::vector<Vec3> column_, row_;
};

}  // namespace lancer
