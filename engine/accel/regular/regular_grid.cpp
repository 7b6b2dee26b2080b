#include "engine/accel/regular/regular_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_group.h>

#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <stdexcept>

#include "engine/accel/accelerator.h"
#include "engine/accel/build_guard.h"
#include "engine/model/restriction.h"
#include "engine/util/format.h"
#include "engine/util/hash.h"
#include "engine/util/huge_pages.h"
#include "engine/util/task_fence.h"

namespace lancer {

// Outside the anonymous namespace: RegularBuilder, a friend of RegularGrid and so of namespace
// lancer, holds these lists (a unity build would warn of a field of an internal type).
namespace regular_build {

/// An allocator whose resize() leaves the new elements uninitialised: a cell's pass sizes its
/// children's lists to hold every primitive and then writes them (zeroing them first took a
/// twentieth of the build's time on balls:6).
template <class T>
struct NoInit : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = NoInit<U>;
    };
    NoInit() = default;
    template <class U>
    NoInit(const NoInit<U>&) {}
    template <class U>
    void construct(U* p) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... A>
    void construct(U* p, A&&... a) {
        ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
    }
};
/// The builder's lists of primitives.
using PrimList = std::vector<uint32_t, NoInit<uint32_t>>;

/// The leaves' distinct primitive sets, each with its restricted tree: RestrictedTreePool's
/// sets and numbering (list 0 the empty set, the others in the order they first arrive), looked
/// up by an open-addressing index of list numbers into `lists` itself. The pool's index keeps
/// each set again in a node of its own (two allocations a set, freed one by one): on balls:6,
/// 65,000 sets in the fragments and again in the layout.
class SetPool {
  public:
    SetPool() : listFirst{0, 0}, roots{-1}, hashes{hashOf({})} { grow(); }

    /// The entry of `prims` (sorted, distinct), whose hash is hashOf(prims). A set not seen
    /// before gets the tree restrict(trees), which appends the restriction to `prims` to trees
    /// and returns its root.
    template <class Restrict>
    RestrictedTreePool::Entry share(std::span<const uint32_t> prims, uint32_t hash,
                                    Restrict&& restrict) {
        const uint32_t mask = uint32_t(slots_.size() - 1);
        for (uint32_t i = hash & mask;; i = (i + 1) & mask) {
            const uint32_t l = slots_[i];
            if (l == kEmpty) {
                const uint32_t list = uint32_t(roots.size());
                roots.push_back(restrict(trees));  // before the list: restrict may read prims
                lists.insert(lists.end(), prims.begin(), prims.end());
                listFirst.push_back(uint32_t(lists.size()));
                hashes.push_back(hash);
                slots_[i] = list;
                if (2 * roots.size() > slots_.size()) grow();
                return {roots[list], list};
            }
            if (hashes[l] == hash && listFirst[l + 1] - listFirst[l] == prims.size() &&
                std::equal(prims.begin(), prims.end(), lists.begin() + listFirst[l]))
                return {roots[l], l};
        }
    }
    /// The hash share() takes.
    static uint32_t hashOf(std::span<const uint32_t> prims) {
        const uint64_t h = hashWords(prims);
        return uint32_t(h ^ (h >> 32));
    }
    /// Set `list`'s primitives.
    std::span<const uint32_t> set(uint32_t list) const {
        return {lists.data() + listFirst[list], listFirst[list + 1] - listFirst[list]};
    }
    /// Distinct sets, the empty one included.
    size_t size() const { return roots.size(); }
    /// Heap bytes held, vectors by capacity, with each set charged as RestrictedTreePool
    /// charges it (its index's node and key, RestrictedTreePool::kEntryBytes, and the key's
    /// elements again): more than this pool holds, but the budget's refusals stay where they
    /// were (--memory-budget's tests refuse the sponge at 256 KiB).
    size_t bytes() const {
        return trees.nodes.capacity() * sizeof(CsgNode) +
               (listFirst.capacity() + 2 * lists.capacity() + roots.capacity() + hashes.capacity() +
                slots_.capacity()) *
                   sizeof(uint32_t) +
               roots.size() * RestrictedTreePool::kEntryBytes;
    }

    CsgTree trees;                    ///< every set's restricted tree
    std::vector<uint32_t> listFirst;  ///< list l: lists[listFirst[l] .. [l + 1])
    std::vector<uint32_t> lists;      ///< every set's primitives, set after set
    std::vector<int> roots;           ///< set l's tree's root in trees; -1: empty
    std::vector<uint32_t> hashes;     ///< set l's hashOf()

  private:
    static constexpr uint32_t kEmpty = 0xffffffffu;
    /// Twice the slots, the sets placed again by their hashes: at most half the slots are used.
    void grow() {
        slots_.assign(std::max<size_t>(16, 2 * slots_.size()), kEmpty);
        const uint32_t mask = uint32_t(slots_.size() - 1);
        for (uint32_t l = 0; l < roots.size(); ++l) {
            uint32_t i = hashes[l] & mask;
            while (slots_[i] != kEmpty) i = (i + 1) & mask;
            slots_[i] = l;
        }
    }
    std::vector<uint32_t> slots_;  ///< a list number or kEmpty
};

}  // namespace regular_build

using regular_build::PrimList;
using regular_build::SetPool;

