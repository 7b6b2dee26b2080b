#include "engine/accel/regular/regular_builder.h"

#include <tbb/task_group.h>

#include <algorithm>
#include <stdexcept>

#include "engine/accel/regular/axis_planner.h"
#include "engine/util/format.h"
#include "engine/util/task_fence.h"

namespace lancer {

namespace {

/// Deepest union-only tree whose leaves are restricted from the scene's tree (64: a balanced
/// union of 2^63 primitives; a chain of unions goes back to the cells' own trees).
constexpr int kRestrictorDepth = 64;

void sortedUnique(std::vector<uint32_t>& v) {
    // A scene's union lists its primitives in order (every format's balanced union): sorting
    // 600,000 of them again took 30 M instructions.
    if (!std::is_sorted(v.begin(), v.end())) std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
}

/// Per primitive of `tree`: whether its solid filling a region leaves the whole tree empty or
/// full there whatever the other primitives do (RegularBuilder::decisive). Top down: a node
/// whose being full (or empty) makes the root empty or full passes that on to the child that
/// would make it so with its sibling unknown.
std::vector<char> decisivePrimitives(const CsgTree& tree, size_t prims) {
    std::vector<char> out(prims, 0);
    if (tree.root < 0) return out;
    // For each node on the stack: whether the node full, and the node empty, settles the root.
    struct Item {
        int node;
        bool full, empty;
    };
    std::vector<uint32_t> leaves(prims, 0);
    std::vector<Item> stack = {{tree.root, true, true}};
    while (!stack.empty()) {
        const Item it = stack.back();
        stack.pop_back();
        const CsgNode& x = tree.nodes[size_t(it.node)];
        if (x.op == Op::Primitive) {
            ++leaves[x.prim];
            out[x.prim] = it.full;
            continue;
        }
        switch (x.op) {
            case Op::Union:  // a full side makes it full, an empty one leaves the other
                stack.push_back({x.left, it.full, false});
                stack.push_back({x.right, it.full, false});
                break;
            case Op::Intersection:  // an empty side makes it empty
                stack.push_back({x.left, false, it.empty});
                stack.push_back({x.right, false, it.empty});
                break;
            default:  // difference: an empty minuend or a full subtrahend empties it
                stack.push_back({x.left, false, it.empty});
                stack.push_back({x.right, it.empty, false});
                break;
        }
    }
    // A primitive with several leaves: one may settle the root, another not.
    for (size_t p = 0; p < prims; ++p)
        if (leaves[p] > 1) out[p] = 0;
    return out;
}

/// The scene tree's primitives, sorted, each once.
std::vector<uint32_t> sortedLivePrimitives(const Scene& scene) {
    std::vector<uint32_t> live =
        scene.tree.empty() ? std::vector<uint32_t>{} : scene.tree.primitives();
    sortedUnique(live);
    return live;
}

}  // namespace

RegularBuilder::RegularBuilder(const Scene& s, const RegularConfig& p, RegularGrid& g,
                               BuildGuard& gd)
    : scene(s),
      params(p),
      grid(g),
      guard(gd),
      live(sortedLivePrimitives(s)),
      maxLevel(effectiveMaxLevel(p, live.size())),
      gainLevel(lancer::gainLevel(p, live.size())),
      weight(regular_build::testWeights(s)),
      quarters(regular_build::testQuarters(weight)),
      unitWeights(std::all_of(weight.begin(), weight.end(), [](float w) { return w == 1.0f; })),
      unionOnly(s.tree.unionOnly()),
      keep([n = s.prims.size()] { return std::vector<char>(n, 0); }) {
    // A leaf's restriction climbs from its primitives to the root: a cost of the tree's
    // depth per primitive, which a balanced union (every scene format makes one) keeps to
    // log2 N.
    if (unionOnly && s.tree.depth() <= kRestrictorDepth) {
        restrictor = std::make_unique<TreeRestrictor>(s.tree);
    }
    const Vec3 e = g.box_.extent();
    solidMargin = 1e-5 * (std::max({e.x, e.y, e.z}) +
                          std::max(glm::length(g.box_.lo), glm::length(g.box_.hi)));
    if (!unionOnly) decisive = decisivePrimitives(s.tree, s.prims.size());
}

RegularBuilder::Fragment RegularBuilder::buildFragments() {
    setGainArea();
    const uint32_t origin[3] = {0, 0, 0};
    Fragment root(maxLevel);
    build(root, 0, 0, origin, grid.box_, scene.tree, PrimList(live.begin(), live.end()));
    return root;
}

std::string RegularBuilder::options() const {
    return "--max-level " + std::to_string(maxLevel) + " --max-objects " +
           std::to_string(params.objects());
}

std::string RegularBuilder::refusal() const {
    return options() + ": the regular subdivision would need more than " +
           std::to_string(RegularGrid::kMaxBspNodes) +
           " BSP nodes, the builder's limit (it keeps a build within seconds and within its "
           "memory budget); lower --max-level or raise --max-objects";
}

void RegularBuilder::check(Fragment& f) {
    const size_t mine = f.bytes();
    const size_t b = bytes.fetch_add(mine - f.reported) + (mine - f.reported);
    f.reported = mine;
    const size_t made = nodes.load(std::memory_order_relaxed);
    guard.poll("regular BSP", b, made);
    if (!guard.fits(b))
        throw std::invalid_argument(
            "--memory-budget " + guard.describe() + ": the regular subdivision at " + options() +
            " passes its memory budget (" + formatBytes(b) + " after " + std::to_string(made) +
            " BSP nodes, with room to grow); lower --max-level, raise --max-objects or raise "
            "--memory-budget");
}

void RegularBuilder::build(Fragment& f, int id, int level, const uint32_t pos[3], const Box3& box,
                           const CsgTree& tree, const PrimList& prims) {
    if (stopsByRule(f, level, box, prims)) return makeLeaf(f, id, level, pos, tree, prims);
    const Cut cut = cutOf(level, pos, box);
    // The children's lists and trees, kept per level so that their memory is reused: a
    // child's own children use the next level's.
    Scratch& sc = f.scratch[size_t(level) + 1];
    // Below the root, where the cost estimate's middle (the box's) is the grid plane, one
    // pass over the primitives makes both children's lists and the estimate's sums (the
    // same comparisons, the same sums); elsewhere the estimate and the lists are made apart.
    const bool onePass = level > 0 && 0.5 * (box.lo[cut.axis] + box.hi[cut.axis]) == cut.mid;
    Estimate first;
    if (onePass)
        first = splitInOnePass(prims, box, cut, sc);
    else if (params.usesCostStop())
        first = estimate(f, box, prims, level);
    if (params.usesCostStop() && stopsByCost(f, box, prims, level, first))
        return makeLeaf(f, id, level, pos, tree, prims);
    split(f, id, level, cut, tree, prims, onePass, sc);
}

bool RegularBuilder::stopsByRule(Fragment& f, int level, const Box3& box, const PrimList& prims) {
    const bool few = prims.size() <= size_t(params.objects());
    if (few || level >= maxLevel) {
        ++(few ? f.counts.objectsLeaves : f.counts.levelLeaves);
        return true;
    }
    if (nodes.load(std::memory_order_relaxed) + 2 > RegularGrid::kMaxBspNodes)
        throw NodeLimitError(refusal());
    check(f);
    // A cell inside every one of its primitives' boxes is not split: every sub-cell would
    // hold the same primitives, hence the same tree, so splitting only adds leaves. (The
    // report stops at max-objects or max-level only; cells inside the overlap of more than
    // max-objects boxes would then split down to max-level: millions of identical leaves.)
    if (regular_build::coveredByAll(grid.boxes(), prims, box)) {
        ++f.counts.coveredLeaves;
        return true;
    }
    return false;
}

RegularBuilder::Cut RegularBuilder::cutOf(int level, const uint32_t pos[3], const Box3& box) const {
    Cut cut;
    // In the grid's own plane coordinates.
    cut.axis = grid.schedule_.axis(level);
    const int cuts = grid.schedule_.cuts(level, cut.axis);
    cut.mid = grid.planeAt(cut.axis, 2 * pos[cut.axis] + 1, cuts + 1);
    for (int side = 0; side < 2; ++side) {
        cut.child[side] = box;
        std::copy_n(pos, 3, cut.pos[side]);
        cut.pos[side][cut.axis] = 2 * pos[cut.axis] + uint32_t(side);
    }
    cut.child[0].hi[cut.axis] = cut.child[1].lo[cut.axis] = cut.mid;
    return cut;
}

RegularBuilder::Estimate RegularBuilder::splitInOnePass(const PrimList& prims, const Box3& box,
                                                        const Cut& cut, Scratch& sc) const {
    const int axis = cut.axis;
    const double mid = cut.mid;
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
    const double leaf = params.stepCost + params.testCost * all;
    if (!decisive.empty()) {
        Box3 child[2] = {box, box};
        child[0].hi[axis] = child[1].lo[axis] = mid;
        double shared = tests[0] + tests[1] - all;
        emptyChildren(prims, child, tests, shared);
        all = tests[0] + tests[1] - shared;
    }
    return {leaf, splitCostOf(box, axis, mid, tests, all)};
}

bool RegularBuilder::emptiedCell(std::span<const uint32_t> prims, const Box3& cell) const {
    for (uint32_t p : prims)
        if (decisive[p] && fills(p, cell)) return true;
    return false;
}

void RegularBuilder::emptyChildren(std::span<const uint32_t> prims, const Box3 child[2],
                                   double tests[2], double& shared) const {
    if (decisive.empty()) return;
    for (int side = 0; side < 2; ++side)
        if (tests[side] > 0.0 && emptiedCell(prims, child[side])) tests[side] = 0.0, shared = 0.0;
}

void RegularBuilder::split(Fragment& f, int id, int level, const Cut& cut, const CsgTree& tree,
                           const PrimList& prims, bool onePass, Scratch& sc) {
    // The node count only grows: a build over the limit passes it at some split whatever
    // the order the tasks make them in.
    if (nodes.fetch_add(2, std::memory_order_relaxed) + 2 > RegularGrid::kMaxBspNodes)
        throw NodeLimitError(refusal());
    const int first = int(f.bsp.nodes.size());
    f.bsp.nodes.resize(f.bsp.nodes.size() + 2);
    f.bsp.nodes[size_t(id)].first = first;
    // The children grow f.bsp.nodes: node `id` is written again only once they are built.
    const uint8_t height = prims.size() >= RegularGrid::kTaskPrims
                               ? splitInTasks(f, first, level, cut, tree, prims, onePass, sc)
                               : splitInPlace(f, first, level, cut, tree, prims, onePass, sc);
    f.bsp.nodes[size_t(id)].height = height;
}

uint8_t RegularBuilder::splitInTasks(Fragment& f, int first, int level, const Cut& cut,
                                     const CsgTree& tree, const PrimList& prims, bool onePass,
                                     Scratch& sc) {
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
            if (!onePass) half(prims, level, cut.child[side], cut.axis, cut.mid, side, k.in);
            buildChild(k, 0, level + 1, cut.pos[side], cut.child[side], tree, prims,
                       onePass ? sc.in[side] : k.in, k.sub, k.live, k.held, k.heldList);
            k.releaseScratch();
        }));
    try {
        tasks.wait();
    } catch (...) {
        fence.acquire();  // the fragments are freed as the exception unwinds
        throw;
    }
    fence.acquire();
    uint8_t height = 0;
    for (Fragment* k : kid) height = std::max<uint8_t>(height, k->bsp.nodes[0].height + 1);
    return height;
}

