// Restriction rules (report, section 2), minimized boxes (Fig. 1), and the restricted tree's
// agreement with the full tree inside a region.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "engine/accel/eval.h"
#include "engine/model/restriction.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

// Tree "p0 op p1" over two unit spheres, restricted to the given membership.
std::string restrictPair(Op op, bool keepA, bool keepB) {
    CsgTree t;
    t.root = t.combine(op, t.leaf(0), t.leaf(1));
    CsgTree r;
    r.root = restrictTree(t, t.root, {char(keepA), char(keepB)}, r);
    return r.toString();
}

TEST(Restriction, PrimitiveInOrOut) {
    CsgTree t;
    t.root = t.leaf(0);
    CsgTree in, out;
    in.root = restrictTree(t, t.root, {1}, in);
    out.root = restrictTree(t, t.root, {0}, out);
    EXPECT_EQ(in.toString(), "p0");
    EXPECT_EQ(out.toString(), "∅");
}

TEST(Restriction, EveryRuleOfTheReport) {
    // Both non-empty: A op B.
    EXPECT_EQ(restrictPair(Op::Union, true, true), "(p0 ∪ p1)");
    EXPECT_EQ(restrictPair(Op::Intersection, true, true), "(p0 ∩ p1)");
    EXPECT_EQ(restrictPair(Op::Difference, true, true), "(p0 − p1)");
    // Both empty: empty.
    for (Op op : {Op::Union, Op::Intersection, Op::Difference})
        EXPECT_EQ(restrictPair(op, false, false), "∅");
    // Only B: union gives B; difference and intersection give empty.
    EXPECT_EQ(restrictPair(Op::Union, false, true), "p1");
    EXPECT_EQ(restrictPair(Op::Difference, false, true), "∅");
    EXPECT_EQ(restrictPair(Op::Intersection, false, true), "∅");
    // Only A: union and difference give A; intersection gives empty.
    EXPECT_EQ(restrictPair(Op::Union, true, false), "p0");
    EXPECT_EQ(restrictPair(Op::Difference, true, false), "p0");
    EXPECT_EQ(restrictPair(Op::Intersection, true, false), "∅");
}

TEST(Restriction, NestedTree) {
    // ((p0 ∪ p1) − (p2 ∩ p3)) restricted to {p1, p2}: (p1) − ∅ = p1.
    CsgTree t;
    int u = t.combine(Op::Union, t.leaf(0), t.leaf(1));
    int i = t.combine(Op::Intersection, t.leaf(2), t.leaf(3));
    t.root = t.combine(Op::Difference, u, i);
    CsgTree r;
    r.root = restrictTree(t, t.root, {0, 1, 1, 0}, r);
    EXPECT_EQ(r.toString(), "p1");
    CsgTree r2;
    r2.root = restrictTree(t, t.root, {1, 0, 1, 1}, r2);
    EXPECT_EQ(r2.toString(), "(p0 − (p2 ∩ p3))");
}

// ((p0 ∪ p1) − (p2 ∩ p3)), the tree of the pool's tests.
CsgTree differenceOfUnionAndIntersection() {
    CsgTree t;
    int u = t.combine(Op::Union, t.leaf(0), t.leaf(1));
    int i = t.combine(Op::Intersection, t.leaf(2), t.leaf(3));
    t.root = t.combine(Op::Difference, u, i);
    return t;
}

/// restrictionWithin of `t` with `held` filling the region: the kept primitives as "p0 p2",
/// "none" (nothing kept) or "as is" (false: left as it is).
std::string keptWithin(const CsgTree& t, std::vector<uint32_t> held) {
    std::vector<uint32_t> kept;
    if (!restrictionWithin(t, held, kept)) return "as is";
    if (kept.empty()) return "none";
    std::string out;
    for (uint32_t p : kept) out += (out.empty() ? "p" : " p") + std::to_string(p);
    return out;
}

