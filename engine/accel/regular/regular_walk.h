// The regular grid's walk from leaf to leaf (docs/regular.md, "Walk"), and its first look at a
// union-only leaf's spheres in floats, four at a time ("Sphere quads"). Included by
// regular_grid.h: the walk's templates, RegularGrid's private steps.
#pragma once

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "engine/accel/regular/regular_grid.h"

namespace lancer {

/// Where the ray leaves a leaf: the nearest of its exit planes; ties are edges and corners.
struct RegularGrid::WalkExit {
    double tAxis[3];  ///< each axis's exit plane
    double t = kInf;
    int axis = 0;  ///< the first of the nearest

    /// Leaf `L`'s exit, by the walk's arrays (walk()).
    [[gnu::always_inline]] WalkExit(const RegularLeaf& L, const double o[3], const double inv[3],
                                    const double bias[3], const uint32_t side[3]) {
        const double* const P = L.plane;
        for (int a = 0; a < 3; ++a) {
            tAxis[a] = (P[side[a]] - o[a]) * inv[a] + bias[a];
            if (tAxis[a] < t) t = tAxis[a], axis = a;
        }
    }
    /// The tied axes, a bit each.
    int ties() const {
        int bits = 0;
        for (int a = 0; a < 3; ++a) bits |= int(tAxis[a] == t) << a;
        return bits;
    }
};

/// The walk's step out of a leaf: the leaf beyond, or the last one.
struct RegularGrid::WalkStep {
    uint32_t leaf;         ///< the next leaf
    bool last;             ///< the ray's stretch ends in this leaf (or it leaves the grid)
    bool stalled = false;  ///< push: the pushed point is still in this leaf
    uint32_t next[3];      ///< the directory cell looked up (how 2 and 3)
    /// For an active observer: 1 rope, 2 index step + lookup, 3 push + lookup.
    int how;
    Vec3 pushed;  ///< the pushed point (how 3), in the grid's frame

    /// From `leaf`, the last one unless the ray leaves it; the rest is set as the step goes.
    WalkStep(uint32_t leaf, bool last) : leaf(leaf), last(last) {}
};

template <class Obs>
bool RegularGrid::intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                            Hit& hit) const {
    return exact_ ? walk<true>(ray, tmin, tmax, ctx, obs, hit)
                  : walk<false>(ray, tmin, tmax, ctx, obs, hit);
}

template <bool kExact, class Obs>
bool RegularGrid::walk(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                       Hit& hit) const {
    // The cells are walked with the ray in the grid's frame (`fr`, the same t for the same
    // point), the primitives tested with the world ray; points told are the world's.
    Ray mapped;
    if (frame_.turned) mapped = frame_.toFrame(ray);
    const Ray& fr = frame_.turned ? mapped : ray;
    double tA, tB;
    if (!clipLine(fr, clipBox_, tA, tB)) return false;
    const double tStart = std::max(tmin, tA), tEnd = std::min(tmax, tB);
    if (!(tStart <= tEnd)) return false;
    uint32_t leaf = startLeaf(fr, tStart, obs);
    // Per ray, held locally (the loop's stores to mailboxes and counters could otherwise alias
    // the ray and the arrays, and each step would reload them; in one struct, 2% more
    // instructions): the origin, 1/d, so each exit plane costs a product, not a division, and
    // the side a cell is left by on each axis: its exit plane's place in RegularLeaf::plane (lo
    // a, hi 3 + a) and the rope across it. An axis the ray runs parallel to is never an exit:
    // its plane gets a factor 0 and a bias of +inf; on the others the bias is 0, which leaves
    // the product bit for bit unchanged.
    const double o[3] = {fr.o.x, fr.o.y, fr.o.z};
    const bool up[3] = {fr.d.x > 0.0, fr.d.y > 0.0, fr.d.z > 0.0};
    double inv[3], bias[3];
    uint32_t side[3], rope[3];
    for (int a = 0; a < 3; ++a) {
        const bool parallel = fr.d[a] == 0.0;
        inv[a] = parallel ? 0.0 : 1.0 / fr.d[a];
        bias[a] = parallel ? kInf : 0.0;
        side[a] = up[a] ? 3 + a : a;
        rope[a] = 2 * a + up[a];
    }
    const RegularLeaf* const leaves = leaves_.data();
    const uint32_t* const primList = primList_.data();
    const bool quads = !quads_.empty();
    QuadRay qr = quads ? quadRay(ray) : QuadRay{};
    // The first region is evaluated from tmin and the last one up to tmax: every primitive lies
    // inside the grid, so this only admits hits that rounding puts a hair outside the box.
    double t0 = tmin, tIn = tStart;
    [[maybe_unused]] const double tShown = shownStart<Obs>(fr, tStart);
    ctx.pending.clear();
    const size_t maxSteps = maxSteps_;
    for (size_t step = 0;; ++step) {
        if (step > maxSteps) return walkError(ctx, obs, "regular: step bound exceeded");
        const RegularLeaf& L = leaves[leaf];
        const WalkExit exit(L, o, inv, bias, side);
        WalkStep s(leaf, !(exit.t < tEnd));
        // How the walk leaves the leaf, told to an active observer after the leaf's own events.
        [[maybe_unused]] const bool exits = !s.last;
        if constexpr (Obs::kActive) s.how = 0, s.pushed = Vec3{};
        if (!s.last) {
            if constexpr (kExact)
                stepExact<Obs>(L, fr, exit, up[exit.axis], rope[exit.axis], s);
            else
                stepPush<Obs>(L, fr, exit, up, s);
        }
        const double t1 = s.last ? tmax : std::max(exit.t, tIn);
        ++ctx.counters.regionVisits;
        if (!s.last) __builtin_prefetch(leaves + s.leaf);
        // The stretch told ends where the ray leaves the leaf: at the clip of the grown box only
        // when that comes first. A ray leaving the grid through an edge or a corner may cross
        // the tied interior face as it leaves, so past the leaf's exit it is outside the leaf.
        if constexpr (Obs::kActive) {
            const double shownEnd = s.last ? std::min(tEnd, std::max(exit.t, tIn)) : t1;
            obs.region(leaf, std::min(std::max(tIn, tShown), shownEnd), shownEnd);
        }
        if (hitInRegion(L, primList, quads, qr, ray, tmin, tIn, t0, t1, ctx, obs, hit)) return true;
        if constexpr (Obs::kActive) tellExit(leaf, exits, exit, rope[exit.axis], s, ray, obs);
        if (s.last) return false;
        if (s.stalled)
            return walkError(ctx, obs,
                             "regular push: the pushed exit point is still in the same leaf");
        t0 = tIn = t1;
        leaf = s.leaf;
    }
}

