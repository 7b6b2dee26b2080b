// How the BVH's walks read node boxes: a reader hands them entries (a node, what it holds, the
// ray's interval in its box), so each walk is written once for every way of testing boxes (the
// ray parallel to an axis or not).
#pragma once

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

/// A node as a walk holds it: its id, what it holds, and the ray's interval in its box.
struct BvhEntry {
    uint32_t node;   ///< its id (nodes(), the observer's region)
    uint32_t first;  ///< leaf: its primList offset; inner: where the reader finds its children
    uint32_t count;  ///< leaf: its primitives; inner: kInner
    double t0, t1;
    static constexpr uint32_t kInner = 0xffffffffu;
    bool leaf() const { return count != kInner; }
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
};

/// Reads the double-precision nodes. kParallel: some axis of the ray has a zero direction,
/// tested by the origin's place rather than by a product with an infinite inverse (0 times
/// infinity is NaN on a box face).
template <bool kParallel>
struct DoubleBoxes {
    const BvhNode* nodes;
    SlabRay slab;

    /// The ray's interval in node `n`'s box, within [tmin, tmax]: false when empty.
    [[gnu::always_inline]] bool clip(const BvhNode& n, double tmin, double tmax, double& t0,
                                     double& t1) const {
        t0 = tmin;
        t1 = tmax;
        for (int a = 0; a < 3; ++a) {
            if constexpr (kParallel) {
                if (slab.inv[a] == 0.0) {  // parallel: inside the slab or not at all
                    if (slab.o[a] < n.lo[a] || slab.o[a] > n.hi[a]) return false;
                    continue;
                }
            }
            const double ta = (n.lo[a] - slab.o[a]) * slab.inv[a],
                         tb = (n.hi[a] - slab.o[a]) * slab.inv[a];
            const double near = ta < tb ? ta : tb, far = ta < tb ? tb : ta;
            t0 = near > t0 ? near : t0;
            t1 = far < t1 ? far : t1;
        }
        return t0 <= t1;
    }
    [[gnu::always_inline]] BvhEntry entry(uint32_t id, double t0, double t1) const {
        const BvhNode& n = nodes[id];
        return {id, n.first, n.leaf ? n.count : BvhEntry::kInner, t0, t1};
    }
    /// The root's entry when the ray meets its box within [tmin, tmax].
    bool root(double tmin, double tmax, BvhEntry& e) const {
        double t0, t1;
        if (!clip(nodes[0], tmin, tmax, t0, t1)) return false;
        e = entry(0, t0, t1);
        return true;
    }
    /// Inner entry `e`'s two children, met[k] when the ray meets child k's box in [tmin, tmax].
    [[gnu::always_inline]] void children(const BvhEntry& e, double tmin, double tmax, BvhEntry c[2],
                                         bool met[2]) const {
        for (uint32_t k = 0; k < 2; ++k) {
            double t0, t1;
            met[k] = clip(nodes[e.first + k], tmin, tmax, t0, t1);
            if (met[k]) c[k] = entry(e.first + k, t0, t1);
        }
    }
};

}  // namespace lancer