uint8_t RegularBuilder::splitInPlace(Fragment& f, int first, int level, const Cut& cut,
                                     const CsgTree& tree, const PrimList& prims, bool onePass,
                                     Scratch& sc) {
    uint8_t height = 0;
    for (int side = 0; side < 2; ++side) {
        if (!onePass) half(prims, level, cut.child[side], cut.axis, cut.mid, side, sc.in[side]);
        buildChild(f, first + side, level + 1, cut.pos[side], cut.child[side], tree, prims,
                   sc.in[side], sc.sub, sc.live, sc.held, sc.heldList);
        height = std::max<uint8_t>(height, f.bsp.nodes[size_t(first + side)].height + 1);
    }
    return height;
}

void RegularBuilder::half(const PrimList& prims, int level, const Box3& child, int axis, double mid,
                          int side, PrimList& out) const {
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

void RegularBuilder::buildChild(Fragment& f, int id, int level, const uint32_t pos[3],
                                const Box3& box, const CsgTree& tree, const PrimList& parentPrims,
                                const PrimList& in, CsgTree& sub, PrimList& live, CsgTree& held,
                                PrimList& heldList) {
    const CsgTree* t = &tree;
    const PrimList* prims = &in;
    if (in.size() == parentPrims.size()) {
        // Every primitive overlaps the child: the restriction is this tree, whose
        // primitives all count (`prims` are the live ones).
        prims = &parentPrims;
    } else if (!restrictor) {
        // (With a restrictor, a union's restriction drops no primitive it keeps, so the child
        // needs no tree of its own: its leaves restrict the scene's.)
        sub.nodes.clear();
        f.key.assign(in.begin(), in.end());
        sub.root = restrictTreeTo(tree, f.key, keep.local(), sub);
        t = &sub;
        if (!unionOnly) {
            // Restricting a union drops no primitive it keeps: all of them are live.
            f.key = sub.primitives();
            sortedUnique(f.key);
            live.assign(f.key.begin(), f.key.end());
            prims = &live;
        }
    }
    if (heldWithin(f, box, *t, *prims, held, heldList))
        build(f, id, level, pos, box, held, heldList);
    else
        build(f, id, level, pos, box, *t, *prims);
}

bool RegularBuilder::fills(uint32_t p, const Box3& box) const {
    const Box3 g{box.lo - Vec3(solidMargin), box.hi + Vec3(solidMargin)};
    // The solid lies in its box: a box not holding the cell rules it out at once.
    const Box3& b = grid.boxes()[p];
    if (!(glm::all(glm::lessThanEqual(b.lo, g.lo)) && glm::all(glm::lessThanEqual(g.hi, b.hi))))
        return false;
    const Primitive& prim = scene.prims[p];
    for (int c = 0; c < 8; ++c) {
        const Vec3 w = grid.frame().toWorld(boxCorner(g, c));
        const Vec3 local = prim.hasXf ? Vec3(prim.xf.inv * glm::dvec4(w, 1.0)) : w;
        if (!convexSolidHolds(prim.shape, local)) return false;
    }
    return true;
}

bool RegularBuilder::heldWithin(Fragment& f, const Box3& box, const CsgTree& tree,
                                const PrimList& prims, CsgTree& held, PrimList& heldList) {
    // A union's cells inside a solid hold no boundary, but rays seldom go there (only
    // refracted ones): union-only scenes are not asked (8% more build on balls:5).
    if (unionOnly) return false;
    f.filling.clear();
    for (uint32_t p : prims)
        if (fills(p, box)) f.filling.push_back(p);
    if (f.filling.empty()) return false;
    if (!restrictionWithin(tree, f.filling, f.kept) || f.kept.size() == prims.size()) return false;
    ++f.counts.solidCells;
    held.nodes.clear();
    held.root = -1;
    heldList.clear();
    if (!f.kept.empty()) {
        held.root = restrictTreeTo(tree, f.kept, keep.local(), held);
        heldList.assign(f.kept.begin(), f.kept.end());
    }
    return true;
}

void RegularBuilder::makeLeaf(Fragment& f, int id, int level, const uint32_t pos[3],
                              const CsgTree& tree, const PrimList& prims) {
    const RestrictedTreePool::Entry entry = treeFor(f, tree, prims);
    const uint32_t nprims = uint32_t(prims.size());
    f.counts.emptyLeaves += nprims == 0;
    f.bsp.nodes[size_t(id)].leaf = uint32_t(f.leafList.size());
    f.leafList.push_back(entry.list);
    f.places.push_back({level, {pos[0], pos[1], pos[2]}});
    f.counts.primRefs += nprims;
    f.counts.maxPrims = std::max(f.counts.maxPrims, nprims);
}

RestrictedTreePool::Entry RegularBuilder::treeFor(Fragment& f, const CsgTree& tree,
                                                  const PrimList& prims) {
    return f.pool.share(prims, SetPool::hashOf(prims), [&](CsgTree& dst) {
        if (restrictor) return reserveTree(prims, f.treeNodes);
        f.treeStart.push_back(dst.nodes.size());
        f.key.assign(prims.begin(), prims.end());
        return restrictTreeTo(tree, f.key, keep.local(), dst);
    });
}

// The cost estimate (docs/regular.md, "Cost-driven splits"): whether a split lowers what the rays
// crossing a cell cost. In this file, beside the build that asks it for every cell: in a file of
// its own, its small functions were calls, 2% more instructions in the build of tetra:6.

double RegularBuilder::leafCost(std::span<const uint32_t> prims) const {
    double tests = 0.0;
    for (uint32_t p : prims) tests += weight[p];
    return params.stepCost + params.testCost * tests;
}

double RegularBuilder::splitCost(Fragment& f, const Box3& box, std::span<const uint32_t> prims,
                                 int level, int depth) {
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
    double shared = tests[0] + tests[1] - all;
    emptyChildren(prims, child, tests, shared);
    double cost = -retestSaving(child, parentArea, shared);
    for (int side = 0; side < 2; ++side) {
        double c = params.stepCost + params.testCost * tests[side];
        if (tests[side] == 0.0) count[side] = 0;  // emptied: nothing to look further at
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
            if (!regular_build::coveredByAll(grid.boxes(), in, child[side]))
                c = std::min(c, splitCost(f, child[side], in, level + 1, depth - 1));
        }
        cost += surfaceArea(child[side]) / parentArea * c;
    }
    return cost;
}