// Within a region that a primitive's solid fills: union(full, x) = full, intersection(full, x)
// = x, x - full = empty; a tree empty or full over the whole region keeps nothing (no boundary
// there); a primitive with two leaves, or nothing held, leaves the tree as it is.
TEST(Restriction, WithinARegionAPrimitiveFills) {
    CsgTree d;  // p0 - (p1 u p2): a block less two bars
    d.root = d.combine(Op::Difference, d.leaf(0), d.combine(Op::Union, d.leaf(1), d.leaf(2)));
    EXPECT_EQ(keptWithin(d, {}), "as is");
    EXPECT_EQ(keptWithin(d, {1}), "none");      // inside a bar: nothing of the block is left
    EXPECT_EQ(keptWithin(d, {0}), "p0 p1 p2");  // inside the block: both bars' boundaries
    EXPECT_EQ(keptWithin(d, {0, 2}), "none");   // inside the block and a bar
    CsgTree u;                                  // (p0 u p1) n p2
    u.root = u.combine(Op::Intersection, u.combine(Op::Union, u.leaf(0), u.leaf(1)), u.leaf(2));
    EXPECT_EQ(keptWithin(u, {0}), "p0 p2");  // the full side of the union stands for it
    EXPECT_EQ(keptWithin(u, {2}), "p0 p1 p2");
    EXPECT_EQ(keptWithin(u, {1, 2}), "none");  // full everywhere in the region
    CsgTree m;  // (p0 - p1) u (p2 - p3): the full subtrahend empties its side only
    m.root = m.combine(Op::Union, m.combine(Op::Difference, m.leaf(0), m.leaf(1)),
                       m.combine(Op::Difference, m.leaf(2), m.leaf(3)));
    EXPECT_EQ(keptWithin(m, {1}), "p2 p3");
    EXPECT_EQ(keptWithin(m, {0}), "p0 p1 p2 p3");
    CsgTree twice;  // p0 - (p1 u p0): p0 has two leaves
    twice.root = twice.combine(Op::Difference, twice.leaf(0),
                               twice.combine(Op::Union, twice.leaf(1), twice.leaf(0)));
    EXPECT_EQ(keptWithin(twice, {1}), "none");  // empty whatever p0's leaves keep
    EXPECT_EQ(keptWithin(twice, {2}), "as is");
    // Restricting to the kept list gives the tree the rules give.
    CsgTree r;
    std::vector<char> marks(4, 0);
    r.root = restrictTreeTo(m, {2, 3}, marks, r);
    EXPECT_EQ(r.toString(), "(p2 − p3)");
}

TEST(Restriction, ToAListLeavesTheMarksClearAndComposes) {
    const CsgTree t = differenceOfUnionAndIntersection();
    std::vector<char> marks(4, 0);
    CsgTree r, rr, direct;
    // {p0, p1, p2}: the intersection loses p3, so the difference keeps its minuend alone.
    r.root = restrictTreeTo(t, {0, 1, 2}, marks, r);
    EXPECT_EQ(r.toString(), "(p0 ∪ p1)");
    EXPECT_EQ(marks, std::vector<char>(4, 0));
    // Restricting to P then to Q ⊆ P is restricting to Q (the regular builder relies on it).
    rr.root = restrictTreeTo(r, {1}, marks, rr);
    direct.root = restrictTreeTo(t, {1}, marks, direct);
    EXPECT_EQ(rr.toString(), "p1");
    EXPECT_EQ(direct.toString(), "p1");
    // The ancestors-only restriction builds the same nodes.
    TreeRestrictor restrictor(t);
    CsgTree sparse;
    sparse.root = restrictor.restrict({0, 1, 2}, sparse);
    EXPECT_EQ(sparse.toString(), r.toString());
    EXPECT_EQ(sparse.nodes.size(), r.nodes.size());
}

