// The regular scheme's BSP builder (docs/regular.md, "Build", "Cost-driven splits" and "How the
// build runs"): regular_builder.cpp builds the cells, with the cost estimate of what a split
// saves; fragment_layout.cpp lays the parallel fragments out in the serial build's order.
#pragma once

#include <tbb/enumerable_thread_specific.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/accel/build_guard.h"
#include "engine/accel/regular/regular_grid.h"
#include "engine/accel/regular/set_pool.h"
#include "engine/model/restriction.h"

namespace lancer {

/// A build that would pass RegularGrid::kMaxBspNodes: refused with the options to change, or,
/// in the automatic mode, made again shallower.
struct NodeLimitError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

/// Builds the BSP depth first. Each node's restricted tree is restricted again for its children
/// (restriction composes: restricting to P then to Q ⊆ P equals restricting to Q), so a node
/// costs the size of its parent's small tree, not of the scene's tree; in a union-only scene the
/// leaves restrict the scene's tree instead (see `restrictor`).
///
/// In parallel: a cell of at least RegularGrid::kTaskPrims primitives builds its two halves as
/// tasks, each into a Fragment of its own (nodes, leaves, restricted trees, in the order a
/// depth-first build makes them). The fragments are then laid out in the order of the serial build:
/// the pairs of nodes, the leaves and the trees' first appearances in depth-first order. Nothing a
/// task decides depends on another task, so the structure is the serial build's whatever the
/// threads.
struct RegularBuilder {
    using PrimList = regular_build::PrimList;
    using SetPool = regular_build::SetPool;

    /// Levels the split decision looks ahead: one cut per axis. A cut through a cell crossed by
    /// bars parallel to it (the sponge's) separates nothing, while the cuts across them do; a
    /// decision on one level would stop there.
    static constexpr int kLookahead = 3;
    /// A mailbox hit in tests: a tag compared and the spans read back (retestSaving()).
    static constexpr double kMailboxHitCost = 0.25;
    /// BspNodes::Node::first of a node whose subtree is another fragment's root (node 0 there):
    /// fragment `leaf` among the children of the fragment holding the node.
    static constexpr int32_t kLinked = -2;
    static constexpr uint32_t kUnplaced = 0xffffffffu;

    struct LeafPlace {
        int level;
        uint32_t pos[3];
    };
    /// Leaves: without primitives, inside all their boxes, stopped by the cost estimate, and (of
    /// the last) by the gain floor; at most max-objects primitives, at max-level with more.
    /// Every leaf is one of objects, level, covered or cost leaves.
    struct LeafCounts {
        uint64_t primRefs = 0;
        uint32_t maxPrims = 0;
        size_t emptyLeaves = 0, coveredLeaves = 0, costLeaves = 0, gainLeaves = 0;
        size_t objectsLeaves = 0, levelLeaves = 0;
        /// Cells whose list shrank because a convex solid fills them (restrictionWithin).
        size_t solidCells = 0;
        /// Another fragment's counts added to these.
        void add(const LeafCounts& o);
    };
    struct Scratch {
        PrimList in[2], live;  ///< the children's primitives, a child's live ones
        CsgTree sub;
        /// A child's tree and list once the solids filling its cell are known (heldWithin).
        CsgTree held;
        PrimList heldList;
    };
    /// What one task builds. Node 0 is the fragment's root (the BSP's root in the first one).
    struct Fragment {
        BspNodes bsp;
        /// Each leaf's place and primitive set in `pool`: the leaf itself (128 bytes, its
        /// primitives and tree from the set) is made where it is laid out (leafOf), rather
        /// than here and copied (on balls:6, 12 MB grown by doubling in fresh pages).
        std::vector<LeafPlace> places;
        std::vector<uint32_t> leafList;
        SetPool pool;                         ///< the leaves' trees and lists
        std::vector<size_t> treeStart = {0};  ///< set l's tree: pool.trees.nodes[treeStart[l]..)
        /// With a restrictor, the nodes the sets' trees will take: the trees are made once the
        /// sets have their final order (RegularBuilder::makeTrees), not in the fragments.
        size_t treeNodes = 0;
        std::vector<std::unique_ptr<Fragment>> children;  ///< fragments of kLinked nodes
        /// Each set's entry in the layout's pool (list kUnplaced: not yet placed).
        std::vector<RestrictedTreePool::Entry> placed;
        std::vector<Scratch> scratch;        ///< per level, for a node's children
        PrimList look[kLookahead + 1] = {};  ///< the cost estimate's lists, per depth
        // A task's own inputs: its cell's primitives and tree, when not its parent's.
        PrimList in, live;
        std::vector<uint32_t> key;  ///< a set's primitives, for restrictTreeTo()
        CsgTree sub;
        CsgTree held;  ///< its cell's tree and list within the solids filling it
        PrimList heldList;
        std::vector<uint32_t> filling, kept;  ///< heldWithin's scratch
        size_t reported = 0;                  ///< bytes() last added to RegularBuilder::bytes
        LeafCounts counts;                    ///< of this fragment's leaves