template <class Obs>
[[gnu::always_inline]] inline uint32_t RegularGrid::startLeaf(const Ray& fr, double tStart,
                                                              Obs& obs) const {
    const Vec3 p = std::isfinite(tStart) ? fr.at(tStart) : fr.o;
    const uint32_t leaf = dir_.lookup(locate(0, p.x), locate(1, p.y), locate(2, p.z));
    if constexpr (Obs::kActive) {
        const uint32_t cell[3] = {locate(0, p.x), locate(1, p.y), locate(2, p.z)};
        obs.lookup(frame_.toWorld(p), cell, leaf);
    }
    return leaf;
}

template <class Obs>
inline double RegularGrid::shownStart(const Ray& fr, double tStart) const {
    // The clip of the grown box comes a hair before the grid's own box, and a grazing ray runs
    // outside the box for that hair.
    double tShown = tStart;
    if constexpr (Obs::kActive) {
        double a, b;
        if (clipLine(fr, box_, a, b)) tShown = std::max(tStart, a);
    }
    return tShown;
}

template <class Obs>
inline bool RegularGrid::walkError(TraceContext& ctx, Obs& obs, const char* what) {
    ++ctx.counters.walkErrors;
    obs.walkError(what);
    return false;
}

template <class Obs>
[[gnu::always_inline]] inline void RegularGrid::stepExact(const RegularLeaf& L, const Ray& fr,
                                                          const WalkExit& exit, bool up,
                                                          uint32_t rope, WalkStep& s) const {
    // The exit face lies on grid plane L.hi or L.lo of the exit axis: the next index there is
    // exact; the other indices are the exit point's, kept on the face. When one leaf covers the
    // whole face, the leaf's rope names it and no lookup is needed.
    const int a = exit.axis;
    const uint32_t across = L.rope[rope];
    if (across == kBorder) {
        s.last = true;
    } else if (across != kSplitFace) {
        s.leaf = across;
        if constexpr (Obs::kActive) s.how = 1;
    } else {
        const Vec3 q = fr.at(exit.t);
        s.next[a] = up ? L.hi[a] : L.lo[a] - 1;
        for (int b = 0; b < 3; ++b)
            if (b != a) s.next[b] = std::clamp(locate(b, q[b]), L.lo[b], L.hi[b] - 1);
        s.leaf = dir_.lookup(s.next[0], s.next[1], s.next[2]);
        if constexpr (Obs::kActive) s.how = 2;
    }
}