namespace {

void sortedUnique(std::vector<uint32_t>& v) {
    // A scene's union lists its primitives in order (every format's balanced union): sorting
    // 600,000 of them again took 30 M instructions.
    if (!std::is_sorted(v.begin(), v.end())) std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// A cell inside every one of its primitives' boxes: every sub-cell would hold the same
/// primitives, hence the same tree, so it is not split.
bool coveredByAll(const std::vector<Box3>& boxes, std::span<const uint32_t> prims,
                  const Box3& cell) {
    for (uint32_t p : prims) {
        const Box3& b = boxes[p];
        if (!(b.lo.x <= cell.lo.x && b.lo.y <= cell.lo.y && b.lo.z <= cell.lo.z &&
              b.hi.x >= cell.hi.x && b.hi.y >= cell.hi.y && b.hi.z >= cell.hi.z))
            return false;
    }
    return true;
}

/// What testing each primitive costs, in sphere tests: a polygon's inside test loops over its
/// edges, so it weighs 1 + vertices / 4 (on gears, whose faces have up to 144 vertices, weighing
/// every test alike made the planner cut x and y first, for 34% more instructions than x, y, z in
/// turn). Floats: 1 + n / 4 is exact in one, and half the bytes of a double are read at random
/// (and touched first) for each of up to a million primitives.
std::vector<float> testWeights(const Scene& scene) {
    std::vector<float> w(scene.prims.size(), 1.0f);
    for (size_t i = 0; i < w.size(); ++i)
        if (const Polygon* pg = std::get_if<Polygon>(&scene.prims[i].shape))
            w[i] = float(1.0 + double(pg->p.size()) / 4.0);
    return w;
}

/// testWeights() in quarters of a test, as integers: every weight is a multiple of a quarter
/// (4 + vertices quarters, or a float of 2^21 or more, a whole number), so their sums are
/// exact in a double, and an integer sum divided by 4 is the double sum bit for bit. The loops
/// over references sum integers, whose additions do not wait on a double's latency.
std::vector<uint32_t> testQuarters(const std::vector<float>& weights) {
    std::vector<uint32_t> q(weights.size());
    for (size_t i = 0; i < q.size(); ++i) q[i] = uint32_t(double(weights[i]) * 4.0);
    return q;
}

/// Levels --split-axes cost plans (4 cuts per axis on a cube: they fix the cells' shape); deeper
/// ones cut the longest axis of the level's cells, as the report's order
/// does on a cube. Planning every level cost up to 40% more build time on scenes of thousands of
/// triangles that stay above max-objects around shared vertices (tetra), for the same counters
/// within 2%; 12 levels cost 1-3% more build instructions, and balls4 14% fewer.
constexpr int kPlannedLevels = 12;

/// Deepest union-only tree whose leaves are restricted from the scene's tree (64: a balanced
/// union of 2^63 primitives; a chain of unions goes back to the cells' own trees).
constexpr int kRestrictorDepth = 64;

/// The axes of --split-axes cost, planned level by level over the primitives' minimized boxes
/// alone (no CSG restriction, so a little pessimistic). Every cell of a level has the same
/// surface area A(axis) once cut on `axis`, so with the surface area heuristic the next level
/// costs A(axis) x (2 visits + the tests of the primitive references) per cut cell; the cheapest
/// axis is cut, ties going to x, then y; a test weighs as testWeights() says (`quarters`:
/// testQuarters()). Cells stop as in the build: at most max-objects primitives, or covered by
/// all their boxes. On a cube of
/// evenly spread primitives this is the report's x, y, z; on a flat scene (balls4: 24 x 24 x 1.5)
/// it cuts x and y until the cells are about cubes, where the report's order makes them 16 times
/// flatter than wide.
AxisSchedule planSchedule(const std::vector<Box3>& primBoxes, const Box3& box,
                          const std::vector<uint32_t>& live, const std::vector<uint32_t>& quarters,
                          int maxLevel, int maxObjects, const BuildGuard& guard) {
    // The cells of a level, their primitives in one array: cell c holds refs[begin, end).
    struct Cell {
        Box3 box;
        size_t begin, end;
    };
    // A stretch of one cell's references, the unit of parallel work: for each axis, the tests
    // its references make in the cell's children and how many go to each child; then where in
    // the next level's array it writes each child's references.
    struct Chunk {
        size_t cell, begin, end;
        double tests[3];
        size_t count[3][2];
        size_t out[2];
    };
    constexpr size_t kChunk = 16384;
    std::vector<Cell> cells{{box, 0, live.size()}}, next;
    std::vector<uint32_t> refs(live), nextRefs;
    std::vector<Chunk> chunks;
    std::vector<char> open;
    Vec3 size = box.extent();
    std::vector<int> axes;
    for (int level = 0; level < maxLevel; ++level) {
        if (level >= kPlannedLevels) {  // the longest axis of the level's cells
            int a = 0;
            if (size.y > size[a]) a = 1;
            if (size.z > size[a]) a = 2;
            axes.push_back(a);
            size[a] *= 0.5;
            continue;
        }
        guard.poll();
        // Drop the cells that stop here.
        open.assign(cells.size(), 0);
        TaskFence fence;
        // Polled per cell and per chunk: a level's passes over the references take a quarter
        // of a second on balls:5 at --max-objects 1 under ThreadSanitizer.
        tbb::parallel_for(size_t(0), cells.size(), fence.task([&](size_t k) {
            guard.poll();
            const Cell& c = cells[k];
            open[k] = c.end - c.begin > size_t(maxObjects) &&
                      !coveredByAll(primBoxes, {refs.data() + c.begin, c.end - c.begin}, c.box);
        }));
        fence.acquire();
        size_t kept = 0;
        for (size_t k = 0; k < cells.size(); ++k)
            if (open[k]) cells[kept++] = cells[k];
        cells.resize(kept);
        if (cells.empty()) break;
        // Every axis in one pass over the references. The tests are sums of multiples of a
        // quarter (testWeights()), exact in any order: the chunks' sums are the serial sums.
        chunks.clear();
        for (size_t k = 0; k < cells.size(); ++k)
            for (size_t b = cells[k].begin; b < cells[k].end; b += kChunk)
                chunks.push_back({k, b, std::min(cells[k].end, b + kChunk), {}, {}, {}});
        tbb::parallel_for(size_t(0), chunks.size(), fence.task([&](size_t k) {
            guard.poll();
            Chunk& ch = chunks[k];
            const Box3& cb = cells[ch.cell].box;
            const double mid[3] = {0.5 * (cb.lo.x + cb.hi.x), 0.5 * (cb.lo.y + cb.hi.y),
                                   0.5 * (cb.lo.z + cb.hi.z)};
            // Sums held locally: stored to the chunk each time, they would be reloaded after
            // every store. Tests in quarters (testQuarters()).
            uint64_t tests[3] = {0, 0, 0};
            size_t count[3][2] = {};
            const Box3* const boxes = primBoxes.data();
            const uint32_t* const weights = quarters.data();
            for (size_t i = ch.begin; i < ch.end; ++i) {
                const Box3& b = boxes[refs[i]];
                const uint64_t w = weights[refs[i]];
                for (int a = 0; a < 3; ++a) {
                    const int lo = b.lo[a] <= mid[a], hi = b.hi[a] >= mid[a];
                    count[a][0] += size_t(lo);
                    count[a][1] += size_t(hi);
                    tests[a] += w * uint64_t(lo + hi);
                }
            }
            for (int a = 0; a < 3; ++a) {
                ch.tests[a] = double(tests[a]) * 0.25;
                ch.count[a][0] = count[a][0];
                ch.count[a][1] = count[a][1];
            }
        }));
        fence.acquire();
        double best = kInf;
        int axis = 0;
        for (int a = 0; a < 3; ++a) {
            Vec3 child = size;
            child[a] *= 0.5;
            const double area = child.x * child.y + child.y * child.z + child.z * child.x;
            double tests = 0.0;
            for (const Chunk& ch : chunks) tests += ch.tests[a];
            const double total = area * (2.0 * double(cells.size()) + tests);
            if (total < best) best = total, axis = a;
        }
        axes.push_back(axis);
        size[axis] *= 0.5;
        // The children, cell by cell, low then high: each child's references in their order,
        // written by the chunks at offsets summed in that order.
        next.clear();
        size_t total = 0;
        for (size_t k = 0, first = 0; k < cells.size(); ++k) {
            const Cell& c = cells[k];
            const double mid = 0.5 * (c.box.lo[axis] + c.box.hi[axis]);
            size_t last = first;
            while (last < chunks.size() && chunks[last].cell == k) ++last;
            for (int side = 0; side < 2; ++side) {
                Cell child{c.box, total, 0};
                (side ? child.box.lo : child.box.hi)[axis] = mid;
                for (size_t h = first; h < last; ++h)
                    chunks[h].out[side] = total, total += chunks[h].count[axis][side];
                child.end = total;
                next.push_back(child);
            }
            first = last;
        }
        nextRefs.resize(total);
        tbb::parallel_for(size_t(0), chunks.size(), fence.task([&](size_t k) {
            guard.poll();
            Chunk& ch = chunks[k];
            const Box3& cb = cells[ch.cell].box;
            const double mid = 0.5 * (cb.lo[axis] + cb.hi[axis]);
            const Box3* const boxes = primBoxes.data();
            uint32_t* lo = nextRefs.data() + ch.out[0];
            uint32_t* hi = nextRefs.data() + ch.out[1];
            for (size_t i = ch.begin; i < ch.end; ++i) {
                const uint32_t r = refs[i];
                const Box3& b = boxes[r];
                if (coord(b.lo, axis) <= mid) *lo++ = r;
                if (coord(b.hi, axis) >= mid) *hi++ = r;
            }
        }));
        fence.acquire();
        cells.swap(next);
        refs.swap(nextRefs);
    }
    return AxisSchedule(axes);
}

}  // namespace

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
    struct Scratch {
        PrimList in[2], live;  ///< the children's primitives, a child's live ones
        CsgTree sub;
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
        size_t reported = 0;  ///< bytes() last added to RegularBuilder::bytes
        uint64_t primRefs = 0;
        uint32_t maxPrims = 0;
        /// Leaves: without primitives, inside all their boxes, stopped by the cost estimate,
        /// and (of the last) by the gain floor; at most max-objects primitives, at max-level
        /// with more. Every leaf is one of objects, level, covered or cost leaves.
        size_t emptyLeaves = 0, coveredLeaves = 0, costLeaves = 0, gainLeaves = 0;
        size_t objectsLeaves = 0, levelLeaves = 0;

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

