// The visible hit in one region of the irregular scheme, for both of its walks (the camera-frame
// walk of irregular.h, the projective walk of projective_zones.h): a region keeps either its
// primitive list alone (a union-only scene) or a restricted tree, and this is where the two are
// told apart, once.
#pragma once

#include <span>

#include "engine/accel/eval.h"

namespace lancer {

/// The visible hit of a region the ray crosses on [t0, t1] (after tmin), ctx.beginLeafWalk()
/// called at the walk's start. `prims` are the region's primitives; `root` its restricted tree
/// in `pool` (-1: an empty region, or, `unionOnly`, none: the scene is union-only and hitInLeaf
/// takes the first start among the listed primitives' held spans, merging them only when the
/// ray starts the window inside a stretch of their union). Both go through hitInLeaf's pending
/// boundaries: a region where no boundary of a primitive this walk has tested lies in the window
/// holds no hit and is left in one comparison, its tree not evaluated. The irregular walk crosses
/// many thin regions whose primitives an earlier region tested, so most are left that way (docs/
/// irregular.md, "One region test for both walks"). `tests`: the primitives to fetch
/// (hitInLeaf's `tests`; none: `prims`), the entering list of a slab the walk stepped into
/// from the slab before it in depth. `lazy`: a CSG region with a primitive not yet fetched by
/// this walk evaluates its tree lazily (hitInLeaf's lazyTree), testing only what the tree needs,
/// instead of fetching all for the pending check. The camera-frame walk crosses from zone to
/// zone into regions whose lists differ, where that saves tests (the turned sponge in the camera
/// frame: 44% more without it); the projective walk steps along one zone's slabs, each adding a
/// few primitives, where fetching them lets most slabs be left without evaluating their tree
/// (docs/irregular.md, "Eager slabs"). The regular walk's path for union-only
/// leaves (hitInUnionLeaf, which scans the held spans of every listed primitive in every
/// region) costs more here for the same reason.
template <class Obs>
[[gnu::always_inline]] inline bool hitInIrregularRegion(
    const Scene& scene, bool unionOnly, std::span<const uint32_t> prims, const CsgTree& pool,
    int root, const Ray& ray, double tmin, double t0, double t1, TraceContext& ctx, Obs& obs,
    Hit& hit, bool lazy, std::optional<std::span<const uint32_t>> tests = {}) {
    if (unionOnly)
        return hitInLeaf(scene, nullptr, -1, prims.data(), uint32_t(prims.size()), ray, tmin, t0,
                         t1, ctx, obs, hit, false, tests);
    return hitInLeaf(scene, &pool, root, prims.data(), uint32_t(prims.size()), ray, tmin, t0, t1,
                     ctx, obs, hit, false, tests, lazy);
}

}  // namespace lancer
