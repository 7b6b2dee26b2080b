// The visible hit in one region of the irregular scheme, for both of its walks (the camera-frame
// walk of irregular.h, the projective walk of projective_zones.h): a region keeps either its
// primitive list alone (a union-only scene) or a restricted tree, and this is where the two are
// told apart, once.
#pragma once

#include <span>

#include "engine/accel/eval.h"

namespace lancer {

/// The visible hit of a region the ray crosses on [t0, t1] (after tmin), ctx.beginLeafWalk()
/// called at the walk's start when `flat`. `flat`: the region keeps its primitives `prims`
/// alone, their union (a union-only scene), and hitInLeaf merges their spans when a boundary of
/// theirs lies in the window. The regular walk's path for union-only leaves (hitInUnionLeaf,
/// which scans the held spans of every listed primitive in every region) costs more here: the
/// irregular walk visits many thin regions whose primitives are already held, which the pending
/// boundaries skip in one comparison (docs/irregular.md, "One region test for both walks").
/// Otherwise `root` is its restricted tree in `pool` (-1: an empty region); `lastRoot` is the
/// tree a region before it on this walk evaluated last, whose spans along the whole line are
/// still in ctx.result, so a region sharing it only reads them on its own interval (the walk
/// starts it at -1).
template <class Obs>
[[gnu::always_inline]] inline bool hitInIrregularRegion(const Scene& scene, bool flat,
                                                        std::span<const uint32_t> prims,
                                                        const CsgTree& pool, int root,
                                                        int& lastRoot, const Ray& ray, double tmin,
                                                        double t0, double t1, TraceContext& ctx,
                                                        Obs& obs, Hit& hit) {
    if (flat) {
        return hitInLeaf(scene, nullptr, -1, prims.data(), uint32_t(prims.size()), ray, tmin, t0,
                         t1, ctx, obs, hit);
    }
    if (root < 0) return false;
    if (root != lastRoot) {
        if (hitInRegion(scene, pool, root, ray, tmin, t0, t1, ctx, obs, hit)) return true;
        lastRoot = root;
        return false;
    }
    // The same tree as the region before (a shared restriction): only the interval changed.
    if constexpr (Obs::kActive) obs.regionSpans(ctx.result);
    if (const Boundary* b = firstBoundary(ctx.result, tmin, t0, t1)) {
        hit = {b->t, b->prim, b->part, b->flip};
        return true;
    }
    return false;
}

}  // namespace lancer
