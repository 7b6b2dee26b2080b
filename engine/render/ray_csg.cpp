#include "engine/render/ray_csg.h"

#include <algorithm>
#include <unordered_map>

#include "engine/accel/eval.h"

namespace lancer {

namespace {

/// Keeps the spans of each node evalTree evaluates.
struct NodeRecorder : NullObserver {
    static constexpr bool kActive = true;
    std::unordered_map<int, SpanList> spans;
    void csgNode(int node, const SpanList& s) { spans[node] = s; }
};

/// The tree's nodes in pre-order with parents and depths, not yet evaluated.
void listNodes(const CsgTree& tree, int node, int parent, int depth, std::vector<NodeSpans>& out) {
    if (node < 0 || size_t(node) >= tree.nodes.size()) return;
    const CsgNode& x = tree.nodes[size_t(node)];
    NodeSpans n;
    n.node = node;
    n.parent = parent;
    n.depth = depth;
    n.op = x.op;
    n.prim = x.prim;
    out.push_back(n);
    if (x.op == Op::Primitive) return;
    const int self = int(out.size()) - 1;
    listNodes(tree, x.left, self, depth + 1, out);
    listNodes(tree, x.right, self, depth + 1, out);
}

/// evalNodes with a context of the scene's size, reused across calls: each call takes a fresh
/// ray id, so the mailboxes need no clearing.
struct Evaluator {
    const Scene& scene;
    TraceContext ctx;
    explicit Evaluator(const Scene& s) : scene(s), ctx(s.prims.size(), s.tree.depth() + 1) {}