TEST(Restriction, InPlaceWritesTheAppendedNodesAndUnionSizeCountsThem) {
    // A union of 40 primitives, balanced over a shuffled order, p7 in two leaves: the regular
    // builder reserves unionSize() nodes per set and writes each restriction there, in parallel.
    CsgTree t;
    std::vector<int> leaves;
    std::vector<uint32_t> order(40);
    for (uint32_t p = 0; p < 40; ++p) order[p] = (p * 17) % 40;
    for (uint32_t p : order) leaves.push_back(t.leaf(p));
    leaves.push_back(t.leaf(7));
    t.root = t.balanced(Op::Union, leaves);
    const TreeRestrictor restrictor(t);
    std::vector<char> marks(restrictor.nodeCount(), 0);
    std::mt19937 rng(5);
    for (int trial = 0; trial < 200; ++trial) {
        std::vector<uint32_t> prims;
        for (uint32_t p = 0; p < 40; ++p)
            if (rng() % 4 == 0) prims.push_back(p);
        if (trial == 0) prims = {7};  // two leaves: a union of p7 with itself
        CsgTree appended;
        appended.nodes.resize(3);  // as if after other trees: the roots are numbered from 3
        appended.root = restrictor.restrict(prims, appended, marks);
        const size_t size = appended.nodes.size() - 3;
        EXPECT_EQ(restrictor.unionSize(prims), size);
        std::vector<CsgNode> out(size + 1);
        out[size].prim = 12345;  // a guard past the room: must stay untouched
        const int root = restrictor.restrict(prims, out.data(), 3, marks);
        EXPECT_EQ(root, appended.root);
        for (size_t i = 0; i < size; ++i) {
            const CsgNode &a = appended.nodes[3 + i], &b = out[i];
            EXPECT_TRUE(a.op == b.op && a.left == b.left && a.right == b.right && a.prim == b.prim)
                << "node " << i << " of the restriction to " << prims.size() << " primitives";
        }
        EXPECT_EQ(out[size].prim, 12345u);
        EXPECT_EQ(marks, std::vector<char>(marks.size(), 0));
        // The same nodes from the kept leaves alone.
        ASSERT_TRUE(restrictor.unionOnly());
        std::vector<CsgNode> direct(size + 1);
        direct[size].prim = 12345u;
        std::vector<int> scratch;
        EXPECT_EQ(restrictor.restrictUnions(prims, direct.data(), 3, scratch), appended.root);
        for (size_t i = 0; i < size; ++i)
            EXPECT_TRUE(direct[i].op == out[i].op && direct[i].left == out[i].left &&
                        direct[i].right == out[i].right && direct[i].prim == out[i].prim)
                << "node " << i << " of the restriction to " << prims.size() << " primitives";
        EXPECT_EQ(direct[size].prim, 12345u);
    }
    EXPECT_EQ(restrictor.unionSize(std::vector<uint32_t>{7}), 3u);
    EXPECT_EQ(restrictor.unionSize(std::vector<uint32_t>{}), 0u);
}

TEST(Restriction, UnionsFromTheKeptLeavesAsTheWalkOnRandomShapes) {
    // Unions of random shapes (chains, lopsided and balanced parts), primitives in a shuffled
    // order, some in two leaves, a leaf the root does not reach: restrictUnions() writes the
    // walk's nodes, numbered alike.
    std::mt19937 rng(11);
    for (int trial = 0; trial < 300; ++trial) {
        CsgTree t;
        const uint32_t prims = 1 + rng() % 60;
        std::vector<int> parts;
        for (uint32_t p = 0; p < prims; ++p)
            parts.push_back(t.leaf((p * 7 + uint32_t(trial)) % prims));
        for (int d = 0; d < int(rng() % 4); ++d) parts.push_back(t.leaf(rng() % prims));
        std::shuffle(parts.begin(), parts.end(), rng);
        t.leaf(rng() % prims);  // unreached
        while (parts.size() > 1) {
            const size_t i = rng() % (parts.size() - 1);
            parts[i] = t.combine(Op::Union, parts[i], parts[i + 1]);
            parts.erase(parts.begin() + std::ptrdiff_t(i) + 1);
        }
        t.root = parts[0];
        const TreeRestrictor restrictor(t);
        ASSERT_TRUE(restrictor.unionOnly());
        std::vector<char> marks(restrictor.nodeCount(), 0);
        std::vector<int> scratch;
        for (int set = 0; set < 20; ++set) {
            std::vector<uint32_t> keep;
            const uint32_t share = 1 + rng() % 4;
            for (uint32_t p = 0; p < prims; ++p)
                if (rng() % share == 0) keep.push_back(p);
            CsgTree walked;
            walked.nodes.resize(5);
            walked.root = restrictor.restrict(keep, walked, marks);
            const size_t size = walked.nodes.size() - 5;
            std::vector<CsgNode> direct(size);
            ASSERT_EQ(restrictor.restrictUnions(keep, direct.data(), 5, scratch), walked.root);
            for (size_t i = 0; i < size; ++i) {
                const CsgNode &a = walked.nodes[5 + i], &b = direct[i];
                ASSERT_TRUE(a.op == b.op && a.left == b.left && a.right == b.right &&
                            a.prim == b.prim)
                    << "trial " << trial << " node " << i << " of " << size << ": " << t.toString();
            }
        }
    }
}

TEST(CsgTree, DepthOfALongChainAndABalancedUnion) {
    // Iterative: a chain of 200,000 differences is measured without a deep recursion.
    CsgTree chain;
    int node = chain.leaf(0);
    for (uint32_t p = 1; p <= 200000; ++p)
        node = chain.combine(Op::Difference, node, chain.leaf(p));
    chain.root = node;
    EXPECT_EQ(chain.depth(), 200001);
    CsgTree balanced;
    std::vector<int> leaves;
    for (uint32_t p = 0; p < 1000; ++p) leaves.push_back(balanced.leaf(p));
    balanced.root = balanced.balanced(Op::Union, leaves);
    EXPECT_EQ(balanced.depth(), 11);  // 1000 leaves: 10 levels of unions above them
    EXPECT_EQ(CsgTree{}.depth(), 0);
}

