// How the BVH's walks read node boxes. The binary nodes (BvhNode, in double) are the structure
// every tool sees; the walks read 4-wide nodes (BvhWideNode) collapsed from them, whose four
// children's boxes are tested at once with SSE in float, rounded outward so that no box the
// double test meets is missed (docs/bvh.md, "Walk"). A reader hands the walks entries (a node,
// and the ray's interval in its box), so each walk is written once.
#pragma once

#include <emmintrin.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "engine/geometry/geometry.h"

namespace lancer {

/// One node, in one cache line: its box (grown by a hair, BvhBuilder), and either its two
/// children (next to each other) or its leaf's primitives and restricted tree.
struct alignas(64) BvhNode {
    double lo[3] = {}, hi[3] = {};
    uint32_t first = 0;    ///< inner: the left child (the right one is first + 1); leaf: primList
    uint32_t count = 0;    ///< leaf: primitives listed (primList[first, first + count))
    int32_t root = -1;     ///< leaf: restricted tree in the pool; -1: none (union-only, or empty)
    uint16_t depth = 0;    ///< the root is depth 0
    uint8_t leaf = 0;      ///< 1: a leaf
    uint8_t assigned = 0;  ///< leaf: primitives the splits gave it (at most 255 shown; see count)
    Box3 box() const { return {{lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]}}; }
};
static_assert(sizeof(BvhNode) == 64);

/// How many children a wide node has at most.
inline constexpr int kBvhWidth = 4;
/// A wide node's slot that holds no child.
inline constexpr uint32_t kNoWide = 0xffffffffu;
/// The bit of a wide node's `wide` slot that marks a leaf; the other bits are the leaf's first
/// entry in Bvh::primList() (and in Bvh::unionEntries()), so that a walk reaches a union-only
/// leaf's primitives without reading its binary node.
inline constexpr uint32_t kWideLeaf = 0x80000000u;

/// A wide node, in two cache lines: an inner binary node with its descendants down to four
/// nodes (its children, or their children), whose boxes are stored axis by axis (SoA) so that
/// one SSE instruction works on all four. The boxes are the binary nodes' boxes less the
/// BVH's anchor, rounded outward to float; an unused slot has an empty box (lo +inf, hi -inf).
struct alignas(64) BvhWideNode {
    float lo[3][kBvhWidth], hi[3][kBvhWidth];
    uint32_t node[kBvhWidth];  ///< each slot's binary node id (kNoNode-like 0xffffffff: unused)
    /// An inner slot's wide node; a leaf's: kWideLeaf | its first entry; kNoWide: unused.
    uint32_t wide[kBvhWidth];
    /// A node whose four slots are unused.
    static BvhWideNode empty() {
        BvhWideNode w;
        for (int k = 0; k < kBvhWidth; ++k) {
            w.node[k] = 0xffffffffu;
            w.wide[k] = kNoWide;
            for (int a = 0; a < 3; ++a) w.lo[a][k] = INFINITY, w.hi[a][k] = -INFINITY;
        }
        return w;
    }
};
static_assert(sizeof(BvhWideNode) == 128);

/// A node as a walk holds it: its binary id, its wide node (a leaf: kWideLeaf and its first
/// entry), and the ray's interval in its box, rounded outward to float (the float test's, which
/// holds the double one).
struct BvhEntry {
    uint32_t node;  ///< its id (nodes(), the observer's region)
    uint32_t wide;  ///< inner: its wide node; leaf: kWideLeaf | its first entry
    float t0, t1;
    bool leaf() const { return wide & kWideLeaf; }
    /// A leaf's first entry in Bvh::primList().
    uint32_t first() const { return wide & ~kWideLeaf; }
};

/// The ray as the double box tests read it: its origin, and its inverse direction (0 along an
/// axis it is parallel to).
struct SlabRay {
    double o[3], inv[3];
    explicit SlabRay(const Ray& r) {
        for (int a = 0; a < 3; ++a) {
            o[a] = r.o[a];
            inv[a] = r.d[a] == 0.0 ? 0.0 : 1.0 / r.d[a];
        }
    }
    /// The ray's interval in `n`'s box within [tmin, tmax], in double: false when empty. An
    /// axis the ray is parallel to is tested by the origin's place (0 times infinity is NaN on
    /// a box face).
    bool clip(const BvhNode& n, double tmin, double tmax, double& t0, double& t1) const {
        t0 = tmin;
        t1 = tmax;
        for (int a = 0; a < 3; ++a) {
            if (inv[a] == 0.0) {
                if (o[a] < n.lo[a] || o[a] > n.hi[a]) return false;
                continue;
            }
            const double ta = (n.lo[a] - o[a]) * inv[a], tb = (n.hi[a] - o[a]) * inv[a];
            const double near = ta < tb ? ta : tb, far = ta < tb ? tb : ta;
            t0 = near > t0 ? near : t0;
            t1 = far < t1 ? far : t1;
        }
        return t0 <= t1;
    }
};

