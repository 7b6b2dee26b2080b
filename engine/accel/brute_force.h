// The reference: every primitive, the full tree, for every ray. One region, no mailboxes.
#pragma once

#include "engine/accel/eval.h"

namespace lancer {

class BruteForce {
  public:
    explicit BruteForce(const Scene& scene) : scene_(&scene) {}

    template <class Obs>
    bool intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                   Hit& hit) const {
        ++ctx.counters.regionVisits;
        obs.region(0, tmin, tmax);
        return hitInRegion(*scene_, scene_->tree, scene_->tree.root, ray, tmin, tmin, tmax, ctx,
                           obs, hit);
    }
    size_t regionCount() const { return 1; }
    size_t memoryBytes() const { return 0; }
    bool usesMailboxes() const { return false; }

  private:
    const Scene* scene_;
};

}  // namespace lancer
