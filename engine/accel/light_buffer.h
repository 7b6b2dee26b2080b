// The light buffer: per point light, a conservative depth map of the scene seen from the light,
// which shortens shadow rays (after Haines and Greenberg's light buffer, 1986).
//
// Each light outside the scene's box looks at it along the axis it lies farthest beyond: depth
// d(p) = s (L[a] - p[a]) > 0, image point (u, v) = the other two coordinates relative to the
// light, over d. Every point of a ray from the light has the same image point. The image is cut
// into bins; a bin keeps the least depth of any primitive's (CSG-minimized) box whose image
// meets it (a box's image lies inside the rectangle of its corners' images).
//
// A shadow ray heads for its light, so its depth falls as t grows, and its image point is that
// of its origin o. A blocker at t > 0 lies nearer the light than o, and its box's least depth is
// at most its own depth. So once the ray is nearer the light than its bin's least depth, nothing
// is left to meet: the ray is unblocked from there on, and when o itself is that near, the ray
// is unblocked without a walk. Each approximation (rectangles for images, bins, least depths)
// can only make that point come later, never earlier.
//
// Only the accelerated schemes use it: brute force stays the unaided reference the others are
// checked against.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer {

struct Scene;

class LightBuffer {
  public:
    /// Bins per image axis.
    static constexpr int kBins = 256;

    LightBuffer() = default;
    /// One depth map per light of the (prepared) scene that lies outside its bounds.
    explicit LightBuffer(const Scene& scene, int bins = kBins);
    /// One depth map per point outside `bounds`, of `boxes` (those inside `bounds`; empty
    /// ones are skipped): the scene's lights, or the eye of a perspective camera.
    LightBuffer(const Box3& bounds, const std::vector<Box3>& boxes, const std::vector<Vec3>& points,
                int bins = kBins);

    /// For the shadow ray from `o` along `dir` toward light `light`: the t beyond which nothing
    /// can block it. <= 0: nothing can; +inf: the buffer does not know (the light is inside the
    /// bounds, or `o` outside them).
    double freeFrom(const Vec3& o, const Vec3& dir, uint32_t light) const {
        if (light >= maps_.size()) return kInf;
        const Map& m = maps_[light];
        if (m.near.empty() || !box_.contains(o)) return kInf;
        const double s = m.s;
        const double d = s * (m.L[m.a] - o[m.a]);    // > 0: o is in the box, the light beyond
        const double rate = s * dir[m.a];             // fall of the depth per unit of t
        if (!(rate > 0.0)) return kInf;
        const double u = (o[m.b] - m.L[m.b]) / d, v = (o[m.c] - m.L[m.c]) / d;
        // Past its bin's least depth (widened by the rounding allowance, in t units).
        return (d - m.least(u, v) + hair_) / rate;
    }

    /// For a ray leaving point `point` itself along `dir` (a primary ray from the eye): a t
    /// before which it can meet nothing. 0 when the buffer does not know.
    double nearFrom(const Vec3& dir, uint32_t point) const {
        if (point >= maps_.size()) return 0.0;
        const Map& m = maps_[point];
        const double rate = -m.s * dir[m.a];  // depth gained per unit of t
        if (m.near.empty() || !(rate > 0.0)) return 0.0;
        const double u = dir[m.b] / rate, v = dir[m.c] / rate;
        return std::max(0.0, (m.least(u, v) - hair_) / rate);
    }

    bool empty() const { return maps_.empty(); }
    size_t memoryBytes() const;
    /// Lights with a depth map.
    size_t mappedLights() const;

  private:
    struct Map {
        Vec3 L{0.0};
        int a = 2, b = 0, c = 1;
        double s = 1.0;
        int n = 0;
        double u0 = 0.0, v0 = 0.0, su = 0.0, sv = 0.0;
        std::vector<double> near;  ///< per bin, row by row: the least depth; empty: no map
        // Monotone in x (a difference and a product by a positive constant round monotonically):
        // a point inside a rectangle is in one of the rectangle's bins.
        int index(double x, double origin, double scale) const {
            const double f = (x - origin) * scale;
            return !(f >= 0.0) ? 0 : f >= double(n) ? n - 1 : int(f);
        }
        /// The least depth of the bin holding image point (u, v).
        double least(double u, double v) const {
            return near[size_t(index(v, v0, sv)) * size_t(n) + size_t(index(u, u0, su))];
        }
        void project(const Box3& x, double& dNear, double& u0, double& u1, double& v0,
                     double& v1) const;
    };
    Box3 box_;           ///< the scene bounds, widened by hair_
    double hair_ = 0.0;  ///< rounding allowance, in scene units
    std::vector<Map> maps_;  ///< per scene light
};

}  // namespace lancer
