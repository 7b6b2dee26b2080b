// Ray casting a CSG tree (Roth): primitive spans (through the mailboxes), combined by the
// tree's operators; and the visible hit inside one region's ray interval. Every scheme uses
// these two functions, so brute force and subdivisions differ only in which tree and interval.
#pragma once

#include <algorithm>
#include <cassert>
#include <optional>
#include <span>
#include <vector>

#include "engine/accel/observer.h"
#include "engine/accel/trace_context.h"
#include "engine/scene/scene.h"

namespace lancer {

/// The primitive's mailbox holding its spans for the current ray id: filled by a test (counted
/// as one) unless this ray id already filled it (counted as a mailbox hit). `fresh` says which.
template <class Obs>
[[gnu::always_inline]] inline const Mailbox& mailboxSpans(const Scene& scene, uint32_t p,
                                                          const Ray& ray, TraceContext& ctx,
                                                          Obs& obs, bool* fresh = nullptr) {
    if (const Mailbox* held = ctx.heldMailbox(p)) {
        ++ctx.counters.mailboxHits;
        obs.mailboxHit(p);
        if (fresh) *fresh = false;
        return *held;
    }
    Span spans[2];
    const int n = scene.primSpans(p, ray, spans, ctx.precision);
    ++ctx.counters.primTests;
    obs.primTest(p, spans, n);
    if (fresh) *fresh = true;
    if (n == 0) {  // a miss, most tests: no mailbox of its own
        ctx.heldEmpty(p);
        return ctx.held[0];
    }
    Mailbox& m = ctx.takeMailbox(p);
    m.count = uint8_t(n);
    std::copy_n(spans, n, m.spans);
    return m;
}

/// Spans of the primitive for the current ray, from its mailbox when this ray already tested it.
template <class Obs>
inline int primitiveSpans(const Scene& scene, uint32_t p, const Ray& ray, TraceContext& ctx,
                          Obs& obs, const Span*& out, Span* local) {
    if (ctx.useMailboxes) {
        const Mailbox& m = mailboxSpans(scene, p, ray, ctx, obs);
        out = m.spans;
        return m.count;
    }
    int n = scene.primSpans(p, ray, local, ctx.precision);
    ++ctx.counters.primTests;
    obs.primTest(p, local, n);
    out = local;
    return n;
}

/// A window [t0, t1] from boxes widened by floatSlack (--precision float), kept within
/// [lo, hi]: a BVH leaf whose box is its primitives' boxes, or a light-buffer stretch, would
/// otherwise lose a hit on a face that bounds a box when the float t rounds to just outside it.
inline void widenForFloat(const Ray& ray, double& t0, double& t1, double lo = -kInf,
                          double hi = kInf) {
    t0 = std::max(lo, t0 - floatSlack(ray, t0));
    t1 = std::min(hi, t1 + floatSlack(ray, t1));
}

/// How evalTree fetches a primitive's spans: through primitiveSpans (tested or taken from the
/// mailbox, counted), or straight from the mailbox that hitInLeaf has just filled (not counted).
enum class Fetch : uint8_t { Counted, Fresh };

/// Spans of `tree` from `node` along the whole line of `ray`, into `out`.
template <class Obs, Fetch F = Fetch::Counted>
void evalTree(const Scene& scene, const CsgTree& tree, int node, const Ray& ray, TraceContext& ctx,
              Obs& obs, size_t level, SpanList& out) {
    const CsgNode& x = tree.nodes[node];
    if (x.op == Op::Primitive) {
        if constexpr (F == Fetch::Fresh) {
            const Mailbox* m = ctx.heldMailbox(x.prim);
            assert(m);
            out.assign(m->spans, m->spans + m->count);
        } else {
            Span local[2];
            const Span* s;
            int n = primitiveSpans(scene, x.prim, ray, ctx, obs, s, local);
            out.assign(s, s + n);
        }
        if constexpr (Obs::kActive) obs.csgNode(node, out);
        return;
    }
    // Sized by TraceContext::reset from the tree depth: never resized here, since parents hold
    // references into it.
    assert(ctx.scratch.size() >= 2 * level + 2);
    SpanList& a = ctx.scratch[2 * level];
    SpanList& b = ctx.scratch[2 * level + 1];
    evalTree<Obs, F>(scene, tree, x.left, ray, ctx, obs, level + 1, a);
    if (a.empty() && x.op != Op::Union) {  // nothing to intersect or to cut from
        out.clear();
        if constexpr (Obs::kActive) obs.csgNode(node, out);
        return;
    }
    evalTree<Obs, F>(scene, tree, x.right, ray, ctx, obs, level + 1, b);
    switch (x.op) {
        case Op::Union:
            spanUnion(a, b, out);
            break;
        case Op::Intersection:
            spanIntersection(a, b, out);
            break;
        case Op::Difference:
            spanDifference(a, b, out);
            break;
        case Op::Primitive:
            break;
    }
    if constexpr (Obs::kActive) obs.csgNode(node, out);
}

/// The visible hit of `tree` inside a region the ray crosses on [t0, t1]: the first span
/// boundary with t in [t0, t1] and t > tmin. The restricted tree agrees with the full tree only
/// inside the region, so boundaries outside it are ignored.
template <class Obs>
bool hitInRegion(const Scene& scene, const CsgTree& tree, int root, const Ray& ray, double tmin,
                 double t0, double t1, TraceContext& ctx, Obs& obs, Hit& hit) {
    if (root < 0) return false;
    evalTree(scene, tree, root, ray, ctx, obs, 0, ctx.result);
    if constexpr (Obs::kActive) obs.regionSpans(ctx.result);
    const Boundary* b = firstBoundary(ctx.result, tmin, t0, t1);
    if (b) hit = {b->t, b->prim, b->part, b->flip};
    return b != nullptr;
}

/// The union of the spans in `spans` (each primitive's sorted and disjoint), sorted and merged
/// into `out` as spanUnion merges them: the spans of a tree of unions over those primitives. The
/// boundary kept where two coincide exactly may be another primitive's than the tree's.
inline void flatUnion(SpanList& spans, SpanList& out) {
    if (spans.size() > 16) {
        std::stable_sort(spans.begin(), spans.end(),
                         [](const Span& a, const Span& b) { return a.in.t < b.in.t; });
    } else {
        for (size_t i = 1; i < spans.size(); ++i) {  // insertion sort: a few spans at most
            const Span s = spans[i];
            size_t j = i;
            for (; j > 0 && spans[j - 1].in.t > s.in.t; --j) spans[j] = spans[j - 1];
            spans[j] = s;
        }
    }
    out.clear();
    for (const Span& s : spans) {
        if (!out.empty() && s.in.t <= out.back().out.t) {
            if (s.out.t > out.back().out.t) out.back().out = s.out;
        } else {
            out.push_back(s);
        }
    }
}

/// The union of the spans held in the mailboxes of `keys` (filled by this walk; none for a
/// sphere the quads rejected) into ctx.result: a union-only region's spans without its tree.
inline void mergeHeldSpans(const uint32_t* keys, uint32_t count, TraceContext& ctx) {
    SpanList& spans = ctx.leafSpans;
    spans.clear();
    for (uint32_t i = 0; i < count; ++i) {
        if (const Mailbox* m = ctx.heldMailbox(keys[i]))
            spans.insert(spans.end(), m->spans, m->spans + m->count);
    }
    flatUnion(spans, ctx.result);
}

/// The spans a primitive's test gave (`n` > 0), held in a mailbox of its own for the ray.
inline const Mailbox* holdSpans(uint32_t key, const Span* spans, int n, TraceContext& ctx) {
    Mailbox& fill = ctx.takeMailbox(key);
    fill.count = uint8_t(n);
    std::copy_n(spans, n, fill.spans);
    return &fill;
}

/// A union-only region's hit from its primitives' spans as they come (hitInUnionLeaf, the
/// regular walk's sphere quads): the first start among the spans reaching into the window
/// [t0, t1] after tmin, then the hit it gives.
struct UnionFirstStart {
    double tmin, t0, t1;
    Boundary first{kInf};
    bool found = false;
    /// Takes one primitive's spans.
    [[gnu::always_inline]] void add(const Mailbox& m) {
        for (int k = 0; k < m.count; ++k) {
            const Span& s = m.spans[k];
            if (s.out.t < t0 || !(s.out.t > tmin) || s.in.t > t1) continue;
            if (s.in.t < first.t) first = s.in, found = true;
        }
    }
    /// The region's hit, once every primitive of `keys` was added: the first start when it is
    /// inside the window, else the end of the stretch the ray starts in, from the merged spans.
    // Inlined by force: with two walks calling it the compiler left it out of line, a call in
    // every union leaf (docs/irregular.md, "Union-only regions: the hit from the first start").
    [[gnu::always_inline]] bool hit(const uint32_t* keys, uint32_t count, TraceContext& ctx,
                                    Hit& out) const {
        if (!found) return false;
        if (first.t >= t0 && first.t > tmin) {
            out = {first.t, first.prim, first.part, first.flip};
            return true;
        }
        mergeHeldSpans(keys, count, ctx);
        const Boundary* b = firstBoundary(ctx.result, tmin, t0, t1);
        if (b) out = {b->t, b->prim, b->part, b->flip};
        return b != nullptr;
    }
};

/// hitInUnionLeaf's `test` for regions that list the scene's primitives: Scene::primSpans.
struct ScenePrimTest {
    const Scene* scene;
    const Ray* ray;
    Precision precision;
    uint32_t prim(uint32_t p) const { return p; }
    void prefetch(uint32_t p) const {
        if (p < scene->packedSpheres.size()) __builtin_prefetch(&scene->packedSpheres[p]);
    }
    int operator()(uint32_t p, Span* out) const {
        return scene->primSpans(p, *ray, out, precision);
    }
};

/// The visible hit in a region whose tree is a union of its primitives, without an active
/// observer (hitInLeaf's answer, the same tests and mailbox hits): straight from the primitives'
/// spans, without the pending boundaries or a merge. `keys` name the region's `count`
/// primitives for `test` and the mailboxes: `test(key, spans)` puts the spans of the primitive
/// `test.prim(key)` in `spans` and returns how many (the regular walk numbers the primitives in
/// an order of its own, for locality). Only the spans reaching into the window count (out >= t0
/// and > tmin, in <= t1): a span wholly before the window or after it changes no boundary that
/// the merged union (flatUnion) has inside it, nor whose it is. The first of them to start (the
/// first listed on a tie, as flatUnion's stable sort keeps it) begins the union's first stretch
/// reaching into the window; when it starts inside the window (t >= t0 and > tmin), its start
/// is the hit. Otherwise the ray is inside that stretch at the window's start, and its end needs
/// the merge: the region's spans are merged as flatUnion merges them (test
/// `RegularUnion.UnionLeafIsFlatUnion`).
template <class Obs, class Test>
[[gnu::always_inline]] inline bool hitInUnionLeaf(const uint32_t* keys, uint32_t count,
                                                  const Test& test, double tmin, double t0,
                                                  double t1, TraceContext& ctx, Obs& obs,
                                                  Hit& hit) {
    if (!ctx.useMailboxes) ctx.newStamp();
    // The tags and spheres the loop reads, fetched together rather than one miss at a time.
    for (uint32_t i = 0; i < count; ++i) {
        __builtin_prefetch(ctx.tags.data() + keys[i]);
        test.prefetch(keys[i]);
    }
    UnionFirstStart start{tmin, t0, t1};
    for (uint32_t i = 0; i < count; ++i) {
        const uint32_t key = keys[i];
        const Mailbox* m = ctx.heldMailbox(key);
        if (m) {
            ++ctx.counters.mailboxHits;
            obs.mailboxHit(test.prim(key));
        } else {
            Span spans[2];
            const int n = test(key, spans);
            ++ctx.counters.primTests;
            obs.primTest(test.prim(key), spans, n);
            if (n == 0) {  // a miss, most tests: no mailbox of its own
                ctx.heldEmpty(key);
                continue;
            }
            m = holdSpans(key, spans, n, ctx);
        }
        start.add(*m);
    }
    return start.hit(keys, count, ctx, hit);
}

/// hitInRegion for a region that lists its tree's primitives (`prims`, `count`), walked in ray
/// order from the ray's first region, ctx.pending cleared for it. Every boundary of a CSG result
/// is a boundary of one of its primitives, with the same t; so when no primitive boundary lies
/// in [t0, t1] after tmin, the region holds no hit and its tree is not evaluated. Most regions a
/// ray crosses are like that: their primitives are hit elsewhere or not at all. The check costs
/// one comparison: ctx.pending keeps the boundaries after tmin of every primitive this ray has
/// tested, so a primitive taken from its mailbox adds nothing new. (A tested primitive outside
/// this region cannot have a boundary inside it unless its box was trimmed by the CSG; then the
/// tree is evaluated for nothing, never wrongly.) The spans are fetched once into the mailboxes
/// (counted as tests or mailbox hits); the tree then reads them there. Without mailboxes, each
/// region gets a fresh stamp and an empty pending list, so every region tests its primitives
/// again. Unlike hitInRegion, ctx.result is left unspecified. `unionOnly`: the tree has only
/// unions, so its spans are those of its primitives merged (flatUnion), without walking it:
/// a fifth of the render of a 598k-sphere union went to evaluating trees of unions (an active
/// observer is still shown the tree's evaluation). `tree` null: the region keeps no tree, only
/// its primitives, of a union-only scene (the irregular scheme's regions there); the hit comes
/// from their held spans as hitInUnionLeaf takes it (merged by flatUnion only when the ray
/// starts inside a stretch of the union, and always for an active observer, which is shown the
/// merged spans), and the region is empty when `count` is 0.
/// A leaf with a tree over more primitives than this is evaluated as brute force evaluates the
/// scene: lazily, a difference or intersection whose left side is empty along the ray leaving
/// its right side untested, instead of testing every primitive first for the pending check. On
/// OpenSCAD's example024 (a turned sponge whose one leaf holds 221 primitives) the up-front
/// tests made 120 tests per ray against brute force's 61 (docs/model.md, "Large leaves").
/// `tests` (none: `prims`) are the primitives to fetch for the pending
/// check, when the walk knows that the others are already in their mailboxes: the irregular
/// walk stepping in depth to the next slab of a zone fetches only the primitives that slab adds
/// (docs/irregular.md, "Entering lists"). `prims` must then be a subset of what this walk has
/// fetched together with `tests`.
inline constexpr uint32_t kLazyLeafPrims = 16;

template <class Obs>
[[gnu::always_inline]] inline bool hitInLeaf(const Scene& scene, const CsgTree* tree, int root,
                                             const uint32_t* prims, uint32_t count, const Ray& ray,
                                             double tmin, double t0, double t1, TraceContext& ctx,
                                             Obs& obs, Hit& hit, bool unionOnly = false,
                                             std::optional<std::span<const uint32_t>> tests = {},
                                             bool lazyTree = false) {
    PendingBoundaries& pend = ctx.pending;
    if (!ctx.useMailboxes) {
        ctx.newStamp();
        pend.clear();
    } else if (pend.next < t0) {
        pend.advance(t0);
    }
    pend.tested = true;
    if (tree ? root < 0 : count == 0) return false;
    const uint32_t* fetch = prims;
    uint32_t fetchCount = count;
    if (tests && ctx.useMailboxes) {  // without mailboxes each region fetches all again
        fetch = tests->data();
        fetchCount = uint32_t(tests->size());
    }
    const double from = std::max(t0, tmin);  // boundaries must be >= t0 and > tmin
    auto addBoundaries = [&](const Mailbox& m) {
        for (int k = 0; k < m.count; ++k) {
            const Span& s = m.spans[k];
            if (s.in.t >= from && s.in.t > tmin) pend.add(s.in.t);
            if (s.out.t >= from && s.out.t > tmin) pend.add(s.out.t);
        }
    };
    const bool csg = tree && !unionOnly;
    bool lazy = csg && count > kLazyLeafPrims;
    if (csg && lazyTree && !lazy) {
        for (uint32_t i = 0; i < fetchCount && !lazy; ++i) lazy = !ctx.heldMailbox(fetch[i]);
    }
    if (lazy) {
        // The spans the evaluation fetches go to the mailboxes filled after `filled` (in order),
        // whose boundaries join the pending ones: later regions may still be left by the check.
        pend.tested = false;
        const size_t filled = ctx.held.size();
        evalTree<Obs, Fetch::Counted>(scene, *tree, root, ray, ctx, obs, 0, ctx.result);
        for (size_t j = filled; j < ctx.held.size(); ++j) addBoundaries(ctx.held[j]);
        if constexpr (Obs::kActive) obs.regionSpans(ctx.result);
        const Boundary* b = firstBoundary(ctx.result, tmin, t0, t1);
        if (b) hit = {b->t, b->prim, b->part, b->flip};
        return b != nullptr;
    }
    for (uint32_t i = 0; i < fetchCount; ++i) {
        bool fresh;
        const Mailbox& m = mailboxSpans(scene, fetch[i], ray, ctx, obs, &fresh);
        if (fresh) addBoundaries(m);
    }
    if (!(pend.next <= t1) && !Obs::kActive) return false;  // the observer is shown the spans
    if (!tree && !Obs::kActive) {
        // A region keeping its list alone (the irregular scheme's, union-only): its hit as
        // hitInUnionLeaf finds it, from the held spans of its primitives, merged only when the
        // ray starts inside one of the union's stretches.
        UnionFirstStart start{tmin, t0, t1};
        for (uint32_t i = 0; i < count; ++i)
            if (const Mailbox* m = ctx.heldMailbox(prims[i])) start.add(*m);
        return start.hit(prims, count, ctx, hit);
    }
    if (!tree || (unionOnly && !Obs::kActive)) {
        mergeHeldSpans(prims, count, ctx);
    } else {
        evalTree<Obs, Fetch::Fresh>(scene, *tree, root, ray, ctx, obs, 0, ctx.result);
    }
    if constexpr (Obs::kActive) obs.regionSpans(ctx.result);
    const Boundary* b = firstBoundary(ctx.result, tmin, t0, t1);
    if (b) hit = {b->t, b->prim, b->part, b->flip};
    return b != nullptr;
}

}  // namespace lancer