        explicit Fragment(int maxLevel) : scratch(size_t(maxLevel) + 2) { bsp.nodes.resize(1); }
        /// Free the working lists once the fragment is built, for the tasks still running to
        /// reuse: fresh pages cost more than the building does (balls:6's fragments' lists
        /// alone would take tens of MB).
        void releaseScratch() {
            std::vector<Scratch>().swap(scratch);
            for (PrimList& l : look) PrimList().swap(l);
            PrimList().swap(in);
            PrimList().swap(live);
            CsgTree().nodes.swap(sub.nodes);
            CsgTree().nodes.swap(held.nodes);
            PrimList().swap(heldList);
        }
        /// Heap bytes it keeps: vectors by capacity, and its pool with the trees still to make;
        /// each leaf at a RegularLeaf's size, which the layout makes of it.
        size_t bytes() const {
            return bsp.nodes.capacity() * sizeof(BspNodes::Node) +
                   leafList.capacity() * sizeof(RegularLeaf) +
                   places.capacity() * sizeof(LeafPlace) + leafList.capacity() * sizeof(uint32_t) +
                   pool.bytes() + treeNodes * sizeof(CsgNode);
        }
    };
    /// The structure laid out from the fragments, in the serial build's order.
    struct Layout {
        BspNodes bsp;
        std::vector<RegularLeaf> leaves;
        std::vector<LeafPlace> places;
        SetPool pool;
        size_t treeNodes = 0;  ///< with a restrictor, the trees' nodes (see makeTrees)
        LeafCounts counts;     ///< every fragment's
    };
    /// A cell's middle cut on its level's axis: its children's boxes, low then high, and their
    /// places in the next level's grid.
    struct Cut {
        int axis;
        double mid;
        Box3 child[2];
        uint32_t pos[2][3];
    };
    /// The first estimate of a split: the cost of a ray crossing the cell as a leaf, and split
    /// with its children as leaves (splitCost() at depth 1).
    struct Estimate {
        double leaf = 0.0, split = 0.0;
    };

    const Scene& scene;
    const RegularConfig& params;
    RegularGrid& grid;
    BuildGuard& guard;
    const std::vector<uint32_t> live;  ///< the scene tree's primitives, sorted, each once
    int maxLevel;                      ///< params.maxLevel, or the automatic one
    /// From this level on a split must pass the gain floor (RegularConfig::minGain).
    int gainLevel;
    /// Surface area of a cell of gainLevel (every cell of a level is alike); set once the axes
    /// are planned (setGainArea).
    double gainArea = 0.0;
    std::vector<float> weight;       ///< each primitive's test, in sphere tests (testWeights)
    std::vector<uint32_t> quarters;  ///< the same in quarters (testQuarters)
    bool unitWeights = false;        ///< every weight is 1: their sums are counts
    /// The scene's tree has only unions: a restriction then keeps every primitive it is given.
    bool unionOnly = false;
    /// How far a primitive's solid must reach beyond a cell to fill it: 1e-5 of the grid's
    /// size (floatSlack's bound on a float test's t for rays from near the scene), far above the
    /// rounding of the corners' mapping, so no surface of it lies in or at the cell.
    double solidMargin = 0.0;
    /// Per primitive: its solid filling a cell leaves the whole tree empty or full there,
    /// whatever the others do (a subtrahend under the root's difference, any primitive of a
    /// union): the cost estimate then counts that cell as empty. Empty for union-only trees,
    /// whose cells rays do not enter inside a solid.
    std::vector<char> decisive;
    /// A union-only scene's tree of small depth: the leaves restrict it, visiting only their
    /// primitives' ancestors, and cells keep no tree (restricting each cell's tree for its
    /// children took half of the build on balls:5). Null: each cell restricts its tree.
    std::unique_ptr<TreeRestrictor> restrictor;
    /// Per thread: membership marks of restrictTreeTo (one per primitive), all 0 between uses,
    /// and the restrictor's scratch; a use never waits for a task.
    tbb::enumerable_thread_specific<std::vector<char>> keep;
    tbb::enumerable_thread_specific<std::vector<int>> restrictorScratch;
    std::atomic<size_t> nodes{1};  ///< BSP nodes made by every fragment
    std::atomic<size_t> bytes{0};  ///< the fragments' bytes(), as last reported

    /// A builder of `g`, whose box and frame are set, over `s`'s primitives.
    RegularBuilder(const Scene& s, const RegularConfig& p, RegularGrid& g, BuildGuard& gd);