    std::vector<NodeSpans> run(const CsgTree& tree, int root, const Ray& ray,
                               const std::vector<PrimSpans>& inputs) {
        std::vector<NodeSpans> nodes;
        if (root < 0) return nodes;
        listNodes(tree, root, -1, 0, nodes);
        if (ctx.scratch.size() < size_t(2 * tree.depth() + 4))
            ctx.scratch.resize(size_t(2 * tree.depth() + 4));
        // The inputs as the walk's mailboxes held them: the tree reads them as mailbox hits.
        ctx.newStamp();
        ctx.useMailboxes = true;
        for (const PrimSpans& p : inputs) {
            if (p.prim >= scene.prims.size()) continue;
            Mailbox& m = ctx.takeMailbox(p.prim);
            m.count = uint8_t(std::min<size_t>(p.spans.size(), 2));
            std::copy_n(p.spans.begin(), m.count, m.spans);
        }
        NodeRecorder rec;
        SpanList out;
        evalTree(scene, tree, root, ray, ctx, rec, 0, out);
        for (NodeSpans& n : nodes) {
            auto it = rec.spans.find(n.node);
            if (it == rec.spans.end()) continue;
            n.evaluated = true;
            n.spans = it->second;
        }
        return nodes;
    }
};

std::optional<Boundary> firstIn(const SpanList& spans, double tmin, double lo, double hi) {
    const Boundary* b = firstBoundary(spans, tmin, lo, hi);
    return b ? std::optional<Boundary>(*b) : std::nullopt;
}

bool sameOutcome(const std::optional<Boundary>& a, const std::optional<Boundary>& b) {
    if (a.has_value() != b.has_value()) return false;
    return !a || (a->t == b->t && a->prim == b->prim && a->part == b->part);
}

}  // namespace

std::vector<NodeSpans> evalNodes(const Scene& scene, const CsgTree& tree, int root, const Ray& ray,
                                 const std::vector<PrimSpans>& inputs) {
    Evaluator ev(scene);
    return ev.run(tree, root, ray, inputs);
}

std::vector<StepCsg> rayCsg(const Scene& scene, const StructureView& view, const TracedRay& ray) {
    return rayCsg(
        scene, ray,
        [&view](uint32_t id) {
            if (id >= view.regionCount()) return RegionTree{};
            const RegionInfo info = view.region(id);
            return RegionTree{info.pool, info.root};
        },
        view.scheme() == SchemeKind::Regular);
}

std::vector<StepCsg> rayCsg(const Scene& scene, const TracedRay& ray, const RegionTreeFn& treeOf,
                            bool toTmaxInLast) {
    std::vector<StepCsg> steps;
    const std::vector<WalkEvent>& ev = ray.events;
    const std::vector<size_t> starts = ray.regionSteps();
    const Ray line{ray.origin, ray.direction};
    Evaluator eval(scene);
    // The spans of each primitive's last test along the ray: what its mailbox holds.
    std::unordered_map<uint32_t, const SpanList*> lastTest;
    int lastEvaluated = -1;  // the last step that evaluated its tree (not carried)
    for (size_t k = 0; k < starts.size(); ++k) {
        const size_t begin = starts[k];
        const size_t end = k + 1 < starts.size() ? starts[k + 1] : ev.size();
        StepCsg s;
        s.event = begin;
        const walk::Region& region = ev[begin].as<walk::Region>();
        s.region = region.region;
        s.t0 = region.t0;
        s.t1 = region.t1;
        s.lo = k == 0 ? std::min(s.t0, ray.tmin) : s.t0;
        s.hi = k + 1 == starts.size() && toTmaxInLast ? std::max(s.t1, ray.tmax) : s.t1;
        const RegionTree tree = treeOf(s.region);
        s.pool = tree.pool;
        s.root = tree.root;
        for (size_t i = begin + 1; i < end; ++i) {
            if (const auto* test = ev[i].get<walk::PrimTest>()) {
                s.inputs.push_back({test->prim, test->spans, false});
                lastTest[test->prim] = &test->spans;
            } else if (const auto* mail = ev[i].get<walk::MailboxHit>()) {
                auto it = lastTest.find(mail->prim);
                s.inputs.push_back(
                    {mail->prim, it != lastTest.end() ? *it->second : SpanList{}, true});
            } else if (const auto* spans = ev[i].get<walk::Spans>()) {
                s.evaluated = true;
                s.result = spans->spans;
            }
        }
        // A region sharing the previous region's tree reads nothing: the walk keeps the spans.
        if (s.evaluated && s.inputs.empty() && lastEvaluated >= 0) {
            s.carried = true;
            s.inputs = steps[size_t(lastEvaluated)].inputs;
        }
        // A region without a tree (the irregular scheme's, in a union-only scene) shows its
        // primitives' inputs and merged result only.
        if (s.evaluated && s.pool && s.root >= 0)
            s.nodes = eval.run(*s.pool, s.root, line, s.inputs);
        if (s.evaluated && s.pool) s.first = firstIn(s.result, ray.tmin, s.lo, s.hi);
        if (s.evaluated && !s.carried) lastEvaluated = int(steps.size());
        steps.push_back(std::move(s));
    }
    return steps;
}

const char* wasteName(Waste w) {
    switch (w) {
        case Waste::None:
            return "";
        case Waste::Repeat:
            return "repeat";
        case Waste::Miss:
            return "miss";
        case Waste::BeyondExit:
            return "beyond exit";
        case Waste::NoEffect:
            return "no effect";
    }
    return "";
}

void WasteCounts::add(Waste w) {
    ++tests;
    repeats += w == Waste::Repeat;
    misses += w == Waste::Miss;
    beyondExit += w == Waste::BeyondExit;
    noEffect += w == Waste::NoEffect;
}

WasteCounts& WasteCounts::operator+=(const WasteCounts& o) {
    tests += o.tests;
    repeats += o.repeats;
    misses += o.misses;
    beyondExit += o.beyondExit;
    noEffect += o.noEffect;
    return *this;
}

std::string WasteCounts::toString() const {
    auto n = [](uint32_t v, const char* one, const char* many) {
        return std::to_string(v) + " " + (v == 1 ? one : many);
    };
    std::string s = n(tests, "test", "tests") + ", " + std::to_string(wasted()) + " wasted";
    std::string parts;
    auto part = [&](uint32_t v, const char* one, const char* many) {
        if (v == 0) return;
        parts += (parts.empty() ? ": " : ", ") + n(v, one, many);
    };
    part(repeats, "repeat", "repeats");
    part(misses, "miss", "misses");
    part(beyondExit, "beyond exit", "beyond exit");
    part(noEffect, "of no effect", "of no effect");
    return s + parts;
}

RayWaste wastedWork(const Scene& scene, const TracedRay& ray, const std::vector<StepCsg>& steps) {
    RayWaste w;
    w.perEvent.assign(ray.events.size(), Waste::None);
    w.perStep.assign(steps.size(), WasteCounts{});
    const Ray line{ray.origin, ray.direction};
    Evaluator eval(scene);
    // The step of each event.
    std::vector<int> stepOf(ray.events.size(), -1);
    for (size_t k = 0; k < steps.size(); ++k) {
        const size_t end = k + 1 < steps.size() ? steps[k + 1].event : ray.events.size();
        for (size_t i = steps[k].event; i < end; ++i) stepOf[i] = int(k);
    }
    // Does step k's first boundary change when `prim`'s spans are taken as empty?
    auto matters = [&](size_t k, uint32_t prim) {
        const StepCsg& s = steps[k];
        if (!s.evaluated || !s.pool) return false;
        if (s.root < 0) {  // no tree (union-only, irregular): the others' spans merged, as the walk
            SpanList spans, merged;
            for (const PrimSpans& p : s.inputs)
                if (p.prim != prim) spans.insert(spans.end(), p.spans.begin(), p.spans.end());
            flatUnion(spans, merged);
            return !sameOutcome(firstIn(merged, ray.tmin, s.lo, s.hi), s.first);
        }
        std::vector<PrimSpans> without = s.inputs;
        for (PrimSpans& p : without)
            if (p.prim == prim) p.spans.clear();
        const std::vector<NodeSpans> nodes = eval.run(*s.pool, s.root, line, without);
        const SpanList empty;
        const SpanList& root = nodes.empty() || !nodes[0].evaluated ? empty : nodes[0].spans;
        return !sameOutcome(firstIn(root, ray.tmin, s.lo, s.hi), s.first);
    };
    std::unordered_map<uint32_t, size_t> tested;  // primitive -> its first test's event
    for (size_t i = 0; i < ray.events.size(); ++i) {
        const walk::PrimTest* test = ray.events[i].get<walk::PrimTest>();
        if (!test || stepOf[i] < 0) continue;
        const walk::PrimTest& e = *test;
        const size_t k = size_t(stepOf[i]);
        Waste cls = Waste::None;
        if (tested.count(e.prim)) {
            cls = Waste::Repeat;
        } else if (e.spans.empty()) {
            cls = Waste::Miss;
        } else {
            // Every test of a primitive along one line gives the same spans: this first one
            // counts as useful when any step reading them (tested again, from the mailbox, or
            // carried) depends on them; the later tests are repeats.
            bool useful = false;
            for (size_t j = k; j < steps.size() && !useful; ++j) {
                if (!steps[j].evaluated) continue;
                for (const PrimSpans& p : steps[j].inputs)
                    if (p.prim == e.prim) {
                        useful = matters(j, e.prim);
                        break;
                    }
            }
            if (!useful) {
                const bool beyond = std::all_of(e.spans.begin(), e.spans.end(), [&](const Span& s) {
                    return s.in.t > steps[k].t1;
                });
                cls = beyond ? Waste::BeyondExit : Waste::NoEffect;
            }
        }
        tested.emplace(e.prim, i);
        w.perEvent[i] = cls;
        w.perStep[k].add(cls);
        w.total.add(cls);
    }
    return w;
}

}  // namespace lancer