    const Scene& scene;
    const RegularConfig& params;
    RegularGrid& grid;
    BuildGuard& guard;
    int maxLevel;  ///< params.maxLevel, or the automatic one
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

    RegularBuilder(const Scene& s, const RegularConfig& p, RegularGrid& g, BuildGuard& gd,
                   size_t livePrims)
        : scene(s),
          params(p),
          grid(g),
          guard(gd),
          maxLevel(effectiveMaxLevel(p, livePrims)),
          gainLevel(lancer::gainLevel(p, livePrims)),
          weight(testWeights(s)),
          quarters(testQuarters(weight)),
          unitWeights(std::all_of(weight.begin(), weight.end(), [](float w) { return w == 1.0f; })),
          unionOnly(s.tree.unionOnly()),
          keep([n = s.prims.size()] { return std::vector<char>(n, 0); }) {
        // A leaf's restriction climbs from its primitives to the root: a cost of the tree's
        // depth per primitive, which a balanced union (every scene format makes one) keeps to
        // log2 N.
        if (unionOnly && s.tree.depth() <= kRestrictorDepth) {
            restrictor = std::make_unique<TreeRestrictor>(s.tree);
        }
    }

    /// Plane `i` of `level`-cut grid on `axis` (i in 0..2^cuts); equal to grid.plane() at the
    /// finest level, since i / 2^c == (i 2^(n-c)) / 2^n exactly in floating point.
    double planeAt(int axis, uint32_t i, int cuts) const {
        return i == (1u << cuts)
                   ? grid.box_.hi[axis]
                   : grid.box_.lo[axis] + grid.ext_[axis] * std::ldexp(double(i), -cuts);
    }

    std::string options() const {
        return "--max-level " + std::to_string(maxLevel) + " --max-objects " +
               std::to_string(params.objects());
    }

    std::string refusal() const {
        return options() + ": the regular subdivision would need more than " +
               std::to_string(RegularGrid::kMaxBspNodes) +
               " BSP nodes, the builder's limit (it keeps a build within seconds and within its "
               "memory budget); lower --max-level or raise --max-objects";
    }

    /// Cancelled or over the budget: both end the build now. The structure's size is every
    /// fragment's bytes(), each adding its change since it last reported.
    void check(Fragment& f) {
        const size_t mine = f.bytes();
        const size_t b = bytes.fetch_add(mine - f.reported) + (mine - f.reported);
        f.reported = mine;
        const size_t made = nodes.load(std::memory_order_relaxed);
        guard.poll("regular BSP", b, made);
        if (!guard.fits(b))
            throw std::invalid_argument(
                "--memory-budget " + guard.describe() + ": the regular subdivision at " +
                options() + " passes its memory budget (" + formatBytes(b) + " after " +
                std::to_string(made) +
                " BSP nodes, with room to grow); lower --max-level, raise --max-objects or raise "
                "--memory-budget");
    }

    /// Estimated cost of a ray crossing a leaf over `prims`: one step of the walk and a test of
    /// each primitive.
    double leafCost(std::span<const uint32_t> prims) const {
        double tests = 0.0;
        for (uint32_t p : prims) tests += weight[p];
        return params.stepCost + params.testCost * tests;
    }

    /// Estimated cost of a ray crossing the cell `box` at `level` that holds `prims`, split on
    /// the level's axis, its children then split as far as `depth` more levels pay. The surface
    /// area heuristic over the minimized boxes: a ray crossing the cell crosses a child with
    /// the chance of their areas' ratio, and a child holds the primitives whose boxes overlap
    /// it. The walk goes from leaf to leaf without descending the BSP, so a split costs nothing
    /// of its own: its price is the extra leaves a ray crosses, each one a step.
    double splitCost(Fragment& f, const Box3& box, std::span<const uint32_t> prims, int level,
                     int depth) {
        const int axis = grid.schedule_.axis(level);
        const double mid = 0.5 * (box.lo[axis] + box.hi[axis]);
        Box3 child[2] = {box, box};
        child[0].hi[axis] = child[1].lo[axis] = mid;
        // The primitives overlap the cell, so a child's test is on the cut axis alone.
        double tests[2] = {0.0, 0.0}, all = 0.0;
        size_t count[2] = {0, 0};
        for (uint32_t p : prims) {
            const Box3& b = grid.boxes()[p];
            all += weight[p];
            if (coord(b.lo, axis) <= mid) tests[0] += weight[p], ++count[0];
            if (coord(b.hi, axis) >= mid) tests[1] += weight[p], ++count[1];
        }
        const double parentArea = surfaceArea(box);
        double cost = -retestSaving(child, parentArea, tests[0] + tests[1] - all);
        for (int side = 0; side < 2; ++side) {
            double c = params.stepCost + params.testCost * tests[side];
            // The look-ahead stops at the gain floor's level, below which a split needs the
            // floor's saving on its own (beyond it, it found splits at the level above that the
            // floor then stopped: 9% more leaves on tetra:7 for the same tests).
            if (depth > 1 && level + 1 < std::min(maxLevel, gainLevel) &&
                count[side] > size_t(params.objects())) {
                PrimList& in = f.look[depth];
                in.clear();
                for (uint32_t p : prims)
                    if (side ? coord(grid.boxes()[p].hi, axis) >= mid
                             : coord(grid.boxes()[p].lo, axis) <= mid)
                        in.push_back(p);
                if (!coveredByAll(grid.boxes(), in, child[side]))
                    c = std::min(c, splitCost(f, child[side], in, level + 1, depth - 1));
            }
            cost += surfaceArea(child[side]) / parentArea * c;
        }
        return cost;
    }

