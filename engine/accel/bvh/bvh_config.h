// The BVH's knobs: a plain struct the command line, the viewer and the tests fill in
// (docs/bvh.md says how each was chosen).
#pragma once

namespace lancer {

/// The automatic max-objects.
inline constexpr int kAutoBvhObjects = 2;

/// A bounding volume hierarchy over the minimized boxes, split by the surface-area heuristic
/// (engine/accel/bvh/bvh.h): the modern baseline beside the report's two subdivisions.
struct BvhConfig {
    /// Deepest level (the root is level 0); 0: automatic (kAutomaticBvhDepth).
    int maxLevel = 0;
    /// A node of at most this many primitives is a leaf (--max-objects); -1 (kAutoObjects,
    /// build_params.h): automatic, kAutoBvhObjects and the cost stop, as the other schemes.
    int maxObjects = -1;
    /// With the automatic max-objects: make a node a leaf where no split lowers the
    /// surface-area estimate of its cost, for nodes of at most kCostLeafPrims primitives
    /// (false: split down to max-objects). An explicit max-objects splits down to it.
    bool costStop = true;
    /// Build along a turned subtree's axes when chooseGridFrame() finds them (false:
    /// --world-frame; docs/regular.md, "Turned scenes").
    bool turnedFrame = true;
    /// The max-objects the build uses.
    int objects() const { return maxObjects < 0 ? kAutoBvhObjects : maxObjects; }
    /// Whether the surface-area estimate stops nodes.
    bool usesCostStop() const { return costStop && maxObjects < 0; }
    /// Cost of visiting a node's two children (their box tests), in primitive tests.
    double stepCost = 1.0;
};

/// The automatic depth limit: deep enough for any scene the memory budget admits.
inline constexpr int kAutomaticBvhDepth = 64;
/// The cost stop makes leaves of at most this many primitives.
inline constexpr int kCostLeafPrims = 8;

}  // namespace lancer