double RegularBuilder::retestSaving(const Box3 child[2], double parentArea, double both) const {
    const double crossBoth = (surfaceArea(child[0]) + surfaceArea(child[1])) / parentArea - 1.0;
    return params.testCost * (1.0 - kMailboxHitCost) * both * std::max(crossBoth, 0.0);
}

double RegularBuilder::splitCostOf(const Box3& box, int axis, double mid, const double tests[2],
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

RegularBuilder::Estimate RegularBuilder::estimate(Fragment& f, const Box3& box,
                                                  std::span<const uint32_t> prims, int level) {
    return {leafCost(prims), splitCost(f, box, prims, level, 1)};
}

void RegularBuilder::setGainArea() {
    if (gainLevel >= maxLevel) return;
    Vec3 e = grid.ext_;
    for (int l = 0; l < gainLevel; ++l) e[grid.schedule_.axis(l)] *= 0.5;
    gainArea = 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

bool RegularBuilder::belowGainFloor(int level, const Box3& box, double saving) const {
    return level >= gainLevel && saving * surfaceArea(box) < params.minGain * gainArea;
}

bool RegularBuilder::stopsByCost(Fragment& f, const Box3& box, std::span<const uint32_t> prims,
                                 int level, const Estimate& first) {
    const bool gainStop = belowGainFloor(level, box, first.leaf - first.split);
    if (!gainStop &&
        (first.split < first.leaf || splitCost(f, box, prims, level, kLookahead) < first.leaf))
        return false;
    ++f.counts.costLeaves;
    f.counts.gainLeaves += gainStop;
    return true;
}

}  // namespace lancer