    // The functions declared inline below are called only in the file that defines them, which
    // lets the compiler fold them into their callers as it does a function written in the class
    // (as calls, the build of tetra:6 took 3% more instructions).

    // The build (regular_builder.cpp).

    /// The BSP, once the axes are planned: the root's fragment, the others linked from it.
    Fragment buildFragments();
    /// "--max-level N --max-objects M", for messages.
    inline std::string options() const;
    /// Why a build past kMaxBspNodes is refused.
    inline std::string refusal() const;
    /// Cancelled or over the budget: both end the build now. The structure's size is every
    /// fragment's bytes(), each adding its change since it last reported.
    inline void check(Fragment& f);
    /// Node `id` of fragment `f` at `level`, at index pos[a] of its level's grid on each axis,
    /// covering `box`; `prims` (sorted) are the primitives that matter here, `tree` the scene's
    /// tree restricted to them (unused with a restrictor).
    inline void build(Fragment& f, int id, int level, const uint32_t pos[3], const Box3& box,
                      const CsgTree& tree, const PrimList& prims);
    /// Whether the cell is a leaf by the report's rules (at most max-objects primitives, or at
    /// max-level) or lies inside all its primitives' boxes; the leaf counted. Throws when the
    /// build is refused, cancelled or over its budget.
    inline bool stopsByRule(Fragment& f, int level, const Box3& box, const PrimList& prims);
    /// The middle cut of the cell `box` at index `pos` of `level`'s grid.
    inline Cut cutOf(int level, const uint32_t pos[3], const Box3& box) const;
    /// Both children's lists into `sc.in` in one pass over `prims`, with the split's first
    /// estimate from the same comparisons.
    inline Estimate splitInOnePass(const PrimList& prims, const Box3& box, const Cut& cut,
                                   Scratch& sc) const;
    /// Node `id`'s children, `prims` split by `cut`; `onePass`: their lists are in `sc.in`.
    inline void split(Fragment& f, int id, int level, const Cut& cut, const CsgTree& tree,
                      const PrimList& prims, bool onePass, Scratch& sc);
    /// split()'s children `first` and `first` + 1 as tasks, each into a fragment of its own;
    /// their height.
    inline uint8_t splitInTasks(Fragment& f, int first, int level, const Cut& cut,
                                const CsgTree& tree, const PrimList& prims, bool onePass,
                                Scratch& sc);
    /// split()'s children `first` and `first` + 1 one after the other in `f`; their height.
    inline uint8_t splitInPlace(Fragment& f, int first, int level, const Cut& cut,
                                const CsgTree& tree, const PrimList& prims, bool onePass,
                                Scratch& sc);
    /// The primitives of `prims` (overlapping `box`) whose boxes overlap the half of `box` on
    /// side `side` of `mid` on `axis`, into `out`.
    inline void half(const PrimList& prims, int level, const Box3& child, int axis, double mid,
                     int side, PrimList& out) const;
    /// Build child `id` at `level` over the primitives `in` of its cell, restricting `tree` (its
    /// parent's, over `parentPrims`) to them where needed; `sc` holds the child's tree and list.
    inline void buildChild(Fragment& f, int id, int level, const uint32_t pos[3], const Box3& box,
                           const CsgTree& tree, const PrimList& parentPrims, const PrimList& in,
                           CsgTree& sub, PrimList& live, CsgTree& held, PrimList& heldList);
    /// Whether primitive p's solid fills the cell `box` of the grid's frame, grown by
    /// solidMargin: a convex solid holding the grown cell's corners.
    inline bool fills(uint32_t p, const Box3& box) const;
    /// The cell's tree and list once the primitives whose solids fill it are known, into
    /// `held` and `heldList` (restrictionWithin: a cell inside a subtrahend or inside the whole
    /// solid keeps nothing); false when they stay `tree` and `prims`.
    inline bool heldWithin(Fragment& f, const Box3& box, const CsgTree& tree, const PrimList& prims,
                           CsgTree& held, PrimList& heldList);
    /// Whether a decisive primitive of `prims` fills `cell`: the cell will be an empty leaf.
    inline bool emptiedCell(std::span<const uint32_t> prims, const Box3& cell) const;
    /// The children's tests with each emptied child's set to 0, and `shared` (the tests of
    /// primitives in both) to 0 when one is.
    inline void emptyChildren(std::span<const uint32_t> prims, const Box3 child[2], double tests[2],
                              double& shared) const;
    /// Node `id` as a leaf over `prims`, its set shared in the fragment's pool.
    inline void makeLeaf(Fragment& f, int id, int level, const uint32_t pos[3], const CsgTree& tree,
                         const PrimList& prims);
    /// With a restrictor, a place for the tree of a new set of `prims` after the `count` nodes
    /// of the trees before it: its root (the walk's last node), -1 for the empty tree.
    int reserveTree(std::span<const uint32_t> prims, size_t& count) const {
        const size_t size = restrictor->unionSize(prims);
        count += size;
        return size ? int(count - 1) : -1;
    }
    /// The tree restricted to `prims` in the fragment's pool, and their list, added once per
    /// set; where each set's tree starts is kept for the layout. With a restrictor only its
    /// place is reserved: the trees are made after the layout (makeTrees), written straight
    /// where they belong, rather than made in each fragment and copied (on balls:6 1.8 million
    /// nodes, made and copied in fresh pages).
    inline RestrictedTreePool::Entry treeFor(Fragment& f, const CsgTree& tree,
                                             const PrimList& prims);

