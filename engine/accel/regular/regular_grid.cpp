#include "engine/accel/regular/regular_grid.h"

#include <span>
#include <stdexcept>

#include "engine/accel/accelerator.h"
#include "engine/accel/build_guard.h"
#include "engine/model/restriction.h"
#include "engine/util/format.h"

namespace lancer {

namespace {

void sortedUnique(std::vector<uint32_t>& v) {
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// A cell inside every one of its primitives' boxes: every sub-cell would hold the same
/// primitives, hence the same tree, so it is not split.
bool coveredByAll(const Scene& scene, std::span<const uint32_t> prims, const Box3& cell) {
    for (uint32_t p : prims) {
        const Box3& b = scene.minBox[p];
        if (!(b.lo.x <= cell.lo.x && b.lo.y <= cell.lo.y && b.lo.z <= cell.lo.z &&
              b.hi.x >= cell.hi.x && b.hi.y >= cell.hi.y && b.hi.z >= cell.hi.z))
            return false;
    }
    return true;
}

/// What testing each primitive costs, in sphere tests: a polygon's inside test loops over its
/// edges, so it weighs 1 + vertices / 4 (on gears, whose faces have up to 144 vertices, weighing
/// every test alike made the planner cut x and y first, for 34% more instructions than x, y, z in
/// turn).
std::vector<double> testWeights(const Scene& scene) {
    std::vector<double> w(scene.prims.size(), 1.0);
    for (size_t i = 0; i < w.size(); ++i)
        if (const Polygon* pg = std::get_if<Polygon>(&scene.prims[i].shape))
            w[i] = 1.0 + double(pg->p.size()) / 4.0;
    return w;
}

/// Surface area of a box.
double area(const Box3& b) {
    const Vec3 e = b.extent();
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

/// Levels --split-axes cost plans (4 cuts per axis on a cube: they fix the cells' shape); deeper
/// ones cut the longest axis of the level's cells, as the report's order
/// does on a cube. Planning every level cost up to 40% more build time on scenes of thousands of
/// triangles that stay above max-objects around shared vertices (tetra), for the same counters
/// within 2%; 12 levels cost 1-3% more build instructions, and balls4 14% fewer.
constexpr int kPlannedLevels = 12;

/// The axes of --split-axes cost, planned level by level over the primitives' minimized boxes
/// alone (no CSG restriction, so a little pessimistic). Every cell of a level has the same
/// surface area A(axis) once cut on `axis`, so with the surface area heuristic the next level
/// costs A(axis) x (2 visits + the tests of the primitive references) per cut cell; the cheapest
/// axis is cut, ties going to x, then y; a test weighs as testWeights() says. Cells stop as in
/// the build: at most max-objects primitives, or covered by all their boxes. On a cube of
/// evenly spread primitives this is the report's x, y, z; on a flat scene (balls4: 24 x 24 x 1.5)
/// it cuts x and y until the cells are about cubes, where the report's order makes them 16 times
/// flatter than wide.
AxisSchedule planSchedule(const Scene& scene, const Box3& box, const std::vector<uint32_t>& live,
                          const std::vector<double>& cost, int maxLevel, int maxObjects,
                          const BuildGuard& guard) {
    // The cells of a level, their primitives in one array: cell c holds refs[begin, end).
    struct Cell {
        Box3 box;
        size_t begin, end;
    };
    std::vector<Cell> cells{{box, 0, live.size()}}, next;
    std::vector<uint32_t> refs(live), nextRefs;
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
        size_t open = 0;
        for (const Cell& c : cells)
            if (c.end - c.begin > size_t(maxObjects) &&
                !coveredByAll(scene, {refs.data() + c.begin, c.end - c.begin}, c.box))
                cells[open++] = c;
        cells.resize(open);
        if (cells.empty()) break;
        double best = kInf;
        int axis = 0;
        for (int a = 0; a < 3; ++a) {
            Vec3 child = size;
            child[a] *= 0.5;
            const double area = child.x * child.y + child.y * child.z + child.z * child.x;
            double tests = 0.0;
            guard.poll();
            for (const Cell& c : cells) {
                const double mid = 0.5 * (c.box.lo[a] + c.box.hi[a]);
                for (size_t i = c.begin; i < c.end; ++i) {
                    const Box3& b = scene.minBox[refs[i]];
                    tests += cost[refs[i]] * double(int(b.lo[a] <= mid) + int(b.hi[a] >= mid));
                }
            }
            const double total = area * (2.0 * double(cells.size()) + tests);
            if (total < best) best = total, axis = a;
        }
        axes.push_back(axis);
        size[axis] *= 0.5;
        next.clear();
        nextRefs.clear();
        for (const Cell& c : cells) {
            const double mid = 0.5 * (c.box.lo[axis] + c.box.hi[axis]);
            for (int side = 0; side < 2; ++side) {
                Cell child{c.box, nextRefs.size(), 0};
                (side ? child.box.lo : child.box.hi)[axis] = mid;
                for (size_t i = c.begin; i < c.end; ++i) {
                    const Box3& b = scene.minBox[refs[i]];
                    if (side ? b.hi[axis] >= mid : b.lo[axis] <= mid) nextRefs.push_back(refs[i]);
                }
                child.end = nextRefs.size();
                next.push_back(child);
            }
        }
        cells.swap(next);
        refs.swap(nextRefs);
    }
    return AxisSchedule(axes);
}

}  // namespace

/// Builds the BSP depth first. Each node's restricted tree is restricted again for its children
/// (restriction composes: restricting to P then to Q ⊆ P equals restricting to Q), so a node
/// costs the size of its parent's small tree, not of the scene's tree.
struct RegularBuilder {
    /// Levels the split decision looks ahead: one cut per axis. A cut through a cell crossed by
    /// bars parallel to it (the sponge's) separates nothing, while the cuts across them do; a
    /// decision on one level would stop there.
    static constexpr int kLookahead = 3;

