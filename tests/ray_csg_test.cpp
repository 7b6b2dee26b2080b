// The CSG along a recorded ray (engine/render/ray_csg.h): every node's spans, got again by the
// tracer's evaluator from the recorded primitive spans, end at the walk's own result and hit;
// and the wasted work is classified as documented, on hand-built walks.
#include "engine/render/ray_csg.h"

#include <gtest/gtest.h>

#include <random>

#include "engine/accel/eval.h"
#include "support/differential.h"

namespace lancer {
namespace {

BuildParams params(SchemeKind scheme, StepMethod step, IrregularFrame frame, bool mailboxes) {
    BuildParams p;
    p.scheme = scheme;
    p.regular.step = step;
    p.irregular.frame = frame;
    p.mailboxes = mailboxes;
    return p;
}

// Random CSG scenes, random pixels, every ray of their trees (bounces 2), every scheme: in each
// step that evaluated its tree, the root row is the walk's recorded spans, every evaluated
// operator row is its operator on its evaluated children, and in the step the walk ended in
// with a hit the root's first boundary in the step's window is that hit (for a ray starting
// outside every solid, the start of the root's first span ahead). Every test of the ray is
// classified once.
TEST(RayCsg, RootRowIsTheWalksResultAndGivesTheHit) {
    size_t steps = 0, hits = 0, operators = 0;
    for (uint64_t seed = 1; seed <= 5; ++seed) {
        test::RandomSceneOptions opt;
        opt.primitives = 8 + int(seed) * 3;
        Scene scene = test::randomGlassyCsgScene(seed, opt);
        const BuildParams configs[] = {
            params(SchemeKind::Brute, StepMethod::Exact, IrregularFrame::Projective, true),
            params(SchemeKind::Regular, StepMethod::Exact, IrregularFrame::Projective, true),
            params(SchemeKind::Regular, StepMethod::Push, IrregularFrame::Projective, false),
            params(SchemeKind::Irregular, StepMethod::Exact, IrregularFrame::Projective, true),
            params(SchemeKind::Irregular, StepMethod::Exact, IrregularFrame::Camera, false),
        };
        for (const BuildParams& p : configs) {
            SCOPED_TRACE(std::string(schemeName(p.scheme)) + " seed " + std::to_string(seed));
            auto accel = buildAccelerator(scene, p);
            const StructureView view(scene, *accel);
            ShadingOptions sh;
            sh.bounces = 2;
            std::mt19937_64 rng(seed);
            std::uniform_int_distribution<int> px(0, 23);
            for (int k = 0; k < 16; ++k) {
                const RayTree t =
                    tracePixel(scene, *accel, sh, scene.camera, px(rng), px(rng), 24, 24);
                for (const TracedRay& r : t.rays) {
                    const std::vector<StepCsg> csg = rayCsg(scene, view, r);
                    for (const StepCsg& s : csg) {
                        if (!s.evaluated || s.root < 0) continue;
                        ++steps;
                        ASSERT_FALSE(s.nodes.empty());
                        ASSERT_TRUE(s.nodes[0].evaluated);
                        EXPECT_EQ(s.nodes[0].spans, s.result) << r.toString();
                        for (const NodeSpans& n : s.nodes) {
                            if (n.op == Op::Primitive || !n.evaluated) continue;
                            // Its children: the next rows whose parent it is.
                            std::vector<const NodeSpans*> kids;
                            for (const NodeSpans& m : s.nodes)
                                if (m.parent >= 0 && &s.nodes[size_t(m.parent)] == &n)
                                    kids.push_back(&m);
                            ASSERT_EQ(kids.size(), 2u);
                            ASSERT_TRUE(kids[0]->evaluated);
                            if (!kids[1]->evaluated) {
                                EXPECT_TRUE(kids[0]->spans.empty());
                                EXPECT_TRUE(n.spans.empty());
                                continue;
                            }
                            SpanList want;
                            if (n.op == Op::Union) spanUnion(kids[0]->spans, kids[1]->spans, want);
                            if (n.op == Op::Intersection)
                                spanIntersection(kids[0]->spans, kids[1]->spans, want);
                            if (n.op == Op::Difference)
                                spanDifference(kids[0]->spans, kids[1]->spans, want);
                            EXPECT_EQ(n.spans, want);
                            ++operators;
                        }
                    }
                    if (r.kind != RayKind::Shadow && r.hit.valid() && !csg.empty()) {
                        const StepCsg& last = csg.back();
                        ASSERT_TRUE(last.first.has_value()) << r.toString();
                        EXPECT_EQ(last.first->t, r.hit.t);
                        EXPECT_EQ(last.first->prim, r.hit.prim);
                        const Span* ahead = nullptr;
                        for (const Span& sp : last.result)
                            if (sp.out.t > r.tmin) {
                                ahead = &sp;
                                break;
                            }
                        ASSERT_NE(ahead, nullptr);
                        if (ahead->in.t > r.tmin && ahead->in.t >= last.lo) {
                            EXPECT_EQ(ahead->in.t, r.hit.t);
                        }
                        ++hits;
                    }
                    const RayWaste w = wastedWork(scene, r, csg);
                    EXPECT_EQ(w.total.tests, r.counters.primTests);
                    WasteCounts sum;
                    for (const WasteCounts& c : w.perStep) sum += c;
                    EXPECT_EQ(sum, w.total);
                }
            }
        }
    }
    EXPECT_GT(steps, 500u);
    EXPECT_GT(hits, 100u);
    EXPECT_GT(operators, 300u);
}

/// A scene of spheres along the x axis and a ray along it from x = 0: sphere i centred at
/// `centre[i]` with radius 1 spans t = [centre - 1, centre + 1].
struct Line {
    Scene scene;
    TracedRay ray;