TEST(RestrictedTreePool, EachSetStoredOnceEqualSetsShareIt) {
    const CsgTree t = differenceOfUnionAndIntersection();
    TreeRestrictor restrictor(t);
    RestrictedTreePool pool;
    int restrictions = 0;
    auto share = [&](const std::vector<uint32_t>& prims) {
        return pool.share(prims, [&](CsgTree& dst) {
            ++restrictions;
            return restrictor.restrict(prims, dst);
        });
    };
    // The empty set is list 0 with the empty tree, there from the start.
    EXPECT_EQ(pool.size(), 1u);
    RestrictedTreePool::Entry empty = share({});
    EXPECT_EQ(empty.list, 0u);
    EXPECT_EQ(empty.root, -1);
    EXPECT_EQ(restrictions, 0);

    RestrictedTreePool::Entry a = share({0, 3});
    EXPECT_EQ(a.list, 1u);
    CsgTree view = pool.trees;
    view.root = a.root;
    EXPECT_EQ(view.toString(), "p0");  // p3 alone: the intersection is empty
    const size_t nodes = pool.trees.nodes.size();

    // The subtrahend's primitives alone restrict to the empty tree, yet the set has its list.
    RestrictedTreePool::Entry b = share({2, 3});
    EXPECT_EQ(b.list, 2u);
    EXPECT_EQ(b.root, -1);
    EXPECT_EQ(pool.trees.nodes.size(), nodes);

    // The same set again: the same root and list, nothing restricted or stored again.
    RestrictedTreePool::Entry again = share({0, 3});
    EXPECT_EQ(again.root, a.root);
    EXPECT_EQ(again.list, a.list);
    EXPECT_EQ(restrictions, 2);
    EXPECT_EQ(pool.size(), 3u);
    EXPECT_EQ(pool.trees.nodes.size(), nodes);
    EXPECT_EQ(pool.listFirst, (std::vector<uint32_t>{0, 0, 2, 4}));
    EXPECT_EQ(pool.lists, (std::vector<uint32_t>{0, 3, 2, 3}));
    EXPECT_GE(pool.bytes(), pool.size() * RestrictedTreePool::kEntryBytes);
}

TEST(MinimizedBoxes, IntersectionClipsBothSides) {
    Scene s;
    s.prims.push_back(makePrimitive(Block{{0, 0, 0}, {4, 4, 4}}, Transform()));
    s.prims.push_back(makePrimitive(Sphere{{4, 4, 4}, 1.0}, Transform()));
    s.tree.root = s.tree.combine(Op::Intersection, s.tree.leaf(0), s.tree.leaf(1));
    s.prepare();
    EXPECT_EQ(s.minBox[0], (Box3{{3, 3, 3}, {4, 4, 4}}));
    EXPECT_EQ(s.minBox[1], (Box3{{3, 3, 3}, {4, 4, 4}}));
    EXPECT_EQ(s.droppedPrims, 0);
}

TEST(MinimizedBoxes, DifferenceClipsTheSubtrahendAndDropsWhatLiesOutside) {
    Scene s;
    s.prims.push_back(makePrimitive(Block{{0, 0, 0}, {2, 2, 2}}, Transform()));
    s.prims.push_back(makePrimitive(Sphere{{2, 1, 1}, 0.5}, Transform()));  // half inside
    s.prims.push_back(makePrimitive(Sphere{{9, 9, 9}, 0.5}, Transform()));  // far outside
    int cut = s.tree.combine(Op::Union, s.tree.leaf(1), s.tree.leaf(2));
    s.tree.root = s.tree.combine(Op::Difference, s.tree.leaf(0), cut);
    s.prepare();
    EXPECT_EQ(s.minBox[0], (Box3{{0, 0, 0}, {2, 2, 2}}));
    EXPECT_EQ(s.minBox[1], (Box3{{1.5, 0.5, 0.5}, {2, 1.5, 1.5}}));
    EXPECT_TRUE(s.minBox[2].isEmpty());
    EXPECT_EQ(s.droppedPrims, 1);
    EXPECT_EQ(s.tree.toString(), "(p0 − p1)");
}

