// The CSG along a recorded ray (a TracedRay of engine/render/ray_tree.h): for each region step,
// every node of the region's restricted tree with its spans, and the ray's wasted work. Nothing
// here walks or tests again: the node spans come from evalTree (engine/accel/eval.h), the
// tracer's own evaluator, fed with the primitive spans the walk recorded, so its root is the
// walk's recorded result span for span. `lancer trace` and the viewer's ray playback read these.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "engine/accel/structure_view.h"
#include "engine/render/ray_tree.h"

namespace lancer {

/// A primitive's spans along a ray, as the walk read them (tested, or from its mailbox).
struct PrimSpans {
    uint32_t prim = kNoPrim;
    SpanList spans;
    bool mailbox = false;  ///< taken from the mailbox (the spans of an earlier test of the ray)
};

/// One node of a restricted tree evaluated along a ray.
struct NodeSpans {
    int node = -1;            ///< index in the tree's pool
    int parent = -1;          ///< index of the parent in the list evalNodes returns; -1: root
    int depth = 0;            ///< the root is 0
    Op op = Op::Primitive;    ///< Primitive: a leaf, `prim`
    uint32_t prim = kNoPrim;  ///< leaves only
    bool evaluated = false;   ///< evalTree reached it (∩ and − skip their right operand when
                              ///< the left one is empty)
    SpanList spans;           ///< along the whole line, when evaluated
};

/// Every node of `tree` from `root`, in pre-order (a node, its left subtree, its right one),
/// with the spans evalTree computes from the primitive spans `inputs` (a primitive the tree
/// reaches that `inputs` lacks is tested along `ray`, as the walk would have). Empty for an
/// empty tree.
std::vector<NodeSpans> evalNodes(const Scene& scene, const CsgTree& tree, int root, const Ray& ray,
                                 const std::vector<PrimSpans>& inputs);

/// The CSG of one step of a recorded ray (one Region event and the events up to the next one).
struct StepCsg {
    size_t event = 0;  ///< index of the step's Region event in the ray's events
    uint32_t region = 0;
    double t0 = 0.0, t1 = 0.0;  ///< the region's stretch of the ray, as the Region event says
    /// The window the walk took a hit in: [t0, t1] of the event, from the ray's tmin in its first
    /// region (every scheme) and up to its tmax in its last one (regular: the leaf's tree is
    /// evaluated to tmax there).
    double lo = 0.0, hi = 0.0;
    /// Primitive spans the step read, in the order read (tests, and mailbox hits with the spans
    /// of the earlier test); for a carried step, those of the step whose result it carries.
    std::vector<PrimSpans> inputs;
    bool evaluated = false;  ///< the walk evaluated the region's tree here (a Spans event)
    /// The region shares the previous region's restricted tree (irregular scheme): the walk read
    /// nothing, it took the tree's spans along the line from that region.
    bool carried = false;
    const CsgTree* pool = nullptr;  ///< the region's restricted tree (StructureView::region)
    int root = -1;
    std::vector<NodeSpans> nodes;   ///< evalNodes of the tree on `inputs`; empty unless evaluated
    SpanList result;                ///< the step's recorded Spans event (the root's spans)
    std::optional<Boundary> first;  ///< the first boundary of `result` in [lo, hi] after tmin
};

/// A region's restricted tree.
struct RegionTree {
    const CsgTree* pool = nullptr;
    int root = -1;
};
/// The restricted tree of each region id a walk reports.
using RegionTreeFn = std::function<RegionTree(uint32_t region)>;

/// Every step of `ray`, in order; `treeOf` gives each region's tree, `toTmaxInLast` says the walk
/// evaluates its last region up to the ray's tmax (the regular scheme).
std::vector<StepCsg> rayCsg(const Scene& scene, const TracedRay& ray, const RegionTreeFn& treeOf,
                            bool toTmaxInLast);
/// Every step of `ray`, traced in the structure `view` describes.
std::vector<StepCsg> rayCsg(const Scene& scene, const StructureView& view, const TracedRay& ray);

/// Why a primitive test did nothing for the ray (docs/viewer.md, "Wasted work").
enum class Waste : uint8_t {
    None,        ///< the test mattered: without its spans some step's first boundary changes
    Repeat,      ///< the ray had tested the primitive before (the same spans)
    Miss,        ///< the ray misses the primitive (no span)
    BeyondExit,  ///< every span of it starts beyond the exit of the region that tested it
    NoEffect,    ///< spans in reach, yet no step's first boundary depends on them
};
/// "", "repeat", "miss", "beyond exit", "no effect".
const char* wasteName(Waste w);

/// Tests of a step or a ray, and how many of them were wasted, by kind.
struct WasteCounts {
    uint32_t tests = 0, repeats = 0, misses = 0, beyondExit = 0, noEffect = 0;
    uint32_t wasted() const { return repeats + misses + beyondExit + noEffect; }
    void add(Waste w);
    WasteCounts& operator+=(const WasteCounts& o);
    bool operator==(const WasteCounts&) const = default;
    /// "14 tests, 3 wasted: 2 repeats, 1 beyond exit" (kinds with none left out).
    std::string toString() const;
};

/// The wasted work of a recorded ray.
struct RayWaste {
    std::vector<Waste> perEvent;       ///< per event of the ray: its class (PrimTest events only)
    std::vector<WasteCounts> perStep;  ///< per step (rayCsg's order)
    WasteCounts total;
};

/// Classifies every PrimTest event of `ray` from its steps (rayCsg of the same ray). A test of a
/// primitive the ray tested before is a repeat (one line, the same spans), a test that finds
/// no span a miss. Otherwise the test is useful when, in some step that reads these spans (its
/// own, later ones taking them from the mailbox or testing again, and the steps carrying those
/// steps' results), the first boundary in the step's window changes once the primitive's spans
/// are taken as empty (evalNodes again); when none does, it is beyond the exit if all its spans
/// start after the testing region's t1, else of no effect.
RayWaste wastedWork(const Scene& scene, const TracedRay& ray, const std::vector<StepCsg>& steps);

}  // namespace lancer