    const Scene& scene;
    const RegularConfig& params;
    RegularGrid& grid;
    BuildGuard& guard;
    int maxLevel;                ///< params.maxLevel, or the automatic one
    std::vector<double> weight;  ///< each primitive's test, in sphere tests (testWeights)
    BspNodes bsp;
    std::vector<char> keep;   ///< membership marks, all 0 between uses
    RestrictedTreePool pool;  ///< the leaves' trees and lists, moved to the grid at the end
    struct LeafPlace {
        int level;
        uint32_t pos[3];
    };
    std::vector<LeafPlace> places;
    /// The scene's tree has only unions: a restriction then keeps every primitive it is given.
    bool unionOnly = false;
    struct Scratch {
        std::vector<uint32_t> in, live;
        CsgTree sub;
    };
    std::vector<Scratch> scratch = {};  ///< per level, for the children of a node there
    std::vector<uint32_t> look[kLookahead + 1] = {};  ///< the cost estimate's lists, per depth
    uint64_t primRefs = 0;
    uint32_t maxPrims = 0;
    size_t emptyLeaves = 0;
    size_t coveredLeaves = 0;  ///< leaves stopped because every box holds the whole cell
    size_t costLeaves = 0;     ///< leaves stopped because no split lowered the estimated cost

    /// Plane `i` of `level`-cut grid on `axis` (i in 0..2^cuts); equal to grid.plane() at the
    /// finest level, since i / 2^c == (i 2^(n-c)) / 2^n exactly in floating point.
    double planeAt(int axis, uint32_t i, int cuts) const {
        return i == (1u << cuts)
                   ? grid.box_.hi[axis]
                   : grid.box_.lo[axis] + grid.ext_[axis] * std::ldexp(double(i), -cuts);
    }

    std::string options() const {
        return "--max-level " + std::to_string(maxLevel) + " --max-objects " +
               std::to_string(params.maxObjects);
    }

    std::string refusal() const {
        return options() + ": the regular subdivision would need more than " +
               std::to_string(RegularGrid::kMaxBspNodes) +
               " BSP nodes, the builder's limit (it keeps a build within seconds and within its "
               "memory budget); lower --max-level or raise --max-objects";
    }

