// Embree 3 as a peer in the report: on union-only scenes (every SPD scene), the nearest hit of
// the union is Embree's closest hit for rays from outside the solids, so primary rays and one
// shadow ray per light (our `--bounces 0` workload) can be traced by both and compared.
#pragma once

#include <memory>

#include "engine/render/renderer.h"

namespace lancer::bench {

class EmbreePeer {
  public:
    /// True when this build has Embree.
    static bool available();
    /// True when the scene is a union of primitives (no intersection or difference).
    static bool supports(const Scene& scene);

    /// Build Embree's BVH: spheres as sphere points, triangles and convex polygons as
    /// triangles, everything else (cones, transformed solids, non-convex polygons) as user
    /// geometry calling Lancer's exact intersection.
    explicit EmbreePeer(const Scene& scene);
    ~EmbreePeer();
    double buildMs() const { return buildMs_; }

    /// Primary rays and shadow rays (one per light the surface faces); Lambert shading.
    RenderStats render(const RenderOptions& opt, Image& img) const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    double buildMs_ = 0.0;
};

}  // namespace lancer::bench