/// The next float above `f` (f itself for +inf and NaN), without a call into libm.
inline float floatAbove(float f) {
    if (!(f < INFINITY)) return f;
    if (f == 0.0f) return FLT_TRUE_MIN;
    const uint32_t u = std::bit_cast<uint32_t>(f);
    return std::bit_cast<float>(f > 0.0f ? u + 1 : u - 1);
}
/// The next float below `f` (f itself for -inf and NaN).
inline float floatBelow(float f) { return -floatAbove(-f); }
/// The largest float at most `x`.
inline float floatDown(double x) {
    const float f = float(x);
    return double(f) > x ? floatBelow(f) : f;
}
/// The smallest float at least `x`.
inline float floatUp(double x) {
    const float f = float(x);
    return double(f) < x ? floatAbove(f) : f;
}

/// Whether the ray's direction along axis `a` is too small for its inverse to fit a float
/// (zero, or below 2^-126): the float walk tests that axis by the origin's place.
inline bool flatAxis(const Ray& r, int a) { return !(std::abs(r.d[a]) >= 0x1p-126); }
/// Whether some axis of the ray is flatAxis().
inline bool hasFlatAxis(const Ray& r) { return flatAxis(r, 0) || flatAxis(r, 1) || flatAxis(r, 2); }

/// Reads the wide nodes with the ray in float. Each child's interval is computed from the near
/// and far face along each axis (chosen once per ray by the direction's sign), with an origin
/// moved to the side that makes the near t smaller and the far t larger; the float
/// subtraction, product and inverse add a relative error of at most 3 ulps, covered by
/// widening the interval by kSlack of its ends. kParallel: some axis is flatAxis(); it is
/// tested by the origin's place, which would miss only a box the ray enters beyond t = 2^126
/// times the box's distance along that axis.
template <bool kParallel>
struct WideBoxes {
    static constexpr bool kHasParallel = kParallel;  ///< some axis is tested by the origin's place
    const BvhWideNode* top;                          ///< a wide node whose one slot is the root
    const BvhWideNode* wides;                        ///< the wide nodes
    __m128 oNear[3];             ///< per axis, the origin less the anchor for the near face's t
    __m128 oFar[3];              ///< and for the far face's
    __m128 inv[3];               ///< the inverse direction (0 along a parallel axis)
    __m128 widenNear, widenFar;  ///< the factors that widen an interval's ends (kSlack)
    int nearOff[3];              ///< byte offset in a BvhWideNode of each axis's near face's floats
    int farOff[3];               ///< of the far face's
    bool parallel[3] = {};       ///< the axes tested by the origin's place
    /// Bit a set: the ray goes down axis a, whose near face is then hi (0 for a parallel axis):
    /// the walks made for one octant (kOct) have the faces' offsets as constants.
    int octant = 0;

    /// Relative widening of an interval's ends: 8 ulps, for the 3 that the arithmetic may lose.
    static constexpr float kSlack = 0x1p-21f;

    /// `t`: the wide node standing for the root (its slot 0); `anchor`: what the wide nodes'
    /// boxes are relative to.
    [[gnu::always_inline]] WideBoxes(const BvhWideNode* t, const BvhWideNode* w, const Ray& r,
                                     const Vec3& anchor)
        : top(t), wides(w) {
        for (int a = 0; a < 3; ++a) {
            // The origin less the anchor, moved by 2^-22 of itself either way (and a hair, for
            // 0) before rounding to the nearest float: the rounding moves it back by at most
            // 2^-24 of it, the subtraction's own by far less, so the true origin lies between.
            const double rel = r.o[a] - anchor[a], pad = std::abs(rel) * 0x1p-22 + 1e-30;
            const float up = float(rel + pad), down = float(rel - pad);
            const bool flat = flatAxis(r, a);
            parallel[a] = flat;
            const bool neg = !flat && r.d[a] < 0.0;
            // Near face: lo when the ray goes up the axis (a larger origin makes its t smaller),
            // hi when it goes down (a smaller origin does). The far face the other way round.
            oNear[a] = _mm_set1_ps(neg ? down : up);
            oFar[a] = _mm_set1_ps(neg ? up : down);
            // The inverse rounds to float with 1 ulp of relative error, part of the 3 covered.
            inv[a] = _mm_set1_ps(flat ? 0.0f : float(1.0 / r.d[a]));
            nearOff[a] = neg ? hiOffset(a) : loOffset(a);
            farOff[a] = neg ? loOffset(a) : hiOffset(a);
            octant |= int(neg) << a;
        }
        // Kept here, read by the products as memory operands, rather than made again per node.
        widenNear = _mm_set1_ps(1.0f - kSlack);
        widenFar = _mm_set1_ps(1.0f + kSlack);
    }