    /// What the mailboxes spare a split: a primitive in both children (`both`: their tests) is
    /// counted in each child's estimate, but a ray crossing both (the chance P0 + P1 - 1, every
    /// ray through the cell crossing one) tests it once and finds it in its mailbox in the
    /// other, for kMailboxHitCost of a test. Without this, a cell of long primitives (the bars
    /// of a Menger sponge) is kept whole where splitting it across them pays.
    double retestSaving(const Box3 child[2], double parentArea, double both) const {
        const double crossBoth = (surfaceArea(child[0]) + surfaceArea(child[1])) / parentArea - 1.0;
        return params.testCost * (1.0 - kMailboxHitCost) * both * std::max(crossBoth, 0.0);
    }

    /// splitCost() at depth 1 from the tests of the children's primitives, the cut at `mid`.
    double splitCostOf(const Box3& box, int axis, double mid, const double tests[2],
                       double all) const {
        Box3 child[2] = {box, box};
        child[0].hi[axis] = child[1].lo[axis] = mid;
        const double parentArea = surfaceArea(box);
        double cost = -retestSaving(child, parentArea, tests[0] + tests[1] - all);
        for (int side = 0; side < 2; ++side)
            cost += surfaceArea(child[side]) / parentArea *
                    (params.stepCost + params.testCost * tests[side]);
        return cost;
    }

    /// The area of a cell of gainLevel, from the grid's box and its axes.
    void setGainArea() {
        if (gainLevel >= maxLevel) return;
        Vec3 e = grid.ext_;
        for (int l = 0; l < gainLevel; ++l) e[grid.schedule_.axis(l)] *= 0.5;
        gainArea = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
    }

    /// Whether the gain floor stops a cell at `level`, `box`, whose split (its children as
    /// leaves) saves `saving` of the estimated cost of a ray crossing it. Scaled by the cell's
    /// area, the saving is per ray crossing a cell of gainLevel: every cell deeper down must
    /// save that much for the rays that cross it, fewer as the cells shrink. A regular level
    /// cuts every cell alike, so without it the depth that separates the clusters of small
    /// primitives (a sphereflake's) is the depth of every cell that holds a few of them.
    bool belowGainFloor(int level, const Box3& box, double saving) const {
        return level >= gainLevel && saving * surfaceArea(box) < params.minGain * gainArea;
    }

    /// Whether splitting the cell lowers the estimated cost: at once with its children as
    /// leaves (most cells), else with kLookahead levels of splits below; deeper than gainLevel
    /// the split at once must also pass the gain floor. `gainStop` tells which rule stopped it.
    bool splitPays(Fragment& f, const Box3& box, std::span<const uint32_t> prims, int level,
                   bool& gainStop) {
        const double leaf = leafCost(prims);
        const double split = splitCost(f, box, prims, level, 1);
        gainStop = belowGainFloor(level, box, leaf - split);
        if (gainStop) return false;
        return split < leaf || splitCost(f, box, prims, level, kLookahead) < leaf;
    }

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
    RestrictedTreePool::Entry treeFor(Fragment& f, const CsgTree& tree, const PrimList& prims) {
        return f.pool.share(prims, SetPool::hashOf(prims), [&](CsgTree& dst) {
            if (restrictor) return reserveTree(prims, f.treeNodes);
            f.treeStart.push_back(dst.nodes.size());
            f.key.assign(prims.begin(), prims.end());
            return restrictTreeTo(tree, f.key, keep.local(), dst);
        });
    }

    /// The leaf over set `list` of `pool`, whose tree's root is `root`.
    static RegularLeaf leafOf(const SetPool& pool, uint32_t list, int root) {
        RegularLeaf leaf;
        leaf.root = root;
        leaf.first = pool.listFirst[list];
        leaf.prims = pool.listFirst[list + 1] - leaf.first;
        if (leaf.prims <= RegularLeaf::kInline)
            std::copy_n(pool.lists.data() + leaf.first, leaf.prims, leaf.inlined);
        return leaf;
    }

    /// The trees of `pool`'s sets, `count` nodes reserved by reserveTree() in the sets' order,
    /// made in parallel: each set's restriction is written at its place, so the nodes are
    /// those that restricting the sets one after the other would append.
    void makeTrees(SetPool& pool, size_t count) {
        std::vector<CsgNode>& nodes = pool.trees.nodes;
        reserveHuge(nodes, count);
        nodes.resize(count);
        const size_t sets = pool.listFirst.size() - 1;
        const uint32_t* lists = pool.lists.data();
        const auto setOf = [&](size_t s) {
            return std::span<const uint32_t>(lists + pool.listFirst[s],
                                             pool.listFirst[s + 1] - pool.listFirst[s]);
        };
        std::vector<size_t> at(sets + 1, 0);
        for (size_t s = 0; s < sets; ++s) at[s + 1] = at[s] + restrictor->unionSize(setOf(s));
        TaskFence fence;
        try {
            tbb::parallel_for(tbb::blocked_range<size_t>(0, sets, 1024),
                              fence.task([&](const auto& r) {
                                  guard.poll();
                                  std::vector<int>& scratch = restrictorScratch.local();
                                  for (size_t s = r.begin(); s != r.end(); ++s)
                                      if (at[s + 1] > at[s])
                                          restrictor->restrictUnions(setOf(s), nodes.data() + at[s],
                                                                     int(at[s]), scratch);
                              }));
        } catch (...) {
            fence.acquire();
            throw;
        }
        fence.acquire();
    }

    void makeLeaf(Fragment& f, int id, int level, const uint32_t pos[3], const CsgTree& tree,
                  const PrimList& prims) {
        const RestrictedTreePool::Entry entry = treeFor(f, tree, prims);
        const uint32_t nprims = uint32_t(prims.size());
        f.emptyLeaves += nprims == 0;
        f.bsp.nodes[size_t(id)].leaf = uint32_t(f.leafList.size());
        f.leafList.push_back(entry.list);
        f.places.push_back({level, {pos[0], pos[1], pos[2]}});
        f.primRefs += nprims;
        f.maxPrims = std::max(f.maxPrims, nprims);
    }