    explicit Line(const std::vector<double>& centres) {
        for (double c : centres)
            scene.prims.push_back(makePrimitive(Sphere{{c, 0, 0}, 1.0}, Transform()));
        ray.origin = Vec3(0.0);
        ray.direction = Vec3(1, 0, 0);
        ray.tmin = 0.0;
        ray.tmax = kInf;
        add(walk::RayBegin{});
    }
    /// Prepares the scene under a union of every primitive (so that none is dropped: prepare
    /// would restrict A − B to A where B's box misses A's), then puts the tree built back.
    void finish() {
        const CsgTree tree = scene.tree;
        scene.tree = CsgTree{};
        std::vector<int> leaves;
        for (uint32_t p = 0; p < scene.prims.size(); ++p) leaves.push_back(scene.tree.leaf(p));
        scene.tree.root = scene.tree.balanced(Op::Union, leaves);
        scene.prepare();
        scene.tree = tree;
    }
    void add(WalkEvent::Data e) { ray.events.push_back(WalkEvent{std::move(e)}); }
    void region(uint32_t id, double t0, double t1) { add(walk::Region{id, t0, t1}); }
    /// The primitive's test as the walk records it.
    void test(uint32_t p) {
        Span s[2];
        const int n = scene.primSpans(p, Ray{ray.origin, ray.direction}, s, Precision::Double);
        add(walk::PrimTest{p, SpanList(s, s + n)});
        ++ray.counters.primTests;
    }
    void mailbox(uint32_t p) { add(walk::MailboxHit{p}); }
    /// The tree's result the walk records: evalTree on the scene's tree.
    void spans() {
        TraceContext ctx(scene.prims.size(), scene.tree.depth());
        ctx.beginRay();
        NullObserver obs;
        SpanList out;
        evalTree(scene, scene.tree, scene.tree.root, Ray{ray.origin, ray.direction}, ctx, obs, 0,
                 out);
        add(walk::Spans{out});
    }
    std::vector<StepCsg> steps() const {
        return rayCsg(
            scene, ray,
            [this](uint32_t) {
                return RegionTree{&scene.tree, scene.tree.root};
            },
            false);
    }
    /// The class of the n-th PrimTest event.
    Waste wasteOfTest(const RayWaste& w, int n) const {
        for (size_t i = 0; i < ray.events.size(); ++i)
            if (ray.events[i].kind() == WalkEvent::PrimTest && n-- == 0) return w.perEvent[i];
        return Waste::None;
    }
};

// A − B where the ray crosses A on [2, 4] and B on [6, 8]: the subtrahend is tested, inside
// the region [0, 10] but outside A, so taken as empty nothing changes: of no effect. In a
// region [0, 5] it lies wholly beyond the exit: beyond exit. B overlapping A's front ([1, 3])
// exposes its inside surface at t = 3, the hit: both tests useful.
TEST(RayCsg, DifferenceWhoseSubtrahendLiesOutside) {
    for (double t1 : {10.0, 5.0}) {
        Line l({3.0, 7.0});
        l.scene.tree.root =
            l.scene.tree.combine(Op::Difference, l.scene.tree.leaf(0), l.scene.tree.leaf(1));
        l.finish();
        l.region(0, 0.0, t1);
        l.test(0);
        l.test(1);
        l.spans();
        const std::vector<StepCsg> steps = l.steps();
        ASSERT_EQ(steps.size(), 1u);
        ASSERT_EQ(steps[0].nodes.size(), 3u);
        EXPECT_EQ(steps[0].nodes[0].op, Op::Difference);
        ASSERT_EQ(steps[0].nodes[0].spans.size(), 1u);
        EXPECT_EQ(steps[0].nodes[0].spans[0].in.t, 2.0);
        ASSERT_TRUE(steps[0].first.has_value());
        EXPECT_EQ(steps[0].first->t, 2.0);
        const RayWaste w = wastedWork(l.scene, l.ray, steps);
        EXPECT_EQ(l.wasteOfTest(w, 0), Waste::None);
        EXPECT_EQ(l.wasteOfTest(w, 1), t1 == 10.0 ? Waste::NoEffect : Waste::BeyondExit);
        EXPECT_EQ(w.total.tests, 2u);
        EXPECT_EQ(w.total.wasted(), 1u);
        EXPECT_EQ(w.total.toString(), t1 == 10.0 ? "2 tests, 1 wasted: 1 of no effect"
                                                 : "2 tests, 1 wasted: 1 beyond exit");
    }
    Line l({3.0, 2.0});
    l.scene.tree.root =
        l.scene.tree.combine(Op::Difference, l.scene.tree.leaf(0), l.scene.tree.leaf(1));
    l.finish();
    l.region(0, 0.0, 10.0);
    l.test(0);
    l.test(1);
    l.spans();
    const std::vector<StepCsg> steps = l.steps();
    ASSERT_TRUE(steps[0].first.has_value());
    EXPECT_EQ(steps[0].first->t, 3.0);
    EXPECT_EQ(steps[0].first->prim, 1u);
    EXPECT_TRUE(steps[0].first->flip);
    const RayWaste w = wastedWork(l.scene, l.ray, steps);
    EXPECT_EQ(w.total.wasted(), 0u);
    EXPECT_EQ(w.total.toString(), "2 tests, 0 wasted");
}

// A ∪ B, A on [2, 4] and B on [6, 8], walked through regions [0, 5] and [5, 10] that both list
// both (the walk is made to go on past A's boundary at 2 to see the second region's reads).
// Without mailboxes the second region tests both again: two repeats, while the first tests
// count as useful (A's spans give the first boundary of the first region, B's that of the
// second). With mailboxes the second region takes both from the mailbox: no test, no waste.
TEST(RayCsg, PrimitiveTestedInTwoRegionsWithoutMailboxes) {
    for (bool mailboxes : {false, true}) {
        Line l({3.0, 7.0});
        l.scene.tree.root =
            l.scene.tree.combine(Op::Union, l.scene.tree.leaf(0), l.scene.tree.leaf(1));
        l.finish();
        l.region(0, 0.0, 5.0);
        l.test(0);
        l.test(1);
        l.spans();
        l.region(1, 5.0, 10.0);
        if (mailboxes) {
            l.mailbox(0);
            l.mailbox(1);
        } else {
            l.test(0);
            l.test(1);
        }
        l.spans();
        const std::vector<StepCsg> steps = l.steps();
        ASSERT_EQ(steps.size(), 2u);
        EXPECT_TRUE(steps[1].inputs[0].mailbox == mailboxes);
        EXPECT_EQ(steps[1].inputs[1].spans, steps[0].inputs[1].spans);
        // B is first in the second region.
        ASSERT_TRUE(steps[1].first.has_value());
        EXPECT_EQ(steps[1].first->t, 6.0);
        const RayWaste w = wastedWork(l.scene, l.ray, steps);
        EXPECT_EQ(l.wasteOfTest(w, 0), Waste::None);
        // B matters in the second region (the first boundary there is its).
        EXPECT_EQ(l.wasteOfTest(w, 1), Waste::None);
        if (!mailboxes) {
            EXPECT_EQ(l.wasteOfTest(w, 2), Waste::Repeat);
            EXPECT_EQ(l.wasteOfTest(w, 3), Waste::Repeat);
            EXPECT_EQ(w.perStep[1].repeats, 2u);
            EXPECT_EQ(w.total.toString(), "4 tests, 2 wasted: 2 repeats");
        } else {
            EXPECT_EQ(w.total.toString(), "2 tests, 0 wasted");
        }
    }
    // A test that finds nothing is a miss.
    Line l({3.0, 7.0});
    l.scene.prims[1] = makePrimitive(Sphere{{7, 5, 0}, 1.0}, Transform());
    l.scene.tree.root = l.scene.tree.combine(Op::Union, l.scene.tree.leaf(0), l.scene.tree.leaf(1));
    l.finish();
    l.region(0, 0.0, 10.0);
    l.test(0);
    l.test(1);
    l.spans();
    const RayWaste w = wastedWork(l.scene, l.ray, l.steps());
    EXPECT_EQ(l.wasteOfTest(w, 1), Waste::Miss);
    EXPECT_EQ(w.total.toString(), "2 tests, 1 wasted: 1 miss");
}

}  // namespace
}  // namespace lancer