template <class Obs>
[[gnu::always_inline]] inline void RegularGrid::stepPush(const RegularLeaf& L, const Ray& fr,
                                                         const WalkExit& exit, const bool up[3],
                                                         WalkStep& s) const {
    // The report's method: the exit point, taken on the cell's box (rounding can put
    // ray.at(tExit) a hair outside it), is pushed by delta across every face it leaves through,
    // then located. Off the pushed axes it stays in the cell's range, so the walk cannot bounce
    // back into the previous cell.
    const double* const P = L.plane;
    const Vec3 q = fr.at(exit.t);
    for (int a = 0; a < 3; ++a) {
        double x = std::clamp(q[a], P[a], P[3 + a]);
        if (exit.tAxis[a] == exit.t) {
            x += up[a] ? delta_ : -delta_;
            if (x < box_.lo[a] || x > box_.hi[a]) s.last = true;  // left the grid
            s.next[a] = locate(a, x);
        } else {
            s.next[a] = std::clamp(locate(a, x), L.lo[a], L.hi[a] - 1);
        }
        if constexpr (Obs::kActive) s.pushed[a] = x;
    }
    if (!s.last) {
        const uint32_t leaf = s.leaf;
        s.leaf = dir_.lookup(s.next[0], s.next[1], s.next[2]);
        s.stalled = s.leaf == leaf;
        if constexpr (Obs::kActive) s.how = 3;
    }
}

template <class Obs>
[[gnu::always_inline]] inline bool RegularGrid::hitInRegion(
    const RegularLeaf& L, const uint32_t* primList, bool quads, QuadRay& qr, const Ray& ray,
    double tmin, double tIn, double t0, double t1, TraceContext& ctx, Obs& obs, Hit& hit) const {
    // A union-only scene's leaf: its hit straight from its primitives' spans, through the
    // sphere quads when the grid has them, for every observer (what an observer sees is the
    // walk made: the same tests and mailbox hits); without quads, an active observer is
    // shown the tree's evaluation (hitInLeaf), with the same counts as hitInUnionLeaf.
    if (quads) return L.prims != 0 && hitInSphereLeaf(L, qr, ray, tmin, tIn, t0, t1, ctx, obs, hit);
    if constexpr (!Obs::kActive) {
        return unionOnly_ ? hitInUnionLeaf(L.primitives(primList), L.prims,
                                           ScenePrimTest{scene_, &ray, ctx.precision}, tmin, t0, t1,
                                           ctx, obs, hit)
                          : hitInLeaf(*scene_, &pool_, L.root, L.primitives(primList), L.prims, ray,
                                      tmin, t0, t1, ctx, obs, hit);
    } else {
        return hitInLeaf(*scene_, &pool_, L.root, L.primitives(primList), L.prims, ray, tmin, t0,
                         t1, ctx, obs, hit, unionOnly_);
    }
}

template <class Obs>
void RegularGrid::tellExit(uint32_t leaf, bool exits, const WalkExit& exit, uint32_t rope,
                           const WalkStep& s, const Ray& ray, Obs& obs) const {
    const int ties = exit.ties();
    if (exits) obs.regionExit(exit.t, ray.at(exit.t), exit.axis, ties);
    if (s.how == 1) obs.rope(leaf, int(rope), s.leaf);
    if (s.how == 2) obs.indexStep(exit.axis, s.next);
    if (s.how == 3) obs.push(frame_.toWorld(s.pushed), ties);
    if (s.how >= 2)
        obs.lookup(s.how == 3 ? frame_.toWorld(s.pushed) : ray.at(exit.t), s.next, s.leaf);
}

inline RegularGrid::QuadRay RegularGrid::quadRay(const Ray& ray) const {
    QuadRay r;
    const Vec3 u = ray.d / glm::length(ray.d);
    r.at(ray.o);
    for (int a = 0; a < 3; ++a) r.d[a] = QuadRay::F4{} + float(u[a]);
    // The exact test computes the line's distance to the centre from the ray's origin: its
    // rounding grows with that distance, some 1e-15 of it (the allowance is a thousand times
    // that).
    const double far = std::max({std::abs(ray.o.x), std::abs(ray.o.y), std::abs(ray.o.z)});
    r.allowance = QuadRay::F4{} + float(1e-12 * (far + quadScale_));
    return r;
}