    // The cost estimate (regular_builder.cpp).

    /// Estimated cost of a ray crossing a leaf over `prims`: one step of the walk and a test of
    /// each primitive.
    inline double leafCost(std::span<const uint32_t> prims) const;
    /// Estimated cost of a ray crossing the cell `box` at `level` that holds `prims`, split on
    /// the level's axis, its children then split as far as `depth` more levels pay. The surface
    /// area heuristic over the minimized boxes: a ray crossing the cell crosses a child with
    /// the chance of their areas' ratio, and a child holds the primitives whose boxes overlap
    /// it. The walk goes from leaf to leaf without descending the BSP, so a split costs nothing
    /// of its own: its price is the extra leaves a ray crosses, each one a step.
    inline double splitCost(Fragment& f, const Box3& box, std::span<const uint32_t> prims,
                            int level, int depth);
    /// What the mailboxes spare a split: a primitive in both children (`both`: their tests) is
    /// counted in each child's estimate, but a ray crossing both (the chance P0 + P1 - 1, every
    /// ray through the cell crossing one) tests it once and finds it in its mailbox in the
    /// other, for kMailboxHitCost of a test. Without this, a cell of long primitives (the bars
    /// of a Menger sponge) is kept whole where splitting it across them pays.
    inline double retestSaving(const Box3 child[2], double parentArea, double both) const;
    /// splitCost() at depth 1 from the tests of the children's primitives, the cut at `mid`.
    inline double splitCostOf(const Box3& box, int axis, double mid, const double tests[2],
                              double all) const;
    /// The first estimate of splitting the cell, from its primitives.
    inline Estimate estimate(Fragment& f, const Box3& box, std::span<const uint32_t> prims,
                             int level);
    /// The area of a cell of gainLevel, from the grid's box and its axes.
    inline void setGainArea();
    /// Whether the gain floor stops a cell at `level`, `box`, whose split (its children as
    /// leaves) saves `saving` of the estimated cost of a ray crossing it. Scaled by the cell's
    /// area, the saving is per ray crossing a cell of gainLevel: every cell deeper down must
    /// save that much for the rays that cross it, fewer as the cells shrink. A regular level
    /// cuts every cell alike, so without it the depth that separates the clusters of small
    /// primitives (a sphereflake's) is the depth of every cell that holds a few of them.
    inline bool belowGainFloor(int level, const Box3& box, double saving) const;
    /// Whether the cost estimate stops the cell, its split's `first` estimate given: a split
    /// must lower the estimated cost at once with its children as leaves (most cells), else
    /// with kLookahead levels of splits below; deeper than gainLevel the split at once must
    /// also pass the gain floor. The leaf counted, by the rule that stopped it.
    inline bool stopsByCost(Fragment& f, const Box3& box, std::span<const uint32_t> prims,
                            int level, const Estimate& first);

    // The layout (fragment_layout.cpp).

    /// The structure laid out from the fragments under `root`, in the serial build's order,
    /// with every fragment's counts and (with a restrictor) the sets' trees.
    Layout layOut(Fragment& root);
    /// Node `i` of fragment `f` as node `g` of the layout, and its subtree.
    inline void layOut(Layout& out, Fragment& f, size_t i, size_t g);
    /// Room in the layout for what the fragments under `root` hold (an upper bound for the
    /// pool, whose sets the fragments may share): a vector grown by doubling touches twice its
    /// final memory, and on the machines measured a first touch of a page costs more than the
    /// copy.
    static inline void reserve(Layout& out, const Fragment& root);
    /// The leaf over set `list` of `pool`, whose tree's root is `root`.
    static inline RegularLeaf leafOf(const SetPool& pool, uint32_t list, int root);
    /// The trees of `pool`'s sets, `count` nodes reserved by reserveTree() in the sets' order,
    /// made in parallel: each set's restriction is written at its place, so the nodes are
    /// those that restricting the sets one after the other would append.
    inline void makeTrees(SetPool& pool, size_t count);
    /// Each leaf's block of the finest grid, from its place in its level's grid, and its
    /// planes there: once the grid's resolution is set (RegularGrid::setResolution).
    void placeLeaves(Layout& out) const;
};

}  // namespace lancer