    /// The primitives of `prims` (overlapping `box`) whose boxes overlap the half of `box` on
    /// side `side` of `mid` on `axis`, into `out`.
    void half(const PrimList& prims, int level, const Box3& child, int axis, double mid, int side,
              PrimList& out) const {
        // Below the root every primitive overlaps the cell, which differs from the child on the
        // cut axis alone: the test there is the whole test. Without branches, as the one-pass
        // split writes its lists: each primitive written, the end moved past it when it
        // belongs (a coin toss for the branch predictor).
        out.clear();
        out.resize(prims.size());
        uint32_t* o = out.data();
        const Box3* const boxes = grid.boxes().data();
        if (level == 0) {
            for (uint32_t p : prims) *o = p, o += boxes[p].overlaps(child);
        } else if (side == 0) {
            for (uint32_t p : prims) *o = p, o += coord(boxes[p].lo, axis) <= mid;
        } else {
            for (uint32_t p : prims) *o = p, o += coord(boxes[p].hi, axis) >= mid;
        }
        out.resize(size_t(o - out.data()));
    }

    /// Build child `id` at `level` over the primitives `in` of its cell, restricting `tree` (its
    /// parent's, over `parentPrims`) to them where needed; `sc` holds the child's tree and list.
    void buildChild(Fragment& f, int id, int level, const uint32_t pos[3], const Box3& box,
                    const CsgTree& tree, const PrimList& parentPrims, const PrimList& in,
                    CsgTree& sub, PrimList& live) {
        if (in.size() == parentPrims.size()) {
            // Every primitive overlaps the child: the restriction is this tree, whose
            // primitives all count (`prims` are the live ones).
            build(f, id, level, pos, box, tree, parentPrims);
        } else if (restrictor) {
            // A union's restriction drops no primitive it keeps, so the child needs no tree of
            // its own: its leaves restrict the scene's.
            build(f, id, level, pos, box, tree, in);
        } else {
            sub.nodes.clear();
            f.key.assign(in.begin(), in.end());
            sub.root = restrictTreeTo(tree, f.key, keep.local(), sub);
            if (unionOnly) {
                // Restricting a union drops no primitive it keeps: all of them are live.
                build(f, id, level, pos, box, sub, in);
            } else {
                f.key = sub.primitives();
                sortedUnique(f.key);
                live.assign(f.key.begin(), f.key.end());
                build(f, id, level, pos, box, sub, live);
            }
        }
    }

    /// Node `id` of fragment `f` at `level`, at index pos[a] of its level's grid on each axis,
    /// covering `box`; `prims` (sorted) are the primitives that matter here, `tree` the scene's
    /// tree restricted to them (unused with a restrictor).
    void build(Fragment& f, int id, int level, const uint32_t pos[3], const Box3& box,
               const CsgTree& tree, const PrimList& prims) {
        const bool few = prims.size() <= size_t(params.objects());
        if (few || level >= maxLevel) {
            ++(few ? f.objectsLeaves : f.levelLeaves);
            makeLeaf(f, id, level, pos, tree, prims);
            return;
        }
        if (nodes.load(std::memory_order_relaxed) + 2 > RegularGrid::kMaxBspNodes)
            throw std::invalid_argument(refusal());
        check(f);
        // A cell inside every one of its primitives' boxes is not split: every sub-cell would
        // hold the same primitives, hence the same tree, so splitting only adds leaves. (The
        // report stops at max-objects or max-level only; cells inside the overlap of more than
        // max-objects boxes would then split down to max-level: millions of identical leaves.)
        if (coveredByAll(grid.boxes(), prims, box)) {
            ++f.coveredLeaves;
            makeLeaf(f, id, level, pos, tree, prims);
            return;
        }
        // Middle cut on the level's axis, in the grid's own plane coordinates.
        const int axis = grid.schedule_.axis(level);
        const int cuts = grid.schedule_.cuts(level, axis);
        const double mid = planeAt(axis, 2 * pos[axis] + 1, cuts + 1);
        // The children's lists and trees, kept per level so that their memory is reused: a
        // child's own children use the next level's.
        Scratch& sc = f.scratch[size_t(level) + 1];
        // Below the root, where the cost estimate's middle (the box's) is the grid plane, one
        // pass over the primitives makes both children's lists and the estimate's sums (the
        // same comparisons, the same sums); elsewhere the estimate and the lists are made apart.
        const bool onePass = level > 0 && 0.5 * (box.lo[axis] + box.hi[axis]) == mid;
        if (onePass) {
            double tests[2] = {0.0, 0.0}, all = 0.0;
            // Without branches (a primitive's side of the cut is a coin toss for the branch
            // predictor): each primitive is written to both lists, each list's end moving past
            // it when it belongs there, and its weight added, or +0, which leaves a sum of
            // non-negative weights bit for bit as it was. Weights all 1 (spheres) sum to counts.
            PrimList &in0 = sc.in[0], &in1 = sc.in[1];
            in0.resize(prims.size());
            in1.resize(prims.size());
            uint32_t *lo = in0.data(), *hi = in1.data();
            const Box3* const boxes = grid.boxes().data();
            if (unitWeights) {
                for (uint32_t p : prims) {
                    const Box3& b = boxes[p];
                    *lo = p, lo += coord(b.lo, axis) <= mid;
                    *hi = p, hi += coord(b.hi, axis) >= mid;
                }
                all = double(prims.size());
                tests[0] = double(lo - in0.data());
                tests[1] = double(hi - in1.data());
            } else {
                // In quarters (testQuarters()): the double sums exactly.
                uint64_t q[2] = {0, 0}, qAll = 0;
                const uint32_t* const weights = quarters.data();
                for (uint32_t p : prims) {
                    const Box3& b = boxes[p];
                    const uint64_t w = weights[p];
                    const bool l = coord(b.lo, axis) <= mid, h = coord(b.hi, axis) >= mid;
                    qAll += w;
                    *lo = p, lo += l;
                    *hi = p, hi += h;
                    q[0] += w & (uint64_t(0) - uint64_t(l));
                    q[1] += w & (uint64_t(0) - uint64_t(h));
                }
                all = double(qAll) * 0.25;
                tests[0] = double(q[0]) * 0.25;
                tests[1] = double(q[1]) * 0.25;
            }
            in0.resize(size_t(lo - in0.data()));
            in1.resize(size_t(hi - in1.data()));
            // A split that does not lower the estimated cost within kLookahead levels is not
            // made (splitPays(), its first estimate from these sums).
            const double leaf = params.stepCost + params.testCost * all;
            const double split = splitCostOf(box, axis, mid, tests, all);
            if (params.usesCostStop()) {
                const bool gainStop = belowGainFloor(level, box, leaf - split);
                if (gainStop ||
                    !(split < leaf || splitCost(f, box, prims, level, kLookahead) < leaf)) {
                    ++f.costLeaves;
                    f.gainLeaves += gainStop;
                    makeLeaf(f, id, level, pos, tree, prims);
                    return;
                }
            }
        } else if (bool gainStop = false;
                   params.usesCostStop() && !splitPays(f, box, prims, level, gainStop)) {
            ++f.costLeaves;
            f.gainLeaves += gainStop;
            makeLeaf(f, id, level, pos, tree, prims);
            return;
        }
        // The node count only grows: a build over the limit passes it at some split whatever
        // the order the tasks make them in.
        if (nodes.fetch_add(2, std::memory_order_relaxed) + 2 > RegularGrid::kMaxBspNodes)
            throw std::invalid_argument(refusal());
        const int first = int(f.bsp.nodes.size());
        f.bsp.nodes.resize(f.bsp.nodes.size() + 2);
        f.bsp.nodes[size_t(id)].first = first;
        Box3 child[2] = {box, box};
        child[0].hi[axis] = child[1].lo[axis] = mid;
        uint32_t cpos[2][3] = {{pos[0], pos[1], pos[2]}, {pos[0], pos[1], pos[2]}};
        cpos[0][axis] = 2 * pos[axis];
        cpos[1][axis] = 2 * pos[axis] + 1;
        uint8_t height = 0;
        if (prims.size() >= RegularGrid::kTaskPrims) {
            // The halves as tasks, each into a fragment of its own linked from its node.
            Fragment* kid[2];
            for (int side = 0; side < 2; ++side) {
                f.bsp.nodes[size_t(first + side)] = {kLinked, uint32_t(f.children.size()), 0};
                f.children.push_back(std::make_unique<Fragment>(maxLevel));
                kid[side] = f.children.back().get();
            }
            tbb::task_group tasks;
            TaskFence fence;
            for (int side = 0; side < 2; ++side)
                tasks.run(fence.task([&, side] {
                    Fragment& k = *kid[side];
                    if (!onePass) half(prims, level, child[side], axis, mid, side, k.in);
                    buildChild(k, 0, level + 1, cpos[side], child[side], tree, prims,
                               onePass ? sc.in[side] : k.in, k.sub, k.live);
                    k.releaseScratch();
                }));
            try {
                tasks.wait();
            } catch (...) {
                fence.acquire();  // the fragments are freed as the exception unwinds
                throw;
            }
            fence.acquire();
            for (Fragment* k : kid) height = std::max<uint8_t>(height, k->bsp.nodes[0].height + 1);
        } else {
            for (int side = 0; side < 2; ++side) {
                if (!onePass) half(prims, level, child[side], axis, mid, side, sc.in[side]);
                buildChild(f, first + side, level + 1, cpos[side], child[side], tree, prims,
                           sc.in[side], sc.sub, sc.live);
                height = std::max<uint8_t>(height, f.bsp.nodes[size_t(first + side)].height + 1);
            }
        }
        f.bsp.nodes[size_t(id)].height = height;
    }