    /// The structure's size so far: what the build has allocated and keeps (vectors by their
    /// capacity) and the pool.
    size_t bytes() const {
        return bsp.nodes.capacity() * sizeof(BspNodes::Node) +
               grid.leaves_.capacity() * sizeof(RegularLeaf) +
               places.capacity() * sizeof(LeafPlace) + pool.bytes();
    }

    /// Cancelled or over the budget: both end the build now.
    void check() {
        const size_t b = bytes();
        guard.poll("regular BSP", b, bsp.nodes.size());
        if (!guard.fits(b))
            throw std::invalid_argument(
                "--memory-budget " + formatBytes(guard.budget()) + ": the regular subdivision at " +
                options() + " passes its memory budget (" + formatBytes(b) + " after " +
                std::to_string(bsp.nodes.size()) +
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
    double splitCost(const Box3& box, std::span<const uint32_t> prims, int level, int depth) {
        const int axis = grid.schedule_.axis(level);
        const double mid = 0.5 * (box.lo[axis] + box.hi[axis]);
        Box3 child[2] = {box, box};
        child[0].hi[axis] = child[1].lo[axis] = mid;
        // The primitives overlap the cell, so a child's test is on the cut axis alone.
        double tests[2] = {0.0, 0.0};
        size_t count[2] = {0, 0};
        for (uint32_t p : prims) {
            const Box3& b = scene.minBox[p];
            if (b.lo[axis] <= mid) tests[0] += weight[p], ++count[0];
            if (b.hi[axis] >= mid) tests[1] += weight[p], ++count[1];
        }
        const double parentArea = area(box);
        double cost = 0.0;
        for (int side = 0; side < 2; ++side) {
            double c = params.stepCost + params.testCost * tests[side];
            if (depth > 1 && level + 1 < maxLevel && count[side] > size_t(params.maxObjects)) {
                std::vector<uint32_t>& in = look[depth];
                in.clear();
                for (uint32_t p : prims)
                    if (side ? scene.minBox[p].hi[axis] >= mid : scene.minBox[p].lo[axis] <= mid)
                        in.push_back(p);
                if (!coveredByAll(scene, in, child[side]))
                    c = std::min(c, splitCost(child[side], in, level + 1, depth - 1));
            }
            cost += area(child[side]) / parentArea * c;
        }
        return cost;
    }

    /// Whether splitting the cell lowers the estimated cost: at once with its children as
    /// leaves (most cells), else with kLookahead levels of splits below.
    bool splitPays(const Box3& box, std::span<const uint32_t> prims, int level) {
        const double leaf = leafCost(prims);
        return splitCost(box, prims, level, 1) < leaf ||
               splitCost(box, prims, level, kLookahead) < leaf;
    }

    /// The tree restricted to `prims` in the shared pool, and their list, added once per set.
    RestrictedTreePool::Entry treeFor(const CsgTree& tree, const std::vector<uint32_t>& prims) {
        return pool.share(prims,
                          [&](CsgTree& dst) { return restrictTreeTo(tree, prims, keep, dst); });
    }

    void makeLeaf(int id, int level, const uint32_t pos[3], RestrictedTreePool::Entry tree,
                  uint32_t nprims) {
        emptyLeaves += nprims == 0;
        bsp.nodes[size_t(id)].leaf = uint32_t(grid.leaves_.size());
        RegularLeaf leaf;
        leaf.root = tree.root;
        leaf.prims = nprims;
        leaf.first = pool.listFirst[tree.list];
        if (nprims <= RegularLeaf::kInline)
            std::copy_n(pool.lists.begin() + leaf.first, nprims, leaf.inlined);
        grid.leaves_.push_back(leaf);
        places.push_back({level, {pos[0], pos[1], pos[2]}});
        primRefs += nprims;
        maxPrims = std::max(maxPrims, nprims);
    }

    /// Node `id` at `level`, at index pos[a] of its level's grid on each axis, covering `box`;
    /// `tree` is the scene's tree restricted to `prims` (sorted), the primitives that matter here.
    void build(int id, int level, const uint32_t pos[3], const Box3& box, const CsgTree& tree,
               const std::vector<uint32_t>& prims) {
        if (prims.size() <= size_t(params.maxObjects) || level >= maxLevel) {
            makeLeaf(id, level, pos, treeFor(tree, prims), uint32_t(prims.size()));
            return;
        }
        if (bsp.nodes.size() + 2 > RegularGrid::kMaxBspNodes)
            throw std::invalid_argument(refusal());
        check();
        // A cell inside every one of its primitives' boxes is not split: every sub-cell would
        // hold the same primitives, hence the same tree, so splitting only adds leaves. (The
        // report stops at max-objects or max-level only; cells inside the overlap of more than
        // max-objects boxes would then split down to max-level: millions of identical leaves.)
        if (coveredByAll(scene, prims, box)) {
            ++coveredLeaves;
            makeLeaf(id, level, pos, treeFor(tree, prims), uint32_t(prims.size()));
            return;
        }
        // A split that does not lower the estimated cost within kLookahead levels is not made.
        if (params.costStop && !splitPays(box, prims, level)) {
            ++costLeaves;
            makeLeaf(id, level, pos, treeFor(tree, prims), uint32_t(prims.size()));
            return;
        }
        // Middle cut on the level's axis, in the grid's own plane coordinates.
        const int axis = grid.schedule_.axis(level);
        const int cuts = grid.schedule_.cuts(level, axis);
        double mid = planeAt(axis, 2 * pos[axis] + 1, cuts + 1);
        int first = int(bsp.nodes.size());
        bsp.nodes.resize(bsp.nodes.size() + 2);
        bsp.nodes[size_t(id)].first = first;
        uint8_t height = 0;
        // The children's lists and trees, kept per level so that their memory is reused: a
        // child's own children use the next level's.
        Scratch& sc = scratch[size_t(level) + 1];
        for (int side = 0; side < 2; ++side) {
            Box3 child = box;
            (side ? child.lo : child.hi)[axis] = mid;
            // Primitives whose minimized boxes overlap the closed child box, then the tree
            // restricted to them; a primitive the restriction drops cannot contribute here.
            sc.in.clear();
            for (uint32_t p : prims)
                if (scene.minBox[p].overlaps(child)) sc.in.push_back(p);
            uint32_t cpos[3] = {pos[0], pos[1], pos[2]};
            cpos[axis] = 2 * pos[axis] + uint32_t(side);
            if (sc.in.size() == prims.size()) {
                // Every primitive overlaps the child: the restriction is this tree, whose
                // primitives all count (`prims` are the live ones).
                build(first + side, level + 1, cpos, child, tree, prims);
            } else {
                sc.sub.nodes.clear();
                sc.sub.root = restrictTreeTo(tree, sc.in, keep, sc.sub);
                if (unionOnly) {
                    // Restricting a union drops no primitive it keeps: all of them are live.
                    build(first + side, level + 1, cpos, child, sc.sub, sc.in);
                } else {
                    sc.live = sc.sub.primitives();
                    sortedUnique(sc.live);
                    build(first + side, level + 1, cpos, child, sc.sub, sc.live);
                }
            }
            height = std::max<uint8_t>(height, bsp.nodes[size_t(first + side)].height + 1);
        }
        bsp.nodes[size_t(id)].height = height;
    }
};

RegularGrid::RegularGrid(const Scene& scene, const RegularConfig& params, BuildGuard* guardIn)
    : scene_(&scene), exact_(params.step == StepMethod::Exact) {
    // A union-only tree restricts to unions: every leaf's spans are its primitives' merged.
    unionOnly_ =
        std::all_of(scene.tree.nodes.begin(), scene.tree.nodes.end(),
                    [](const CsgNode& n) { return n.op == Op::Primitive || n.op == Op::Union; });
    BuildGuard ownGuard;
    BuildGuard& guard = guardIn ? *guardIn : ownGuard;
    if (params.maxLevel < 0 || params.maxLevel > 48)
        throw std::invalid_argument("--max-level " + std::to_string(params.maxLevel) +
                                    ": must be in 0..48 for the regular scheme (0: automatic)");
    if (params.maxObjects < 1)
        throw std::invalid_argument("--max-objects " + std::to_string(params.maxObjects) +
                                    ": must be at least 1");
    if (!exact_ && !(params.delta > 0.0 && params.delta < 1.0))
        throw std::invalid_argument("--delta " + std::to_string(params.delta) +
                                    ": must be in (0, 1) (relative to the scene size)");

    // The grid box: the scene bounds, widened where they are flat so every axis can be cut.
    box_ = scene.bounds.isEmpty() ? Box3{Vec3(-1.0), Vec3(1.0)} : scene.bounds;
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
    RegularBuilder b{scene,
                     params,
                     *this,
                     guard,
                     effectiveMaxLevel(params, live.size()),
                     testWeights(scene),
                     {},
                     std::vector<char>(scene.prims.size(), 0),
                     {},
                     {}};
    b.bsp.nodes.resize(1);
    b.unionOnly =
        std::all_of(scene.tree.nodes.begin(), scene.tree.nodes.end(),
                    [](const CsgNode& n) { return n.op == Op::Primitive || n.op == Op::Union; });
    b.scratch.resize(size_t(b.maxLevel) + 2);
    if (params.splitAxes == SplitAxes::Cost)
        schedule_ = planSchedule(scene, box_, live, b.weight, b.maxLevel, params.maxObjects, guard);
    const uint32_t origin[3] = {0, 0, 0};
    b.build(0, 0, origin, box_, scene.tree, live);
    pool_ = std::move(b.pool.trees);
    primList_ = std::move(b.pool.lists);

    // The finest level reached fixes the directory's resolution, 2^n per axis.
    const int finest = b.bsp.nodes[0].height;
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
        const RegularBuilder::LeafPlace& pl = b.places[i];
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
    const size_t fullBytes = Directory::estimateBytes(b.bsp, finest, true);
    const size_t dirBytes = full ? fullBytes : Directory::estimateBytes(b.bsp, finest, false);
    const size_t otherBytes = memoryBytes();  // everything but the directory, not built yet
    const size_t budget = guard.budget();
    if (dirBytes > budget || dirBytes + otherBytes > budget) {
        std::string what = full ? "--full-table" : "--max-level " + std::to_string(b.maxLevel);
        throw std::invalid_argument(
            what + ": the regular directory at level " + std::to_string(finest) + " would take " +
            (dirBytes == SIZE_MAX ? std::string("2^") + std::to_string(finest + 2) + " bytes"
                                  : formatBytes(dirBytes)) +
            ", over the memory budget of " + formatBytes(budget) + " (--memory-budget)" +
            (full ? "; use sub-tables (drop --full-table)" : "; lower --max-level"));
    }
    guard.poll();
    dir_.build(b.bsp, schedule_, finest, full);

    // Ropes: across each face, the cell at the face's low corner names the neighbour leaf; it is
    // the only one when it covers the face on the other two axes.
    for (RegularLeaf& L : leaves_) {
        if ((&L - leaves_.data()) % 4096 == 0) guard.poll();
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

    extra_ = {
        {"directory", full ? "full" : "sub-tables"},
        {"directory_bytes", dir_.memoryBytes()},
        {"full_table_bytes",
         fullBytes == SIZE_MAX ? nlohmann::json(nullptr) : nlohmann::json(fullBytes)},
        {"sub_tables", dir_.tableCount()},
        {"leaves", leaves_.size()},
        {"empty_leaves", b.emptyLeaves},
        {"covered_leaves", b.coveredLeaves},
        {"cost_leaves", b.costLeaves},
        {"effective_max_level", b.maxLevel},
        {"bsp_nodes", b.bsp.nodes.size()},
        {"finest_level", finest},
        {"depth_xyz", {depth[0], depth[1], depth[2]}},
        {"split_axes", splitAxesName(params.splitAxes)},
        {"axis_schedule", schedule_.toString(finest)},
        {"distinct_trees", b.pool.size() - 1},  // the empty set has no tree
        {"tree_pool_nodes", pool_.nodes.size()},
        {"prims_per_leaf", leaves_.empty() ? 0.0 : double(b.primRefs) / double(leaves_.size())},
        {"max_prims_per_leaf", b.maxPrims},
    };
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