TEST(MinimizedBoxes, IteratesToAFixedPoint) {
    // (A ∩ B) − C, then the clipped box of A ∩ B clips C further: needs more than one pass
    // when boxes shrink through several operators.
    Scene s;
    s.prims.push_back(makePrimitive(Block{{0, 0, 0}, {10, 10, 10}}, Transform()));
    s.prims.push_back(makePrimitive(Block{{5, 5, 5}, {20, 20, 20}}, Transform()));
    s.prims.push_back(makePrimitive(Block{{-5, -5, -5}, {7, 7, 7}}, Transform()));
    int i = s.tree.combine(Op::Intersection, s.tree.leaf(0), s.tree.leaf(1));
    s.tree.root = s.tree.combine(Op::Difference, i, s.tree.leaf(2));
    s.prepare();
    EXPECT_EQ(s.minBox[0], (Box3{{5, 5, 5}, {10, 10, 10}}));
    EXPECT_EQ(s.minBox[2], (Box3{{5, 5, 5}, {7, 7, 7}}));
    EXPECT_GE(s.minimizeIterations, 2);
}

TEST(MinimizedBoxes, EveryVisibleHitLiesInItsPrimitivesBox) {
    NullObserver obs;
    size_t hits = 0;  // the rays must hit: a test of no hit would check nothing
    for (uint64_t seed = 1; seed <= 40; ++seed) {
        Scene s = test::randomCsgScene(seed);
        BuildParams bp;
        auto brute = buildAccelerator(s, bp);
        TraceContext ctx(s.prims.size(), s.tree.depth());
        ctx.useMailboxes = false;
        for (const Ray& r : test::randomRays(s, seed * 7, 500)) {
            Hit h;
            ctx.beginRay();
            if (!brute->intersect(r, 0.0, kInf, ctx, obs, h)) continue;
            ++hits;
            Vec3 p = r.at(h.t);
            Box3 b = s.minBox[h.prim];
            Vec3 slack = Vec3(1e-9 * std::max(1.0, glm::length(p)));
            Box3 loose{b.lo - slack, b.hi + slack};
            ASSERT_TRUE(loose.contains(p))
                << "seed " << seed << " " << r.toString() << " hit p" << h.prim << " at "
                << toString(p) << " outside " << b.toString();
        }
    }
    EXPECT_GT(hits, 40u * 500u / 10u);
}

// Within any box region, the tree restricted to the primitives whose minimized boxes overlap
// the region gives the same span boundaries as the full tree.
TEST(Restriction, RestrictedTreeAgreesInsideRandomRegions) {
    NullObserver obs;
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int checkedHits = 0;
    for (uint64_t seed = 1; seed <= 60; ++seed) {
        Scene s = test::randomCsgScene(seed);
        if (s.tree.empty()) continue;
        TraceContext ctx(s.prims.size(), s.tree.depth());
        ctx.useMailboxes = false;
        for (int k = 0; k < 20; ++k) {
            // A random sub-box of the scene bounds.
            Vec3 a = s.bounds.lo + Vec3(u(rng), u(rng), u(rng)) * s.bounds.extent();
            Vec3 b = s.bounds.lo + Vec3(u(rng), u(rng), u(rng)) * s.bounds.extent();
            Box3 region{glm::min(a, b), glm::max(a, b)};
            std::vector<char> keep(s.prims.size(), 0);
            for (uint32_t p : s.livePrimitives()) keep[p] = s.minBox[p].overlaps(region);
            CsgTree r;
            r.root = restrictTree(s.tree, s.tree.root, keep, r);
            for (const Ray& ray : test::randomRays(s, seed * 1000 + uint64_t(k), 60)) {
                double t0, t1;
                if (!clipLine(ray, region, t0, t1)) continue;
                Hit full, part;
                ctx.beginRay();
                bool f = hitInRegion(s, s.tree, s.tree.root, ray, -kInf, t0, t1, ctx, obs, full);
                ctx.beginRay();
                bool p = hitInRegion(s, r, r.root, ray, -kInf, t0, t1, ctx, obs, part);
                ASSERT_EQ(f, p) << "seed " << seed << " " << ray.toString() << " region "
                                << region.toString() << "\nfull " << s.tree.toString()
                                << "\nrestricted " << r.toString();
                if (f) {
                    ASSERT_EQ(full.t, part.t) << ray.toString();
                    ++checkedHits;
                }
            }
        }
    }
    EXPECT_GT(checkedHits, 1000);
}

}  // namespace
}  // namespace lancer