    /// The structure laid out from the fragments, in the serial build's order.
    struct Layout {
        BspNodes bsp;
        std::vector<RegularLeaf> leaves;
        std::vector<LeafPlace> places;
        SetPool pool;
        size_t treeNodes = 0;  ///< with a restrictor, the trees' nodes (see makeTrees)
    };

    /// Node `i` of fragment `f` as node `g` of the layout, and its subtree.
    void layOut(Layout& out, Fragment& f, size_t i, size_t g) {
        const BspNodes::Node n = f.bsp.nodes[i];
        if (n.first == kLinked) return layOut(out, *f.children[n.leaf], 0, g);
        if (n.first >= 0) {
            const size_t first = out.bsp.nodes.size();
            out.bsp.nodes.resize(first + 2);
            out.bsp.nodes[g] = {int32_t(first), 0, n.height};
            layOut(out, f, size_t(n.first), first);
            layOut(out, f, size_t(n.first) + 1, first + 1);
            return;
        }
        if (out.leaves.size() % 4096 == 0) guard.poll();
        // The leaf's set: placed in the layout's pool where the serial build first met it,
        // its tree moved to the end of the layout's trees.
        if (f.placed.empty()) f.placed.assign(f.pool.listFirst.size() - 1, {-1, kUnplaced});
        const uint32_t set = f.leafList[n.leaf];
        if (f.placed[set].list == kUnplaced) {
            const std::span<const uint32_t> prims = f.pool.set(set);
            f.placed[set] = out.pool.share(prims, f.pool.hashes[set], [&](CsgTree& dst) {
                if (restrictor) return reserveTree(prims, out.treeNodes);
                const size_t begin = f.treeStart[set];
                const size_t end =
                    set + 1 < f.treeStart.size() ? f.treeStart[set + 1] : f.pool.trees.nodes.size();
                const int shift = int(dst.nodes.size()) - int(begin);
                for (size_t k = begin; k < end; ++k) {
                    CsgNode c = f.pool.trees.nodes[k];
                    if (c.op != Op::Primitive) c.left += shift, c.right += shift;
                    dst.nodes.push_back(c);
                }
                return f.pool.roots[set] < 0 ? -1 : f.pool.roots[set] + shift;
            });
        }
        out.bsp.nodes[g] = {-1, uint32_t(out.leaves.size()), 0};
        out.leaves.push_back(leafOf(out.pool, f.placed[set].list, f.placed[set].root));
        out.places.push_back(f.places[n.leaf]);
    }

    /// Room in the layout for what the fragments under `f` hold (an upper bound for the pool,
    /// whose sets the fragments may share): a vector grown by doubling touches twice its final
    /// memory, and on the machines measured a first touch of a page costs more than the copy.
    static void reserve(const Fragment& f, size_t& leaves, size_t& nodes, size_t& trees,
                        size_t& lists, size_t& sets) {
        leaves += f.leafList.size();
        nodes += f.bsp.nodes.size();
        trees += f.pool.trees.nodes.size();
        lists += f.pool.lists.size();
        sets += f.pool.listFirst.size();
        for (const auto& k : f.children) reserve(*k, leaves, nodes, trees, lists, sets);
    }
    static void reserve(Layout& out, const Fragment& root) {
        size_t leaves = 0, nodes = 0, trees = 0, lists = 0, sets = 0;
        reserve(root, leaves, nodes, trees, lists, sets);
        reserveHuge(out.leaves, leaves);
        reserveHuge(out.places, leaves);
        reserveHuge(out.bsp.nodes, nodes);
        reserveHuge(out.pool.trees.nodes, trees);
        reserveHuge(out.pool.lists, lists);
        reserveHuge(out.pool.listFirst, sets);
        reserveHuge(out.pool.roots, sets);
        reserveHuge(out.pool.hashes, sets);
    }