    /// The root's entry when the ray may meet its box within [tmin, tmax] (the float test, as
    /// for any node); returns 0 or 1.
    [[gnu::always_inline]] int root(__m128 tmin, __m128 tmax, BvhEntry& e) const {
        return meets<-1>(*top, tmin, tmax, &e);
    }

    /// Inner entry `e`'s children that the ray may meet within [tmin, tmax] (every one that
    /// the double test meets, and perhaps a few more), in slot order; returns how many. The
    /// bounds come in each of the four lanes: the walks round them to float (floatDown(tmin),
    /// floatUp(tmax)) and broadcast them once, not per node. tmin >= 0, as every walk's.
    /// kOct: the ray's octant when the caller is made for one (its faces' offsets constants;
    /// not with kParallel), -1 for any.
    template <int kOct = -1>
    [[gnu::always_inline]] int children(const BvhEntry& e, __m128 tmin, __m128 tmax,
                                        BvhEntry c[kBvhWidth]) const {
        return meets<kOct>(wides[e.wide], tmin, tmax, c);
    }
    /// children() with the bounds as floats.
    int children(const BvhEntry& e, float tmin, float tmax, BvhEntry c[kBvhWidth]) const {
        return children(e, _mm_set1_ps(tmin), _mm_set1_ps(tmax), c);
    }

  private:
    /// Byte offset in a BvhWideNode of axis a's lo floats, and of its hi ones.
    static constexpr int loOffset(int a) { return int(offsetof(BvhWideNode, lo)) + a * 16; }
    static constexpr int hiOffset(int a) { return int(offsetof(BvhWideNode, hi)) + a * 16; }

    /// The slots of `w` the ray may meet within [tmin, tmax], in slot order, into `c`.
    template <int kOct>
    [[gnu::always_inline]] int meets(const BvhWideNode& w, __m128 tmin, __m128 tmax,
                                     BvhEntry c[kBvhWidth]) const {
        static_assert(kOct < 0 || !kParallel, "a parallel axis has no octant");
        const char* base = reinterpret_cast<const char*>(&w);
        __m128 t0 = tmin, t1 = tmax;
        __m128 outside = _mm_setzero_ps();
        for (int a = 0; a < 3; ++a) {
            const bool down = kOct >> a & 1;
            const int nOff = kOct < 0 ? nearOff[a] : down ? hiOffset(a) : loOffset(a);
            const int fOff = kOct < 0 ? farOff[a] : down ? loOffset(a) : hiOffset(a);
            const __m128 fn = _mm_load_ps(reinterpret_cast<const float*>(base + nOff));
            const __m128 ff = _mm_load_ps(reinterpret_cast<const float*>(base + fOff));
            if constexpr (kParallel) {
                if (parallel[a]) {  // the origin outside the slab: lo > origin or hi < origin
                    outside = _mm_or_ps(
                        outside, _mm_or_ps(_mm_cmpgt_ps(fn, oNear[a]), _mm_cmplt_ps(ff, oFar[a])));
                    continue;
                }
            }
            t0 = _mm_max_ps(t0, _mm_mul_ps(_mm_sub_ps(fn, oNear[a]), inv[a]));
            t1 = _mm_min_ps(t1, _mm_mul_ps(_mm_sub_ps(ff, oFar[a]), inv[a]));
        }
        // t0 >= tmin >= 0, so widening it is a product; a negative t1 is a box that the
        // double test misses too (its t0 >= tmin >= 0; the rounding never turns a sign).
        // Each product rounds by half an ulp, far within the slack.
        t0 = _mm_mul_ps(t0, widenNear);
        t1 = _mm_mul_ps(t1, widenFar);
        int mask = _mm_movemask_ps(_mm_cmple_ps(t0, t1));  // NaN (an empty slot): not met
        if constexpr (kParallel) mask &= ~_mm_movemask_ps(outside);
        if (!mask) return 0;
        alignas(16) float a0[kBvhWidth], a1[kBvhWidth];
        _mm_store_ps(a0, t0);
        _mm_store_ps(a1, t1);
        int n = 0;
        do {
            const int k = __builtin_ctz(unsigned(mask));
            mask &= mask - 1;
            c[n++] = {w.node[k], w.wide[k], a0[k], a1[k]};
        } while (mask);
        return n;
    }
};

}  // namespace lancer