inline uint32_t RegularGrid::quadMisses(const SphereQuad& q, const QuadRay& r) {
    using F4 = QuadRay::F4;
    using I4 = int32_t __attribute__((vector_size(16)));
    // The vector from the ray's point to each centre, and the line's distance to the centre
    // as |f x d| (d a unit vector): no cancellation but that of the cross product's terms.
    const F4 fx = *reinterpret_cast<const F4*>(q.x) - r.p[0];
    const F4 fy = *reinterpret_cast<const F4*>(q.y) - r.p[1];
    const F4 fz = *reinterpret_cast<const F4*>(q.z) - r.p[2];
    const F4 gx = fy * r.d[2] - fz * r.d[1];
    const F4 gy = fz * r.d[0] - fx * r.d[2];
    const F4 gz = fx * r.d[1] - fy * r.d[0];
    const F4 dist2 = gx * gx + gy * gy + gz * gz;
    // The floats' rounding: a few 1e-7 of |f| (bounded by its 1-norm) from f, d and the cross
    // product, besides the centre's and the point's own (in the stored radius, see
    // makeSphereQuads); allowed for ten times over.
    const I4 absMask = {0x7fffffff, 0x7fffffff, 0x7fffffff, 0x7fffffff};
    const F4 norm1 = reinterpret_cast<F4>(reinterpret_cast<I4>(fx) & absMask) +
                     reinterpret_cast<F4>(reinterpret_cast<I4>(fy) & absMask) +
                     reinterpret_cast<F4>(reinterpret_cast<I4>(fz) & absMask);
    const F4 reach = *reinterpret_cast<const F4*>(q.r) + r.allowance + 4e-6f * norm1;
    // NaN and infinities compare false: such a sphere is not rejected.
    const I4 miss = dist2 > reach * reach;
#if defined(__SSE2__)
    return uint32_t(_mm_movemask_ps(reinterpret_cast<__m128>(miss)));
#else
    return uint32_t(miss[0] & 1) | uint32_t(miss[1] & 2) | uint32_t(miss[2] & 4) |
           uint32_t(miss[3] & 8);
#endif
}

template <class Obs>
[[gnu::always_inline]] inline bool RegularGrid::hitInSphereLeaf(const RegularLeaf& L, QuadRay& qr,
                                                                const Ray& ray, double tmin,
                                                                double tIn, double t0, double t1,
                                                                TraceContext& ctx, Obs& obs,
                                                                Hit& hit) const {
    if (!ctx.useMailboxes) ctx.newStamp();
    const uint32_t* const keys = L.primitives(primList_.data());
    const uint32_t count = L.prims;
    TraceContext::Tag* const tags = ctx.tags.data();
    // The quads' floats are near the leaf: the walk's point in it (the ray's origin for a first
    // leaf entered from an infinite tmin).
    if (std::isfinite(tIn)) qr.at(ray.at(tIn));
    const uint32_t rayId = ctx.rayId;
    UnionFirstStart start{tmin, t0, t1};
    for (uint32_t from = 0; from < count; from += 60) {
        const uint32_t n = std::min(count - from, 60u);
        const uint64_t misses = entryMisses(L.first + from, n, qr);
        // A rejected sphere has no span: its mailbox is neither read nor written (most of the
        // tags' cache misses spared), and it is a test each time a leaf lists it. All n are
        // counted as tests here and the mailbox hits below taken back: without -mpopcnt a
        // popcount is a call.
        ctx.counters.primTests += n;
        const uint64_t take = ~misses & ((uint64_t(1) << n) - 1);
        // The others' tags and spheres, fetched together rather than one miss at a time.
        for (uint64_t b = take; b; b &= b - 1) {
            const uint32_t key = keys[from + uint32_t(__builtin_ctzll(b))];
            __builtin_prefetch(tags + key);
            __builtin_prefetch(scene_->packedSpheres.data() + key);
        }
        if constexpr (Obs::kActive)
            for (uint64_t b = misses; b; b &= b - 1)
                obs.primTest(keys[from + uint32_t(__builtin_ctzll(b))], nullptr, 0);
        for (uint64_t b = take; b; b &= b - 1) {
            const uint32_t key = keys[from + uint32_t(__builtin_ctzll(b))];
            TraceContext::Tag& tag = tags[key];
            const Mailbox* m;
            if (tag.stamp == rayId) {
                --ctx.counters.primTests;
                ++ctx.counters.mailboxHits;
                obs.mailboxHit(key);
                if (tag.slot == 0) continue;  // tested and missed
                m = &ctx.held[tag.slot];
            } else {
                // Storage for the spans the test writes, not cleared first (Span's members
                // have defaults: a declared array costs its clearing in each test).
                alignas(Span) std::byte room[2 * sizeof(Span)];
                Span* const spans = reinterpret_cast<Span*>(room);
                const int k = scene_->primSpans(key, ray, spans, ctx.precision);
                obs.primTest(key, spans, k);
                if (k == 0) {
                    tag = {rayId, 0};  // the empty mailbox, as ctx.heldEmpty
                    continue;
                }
                m = holdSpans(key, spans, k, ctx);
            }
            start.add(*m);
        }
    }
    if constexpr (Obs::kActive) {
        mergeHeldSpans(keys, count, ctx);  // the leaf's spans, as hitInLeaf shows them
        obs.regionSpans(ctx.result);
    }
    return start.hit(keys, count, ctx, hit);
}

}  // namespace lancer