    /// Every fragment's counters added into `f`'s.
    static void addCounters(Fragment& f, const Fragment& from) {
        for (const auto& k : from.children) {
            addCounters(f, *k);
            f.primRefs += k->primRefs;
            f.maxPrims = std::max(f.maxPrims, k->maxPrims);
            f.emptyLeaves += k->emptyLeaves;
            f.coveredLeaves += k->coveredLeaves;
            f.costLeaves += k->costLeaves;
            f.gainLeaves += k->gainLeaves;
            f.objectsLeaves += k->objectsLeaves;
            f.levelLeaves += k->levelLeaves;
        }
    }
};

RegularGrid::RegularGrid(const Scene& scene, const RegularConfig& params, BuildGuard* guardIn)
    : scene_(&scene), exact_(params.step == StepMethod::Exact) {
    // A union-only tree restricts to unions: every leaf's spans are its primitives' merged.
    unionOnly_ = scene.tree.unionOnly();
    BuildGuard ownGuard;
    BuildGuard& guard = guardIn ? *guardIn : ownGuard;
    if (params.maxLevel < 0 || params.maxLevel > 48)
        throw std::invalid_argument("--max-level " + std::to_string(params.maxLevel) +
                                    ": must be in 0..48 for the regular scheme (0: automatic)");
    if (params.maxObjects < 1 && params.maxObjects != kAutoObjects)
        throw std::invalid_argument("--max-objects " + std::to_string(params.maxObjects) +
                                    ": must be at least 1 for the regular scheme (or auto)");
    if (!exact_ && !(params.delta > 0.0 && params.delta < 1.0))
        throw std::invalid_argument("--delta " + std::to_string(params.delta) +
                                    ": must be in (0, 1) (relative to the scene size)");

    // The frame: a turned subtree's where its boxes are much smaller (grid_frame.h).
    Box3 bounds = scene.bounds;
    nlohmann::json frameStats = {{"turned", false}};
    if (params.turnedFrame) {
        FrameChoice fc = chooseGridFrame(scene);
        frameStats["candidates"] = fc.candidates;
        frameStats["world_box_area"] = fc.worldArea;
        frameStats["frame_box_area"] = fc.frameArea;
        if (fc.frame.turned) {
            frame_ = fc.frame;
            frameBoxes_ = std::move(fc.boxes);
            bounds = fc.bounds;
            frameStats["turned"] = true;
            for (int a = 0; a < 3; ++a)
                frameStats["axes"].push_back(
                    {frame_.axes[a].x, frame_.axes[a].y, frame_.axes[a].z});
        }
    }
    // The grid box: the scene bounds, widened where they are flat so every axis can be cut.
    box_ = bounds.isEmpty() ? Box3{Vec3(-1.0), Vec3(1.0)} : bounds;
    Vec3 e = box_.extent();
    double largest = std::max({e.x, e.y, e.z});
    double pad = largest > 0.0 ? 1e-3 * largest
                               : 1e-6 * std::max({1.0, glm::length(box_.lo), glm::length(box_.hi)});
    for (int a = 0; a < 3; ++a)
        if (!(e[a] > 0.0)) box_.lo[a] -= pad, box_.hi[a] += pad;
    ext_ = box_.extent();
    double hair = 1e-9 * (std::max({ext_.x, ext_.y, ext_.z}) +
                          std::max(glm::length(box_.lo), glm::length(box_.hi)));
    clipBox_ = {box_.lo - Vec3(hair), box_.hi + Vec3(hair)};
    delta_ = params.delta * std::max({ext_.x, ext_.y, ext_.z});

    // Build the BSP.
    std::vector<uint32_t> live =
        scene.tree.empty() ? std::vector<uint32_t>{} : scene.tree.primitives();
    sortedUnique(live);
    RegularBuilder b(scene, params, *this, guard, live.size());
    if (params.splitAxes == SplitAxes::Cost)
        schedule_ =
            planSchedule(boxes(), box_, live, b.quarters, b.maxLevel, params.objects(), guard);
    b.setGainArea();
    const uint32_t origin[3] = {0, 0, 0};
    RegularBuilder::Fragment root(b.maxLevel);
    b.build(root, 0, 0, origin, box_, scene.tree, PrimList(live.begin(), live.end()));
    RegularBuilder::addCounters(root, root);
    // One fragment is the serial build's structure as it is; several are laid out in its order.
    RegularBuilder::Layout out;
    if (root.children.empty()) {
        out.bsp = std::move(root.bsp);
        reserveHuge(out.leaves, root.leafList.size());
        for (const uint32_t set : root.leafList)
            out.leaves.push_back(RegularBuilder::leafOf(root.pool, set, root.pool.roots[set]));
        out.places = std::move(root.places);
        out.pool = std::move(root.pool);
        out.treeNodes = root.treeNodes;
    } else {
        RegularBuilder::reserve(out, root);
        out.bsp.nodes.resize(1);
        b.layOut(out, root, 0, 0);
        root.children.clear();  // laid out: their memory is free for what follows
    }
    if (b.restrictor) b.makeTrees(out.pool, out.treeNodes);
    leaves_ = std::move(out.leaves);
    pool_ = std::move(out.pool.trees);
    primList_ = std::move(out.pool.lists);
    const BspNodes& bsp = out.bsp;

    // The finest level reached fixes the directory's resolution, 2^n per axis.
    const int finest = bsp.nodes[0].height;
    int depth[3];
    for (int a = 0; a < 3; ++a) {
        depth[a] = schedule_.cuts(finest, a);
        n_[a] = 1u << depth[a];
        scale_[a] = double(n_[a]) / ext_[a];
        // The builder's cut planes at the finest level (the last one exactly max).
        planes_[a].resize(size_t(n_[a]) + 1);
        for (uint32_t k = 0; k <= n_[a]; ++k) planes_[a][k] = b.planeAt(a, k, depth[a]);
    }
    for (size_t i = 0; i < leaves_.size(); ++i) {
        const RegularBuilder::LeafPlace& pl = out.places[i];
        for (int a = 0; a < 3; ++a) {
            int shift = depth[a] - schedule_.cuts(pl.level, a);
            RegularLeaf& L = leaves_[i];
            L.lo[a] = pl.pos[a] << shift;
            L.hi[a] = (pl.pos[a] + 1) << shift;
            L.plane[a] = planes_[a][L.lo[a]];
            L.plane[3 + a] = planes_[a][L.hi[a]];
        }
    }
    // Longest exact walk: one step per grid plane crossed, plus degenerate steps at edges.
    maxSteps_ = 4 * (size_t(n_[0]) + n_[1] + n_[2]) + 16;

    // The directory: estimated before it is allocated.
    const bool full = params.fullTable;
    const size_t fullBytes = Directory::estimateBytes(bsp, finest, true);
    const size_t dirBytes = full ? fullBytes : Directory::estimateBytes(bsp, finest, false);
    const size_t otherBytes = memoryBytes();  // everything but the directory, not built yet
    const size_t budget = guard.budget();
    if (dirBytes > budget || dirBytes + otherBytes > budget) {
        std::string what = full ? "--full-table" : "--max-level " + std::to_string(b.maxLevel);
        throw std::invalid_argument(
            what + ": the regular directory at level " + std::to_string(finest) + " would take " +
            (dirBytes == SIZE_MAX ? std::string("2^") + std::to_string(finest + 2) + " bytes"
                                  : formatBytes(dirBytes)) +
            ", over the memory budget of " + guard.describe() + " (--memory-budget)" +
            (full ? "; use sub-tables (drop --full-table)" : "; lower --max-level"));
    }
    guard.poll();
    dir_.build(bsp, schedule_, finest, full, &guard);

    // Ropes: across each face, the cell at the face's low corner names the neighbour leaf; it is
    // the only one when it covers the face on the other two axes.
    // Each leaf's own ropes, from the directory: independent, so in parallel.
    const auto ropes = [&](const tbb::blocked_range<size_t>& r) {
        guard.poll();
        for (size_t i = r.begin(); i != r.end(); ++i) {
            RegularLeaf& L = leaves_[i];
            for (int a = 0; a < 3; ++a) {
                for (int side = 0; side < 2; ++side) {
                    uint32_t& rope = L.rope[2 * a + side];
                    if (side ? L.hi[a] == n_[a] : L.lo[a] == 0) {
                        rope = kBorder;
                        continue;
                    }
                    uint32_t c[3] = {L.lo[0], L.lo[1], L.lo[2]};
                    c[a] = side ? L.hi[a] : L.lo[a] - 1;
                    const uint32_t nb = dir_.lookup(c[0], c[1], c[2]);
                    const RegularLeaf& N = leaves_[nb];
                    bool covers = true;
                    for (int o = 0; o < 3; ++o)
                        if (o != a && (N.lo[o] > L.lo[o] || N.hi[o] < L.hi[o])) covers = false;
                    rope = covers ? nb : kSplitFace;
                }
            }
        }
    };
    TaskFence fence;
    try {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves_.size(), 4096), fence.task(ropes));
    } catch (...) {
        fence.acquire();
        throw;
    }
    fence.acquire();

    // The quads are a copy the walk reads instead of the spheres: made only within the budget
    // (the walk tests the spheres themselves without them), and said so in --stats.
    const size_t quadBytes = (primList_.size() + 3) / 4 * sizeof(SphereQuad);
    const bool quadsFit = memoryBytes() + quadBytes <= guard.budget();
    if (unionOnly_ && quadsFit) makeSphereQuads();

    extra_ = {
        {"directory", full ? "full" : "sub-tables"},
        {"directory_bytes", dir_.memoryBytes()},
        {"full_table_bytes",
         fullBytes == SIZE_MAX ? nlohmann::json(nullptr) : nlohmann::json(fullBytes)},
        {"sub_tables", dir_.tableCount()},
        {"leaves", leaves_.size()},
        {"empty_leaves", root.emptyLeaves},
        {"covered_leaves", root.coveredLeaves},
        {"cost_leaves", root.costLeaves},
        {"gain_leaves", root.gainLeaves},
        // Why each leaf's cell was not split (docs/regular.md, "Stop reasons"): covered cells,
        // whose parts would all hold the same primitives, count as cost; a build over its memory
        // budget is refused, never stopped.
        {"stop_reasons",
         {{"max_objects", root.objectsLeaves},
          {"max_level", root.levelLeaves},
          {"cost", root.coveredLeaves + root.costLeaves},
          {"memory", 0}}},
        {"cost_stop", params.usesCostStop()},
        {"effective_max_level", b.maxLevel},
        {"gain_level",
         b.gainLevel < b.maxLevel ? nlohmann::json(b.gainLevel) : nlohmann::json(nullptr)},
        {"bsp_nodes", bsp.nodes.size()},
        {"finest_level", finest},
        {"depth_xyz", {depth[0], depth[1], depth[2]}},
        {"split_axes", splitAxesName(params.splitAxes)},
        {"axis_schedule", schedule_.toString(finest)},
        {"distinct_trees", out.pool.size() - 1},  // the empty set has no tree
        {"tree_pool_nodes", pool_.nodes.size()},
        {"prims_per_leaf", leaves_.empty() ? 0.0 : double(root.primRefs) / double(leaves_.size())},
        {"max_prims_per_leaf", root.maxPrims},
        {"sphere_quad_bytes", quads_.size() * sizeof(SphereQuad)},
    };
    if (unionOnly_ && !quadsFit)
        extra_["sphere_quads_left_out"] = formatBytes(quadBytes) + " would pass the memory budget";
    extra_["frame"] = std::move(frameStats);
}

