// The reference: every primitive, the full tree, for every ray. One region, no mailboxes.
#pragma once

#include <nlohmann/json.hpp>

#include "engine/accel/build_params.h"
#include "engine/accel/eval.h"

namespace lancer {

/// Brute force has no knobs; its empty config gives every scheme the same build shape.
struct BruteConfig {};

class BuildGuard;  // engine/accel/build_guard.h

class BruteForce {
  public:
    static constexpr SchemeKind kKind = SchemeKind::Brute;  ///< its row of kSchemeTable
    /// Its knobs in `p`: none.
    static BruteConfig config(const BuildParams& /*p*/) { return {}; }

    explicit BruteForce(const Scene& scene) : scene_(&scene) {}
    /// The scheme's build, in the shape every scheme has: nothing to build, nothing to report.
    static BruteForce build(const Scene& scene, const BruteConfig&, nlohmann::json& /*extra*/,
                            BuildGuard* /*guard*/ = nullptr) {
        return BruteForce(scene);
    }

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