void RegularGrid::makeSphereQuads() {
    const Scene& scene = *scene_;
    // The world's largest coordinate in the grid (the quads test world points): the largest of
    // its corners' coordinates, which along the world's axes is the box's own.
    quadScale_ = 0.0;
    for (int c = 0; c < 8; ++c) {
        const Vec3 w = glm::abs(frame_.toWorld(boxCorner(clipBox_, c)));
        quadScale_ = std::max({quadScale_, w.x, w.y, w.z});
    }
    // A centre and the walk's point in floats are each off by 2^-24 of the largest coordinate:
    // the radius is grown by ten times their sum, and by ten times the floats' relative
    // rounding of the comparison.
    const double grow = 1e-6 * quadScale_;
    bool spheres = false;
    reserveHuge(quads_, (primList_.size() + 3) / 4);
    quads_.assign((primList_.size() + 3) / 4, SphereQuad{});
    for (size_t i = 0; i < primList_.size(); ++i) {
        const uint32_t p = primList_[i];
        SphereQuad& q = quads_[i / 4];
        const size_t j = i % 4;
        const bool packed = p < scene.packedSpheres.size() && scene.packedSpheres[p].r >= 0.0;
        if (!packed) {
            q.x[j] = q.y[j] = q.z[j] = 0.0f;
            q.r[j] = std::numeric_limits<float>::infinity();
            continue;
        }
        const PackedSphere& s = scene.packedSpheres[p];
        spheres = true;
        q.x[j] = float(s.c.x), q.y[j] = float(s.c.y), q.z[j] = float(s.c.z);
        const double r = s.r * (1.0 + 4e-6) + grow;
        // The next float up, as std::nextafter toward infinity gives it for a finite r >= 0
        // (its bits plus one; a call per sphere was a tenth of the quads' instructions).
        const float f = float(r);
        q.r[j] = f < std::numeric_limits<float>::infinity()
                     ? std::bit_cast<float>(std::bit_cast<uint32_t>(f) + 1u)
                     : f;
    }
    if (!spheres) quads_.clear();
}

std::string RegularGrid::describeLeaf(uint32_t id) const {
    const RegularLeaf& L = leaves_.at(id);
    std::string out = "leaf " + std::to_string(id) + " cells ";
    Box3 box;
    for (int a = 0; a < 3; ++a) {
        out += (a ? "x[" : "[") + std::to_string(L.lo[a]) + "," + std::to_string(L.hi[a]) + ")";
        box.lo[a] = plane(a, L.lo[a]);
        box.hi[a] = plane(a, L.hi[a]);
    }
    CsgTree tree;
    tree.nodes = pool_.nodes;  // toString walks from root: a copy keeps this const
    tree.root = L.root;
    return out + " " + box.toString() + " " + std::to_string(L.prims) + " prims " + tree.toString();
}

}  // namespace lancer
