// A bounding volume hierarchy (BVH) over the minimized boxes, split by the surface-area
// heuristic (MacDonald and Booth, 1990; binned as in Wald, 2007): the modern baseline beside
// the report's two subdivisions, in the same tool and ray for ray.
//
// A CSG scene needs one thing more than a BVH of triangles: a leaf's tree must give the full
// tree's spans inside the leaf's box. Each leaf is built from the primitives assigned to it by
// the splits, and lists every primitive whose minimized box meets its box (the assigned ones
// and those of other leaves reaching into it), with their restricted tree (report, section 2)
// as every region of the other schemes has. Inside that box the restricted tree agrees with the
// full one, so the first boundary a leaf finds within its box is a boundary of the scene; the
// nearest of the leaves' is the visible hit. Leaves overlap, so the walk is not in ray order:
// front to back by box entry, a node whose box starts beyond the hit found is not entered, and
// the mailboxes spare a primitive listed by several leaves a second test.
#pragma once

#include <array>
#include <cassert>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "engine/accel/build_params.h"
#include "engine/accel/bvh/bvh_boxes.h"
#include "engine/accel/eval.h"
#include "engine/accel/regular/grid_frame.h"

namespace lancer {

class BuildGuard;  // engine/accel/build_guard.h

/// A node id meaning "no node" in the walk's events.
inline constexpr uint32_t kNoNode = 0xffffffffu;
/// The walks' stack: each wide node visited leaves at most kBvhWidth - 1 more entries waiting,
/// and a wide node is at least one level below its parent.
inline constexpr int kWalkStack = (kBvhWidth - 1) * kAutomaticBvhDepth + 2;

/// A union-only scene's primitive as the walks test it, listed as Bvh::primList() lists it (so
/// a leaf's are one contiguous read): a sphere's centre and radius, as Scene::packedSpheres holds
/// them (the same test, the same bits), r < 0 for any other primitive (tested by the scene).
struct BvhUnionEntry {
    Vec3 c{0.0};
    double r = -1.0;
    uint32_t prim = 0;  ///< its id: the hit's, the observer's
    uint32_t last = 0;  ///< 1: the last of its leaf's
};
static_assert(sizeof(BvhUnionEntry) == 40);

class Bvh {
  public:
    static constexpr SchemeKind kKind = SchemeKind::Bvh;  ///< its row of kSchemeTable
    /// Its knobs in `p`.
    static const BvhConfig& config(const BuildParams& p) { return p.bvh; }

    /// Build over a prepared scene; the scheme's figures go to `extra`. Throws
    /// std::invalid_argument naming the option for refused parameters or a structure over the
    /// guard's memory budget, BuildCancelled when its stop is requested. `guard` null: the
    /// default budget, no cancellation.
    static Bvh build(const Scene& scene, const BvhConfig& config, nlohmann::json& extra,
                     BuildGuard* guard = nullptr);

    /// Nearest visible hit with t in (tmin, tmax] (tmin >= 0), the nodes visited front to back.
    template <class Obs>
    bool intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                   Hit& hit) const {
        return query<false>(ray, tmin, tmax, ctx, obs, hit);
    }
    /// Whether the ray meets a visible boundary with t in (tmin, tmax], intersect()'s answer,
    /// for shadow rays: the walk ends at the first boundary it is sure of, not the nearest
    /// (`hit` is that boundary).
    template <class Obs>
    bool occluded(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                  Hit& hit) const {
        return query<true>(ray, tmin, tmax, ctx, obs, hit);
    }

    /// Regions are the nodes, inner and leaf: the ids the walk reports.
    size_t regionCount() const { return nodes_.size(); }
    size_t memoryBytes() const {
        return nodes_.size() * sizeof(BvhNode) + wides_.size() * sizeof(BvhWideNode) +
               primList_.size() * sizeof(uint32_t) + parent_.size() * sizeof(uint32_t) +
               unionEntries_.size() * sizeof(BvhUnionEntry) + pool_.nodes.size() * sizeof(CsgNode);
    }
    /// A union-only scene's leaves list only their own primitives, each primitive in one leaf.
    bool usesMailboxes() const { return !unionOnly_; }

    const std::vector<BvhNode>& nodes() const { return nodes_; }
    /// The wide nodes the walks read (bvh_boxes.h): wides()[0] stands for the root, when it is
    /// not a leaf.
    const std::vector<BvhWideNode>& wides() const { return wides_; }
    /// The wide node whose slot 0 is the root (the others unused), where the walks start.
    const BvhWideNode& top() const { return top_; }
    /// What the wide nodes' float boxes are relative to: the root box's centre.
    const Vec3& anchor() const { return anchor_; }
    /// Node `id`'s parent; kNoNode for the root.
    uint32_t parent(uint32_t id) const { return parent_[id]; }
    /// Primitives listed by the leaves: leaf n's are primList()[n.first, n.first + n.count).
    const std::vector<uint32_t>& primList() const { return primList_; }
    /// A union-only scene's primitives as primList() lists them, with their spheres (each
    /// leaf's last marked): what its walks read; empty for other scenes.
    const std::vector<BvhUnionEntry>& unionEntries() const { return unionEntries_; }
    /// The leaves' restricted trees (empty for a union-only scene: its leaves merge their
    /// primitives' spans).
    const CsgTree& treePool() const { return pool_; }
    /// The frame its boxes are in (grid_frame.h): the world's axes, or a turned subtree's.
    const GridFrame& frame() const { return frame_; }
    /// The structure's box, in its frame: the root's.
    Box3 box() const { return nodes_.empty() ? Box3() : nodes_[0].box(); }
    /// Deepest level reached.
    int depth() const { return depth_; }
    /// The leaf holding a world point, for picking: the deepest leaf whose box contains it (the
    /// nearest leaf's box when none does); kNoNode for an empty structure.
    uint32_t leafAt(const Vec3& p) const;
    /// "leaf 12 depth 5 Box3{..} 3 prims (2 assigned)" or "node 3 depth 1 Box3{..} children 4, 5".
    std::string describe(uint32_t id) const;

  private:
    /// intersect() (kAnyHit false) or occluded() (true).
    template <bool kAnyHit, class Obs>
    bool query(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
               Hit& hit) const {
        assert(tmin >= 0.0);  // the float box tests widen their intervals for t >= 0
        if (nodes_.empty()) return false;
        // The boxes are the frame's (the world's unless the scene is turned): the walk reads
        // them with the ray in the frame, `fr` (the same t), the leaves test the world ray.
        Ray mapped;
        if (frame_.turned) mapped = frame_.toFrame(ray);
        const Ray& fr = frame_.turned ? mapped : ray;
        // A ray with a flat axis (bvh_boxes.h) has that axis tested by the origin's place; the
        // others never pay for the check.
        if (hasFlatAxis(fr)) {
            const WideBoxes<true> boxes(&top_, wides_.data(), fr, anchor_);
            return unionOnly_ ? unionQuery<kAnyHit>(boxes, ray, tmin, tmax, ctx, obs, hit)
                              : walk<kAnyHit>(boxes, SlabRay(fr), ray, tmin, tmax, ctx, obs, hit);
        }
        const WideBoxes<false> boxes(&top_, wides_.data(), fr, anchor_);
        return unionOnly_ ? unionQuery<kAnyHit>(boxes, ray, tmin, tmax, ctx, obs, hit)
                          : walk<kAnyHit>(boxes, SlabRay(fr), ray, tmin, tmax, ctx, obs, hit);
    }
    /// A union-only scene's query: the first-start walk, and the walk in box-entry order when
    /// that one cannot decide.
    template <bool kAnyHit, class Boxes, class Obs>
    bool unionQuery(const Boxes& boxes, const Ray& ray, double tmin, double tmax, TraceContext& ctx,
                    Obs& obs, Hit& hit) const {
        BvhEntry root;
        if (!boxes.root(_mm_set1_ps(floatDown(tmin)), _mm_set1_ps(floatUp(tmax)), root))
            return false;
        const int r = firstStart<kAnyHit>(boxes, root, ray, tmin, tmax, ctx, obs, hit);
        if (r >= 0) return r == 1;
        if constexpr (Obs::kActive)
            obs.walkRestart(
                "bvh: the ray begins inside a primitive "
                "or two starts tie; walked in order");
        return walkUnion(boxes, root, ray, tmin, tmax, ctx, obs, hit);
    }
    // Each walk reads the boxes through `boxes` (bvh_boxes.h: the ray in the BVH's frame) and
    // tests the leaves' primitives with the world ray `ray`.
    /// The walk of a scene with intersections or differences: leaves list every primitive
    /// meeting their box, with its restricted tree; front to back by a stack, each leaf's hit
    /// inside its box (`slab`: the ray in the frame, for the leaves' double boxes), the nearest
    /// kept. Each leaf's hit is a boundary of the whole scene (its tree agrees with the scene's
    /// inside its box), so with kAnyHit the first one ends it.
    template <bool kAnyHit, class Boxes, class Obs>
    bool walk(const Boxes& boxes, const SlabRay& slab, const Ray& ray, double tmin, double tmax,
              TraceContext& ctx, Obs& obs, Hit& hit) const;
    /// A union-only scene's walk for a ray that begins outside every primitive, most rays: the
    /// union's first boundary is then the first start of a span after tmin, and the walk is a
    /// closest-hit walk (a stack, nodes beyond the nearest start culled). Returns 1 (hit), 0
    /// (none), or -1 when a span holds tmin or two starts tie for the first: walkUnion decides.
    /// With kAnyHit, any start in (tmin, tmax] proves a boundary there once the ray is known to
    /// begin outside every primitive: from then on only the nodes whose box holds the ray's
    /// start (entered at tmin) are walked, to rule out a span holding tmin; ties do not matter.
    /// kOct: made for rays of that octant (WideBoxes::octant), -1 for any.
    template <bool kAnyHit, int kOct, class Boxes, class Obs>
    int walkFirstStart(const Boxes& boxes, const BvhEntry& root, const Ray& ray, double tmin,
                       double tmax, TraceContext& ctx, Obs& obs, Hit& hit) const;
    /// walkFirstStart, made for the ray's octant: the render's walks, whose node visits then
    /// read the faces at constant offsets (balls:6's render: 5% fewer instructions); an observed
    /// walk or a ray with a parallel axis takes the one for any.
    template <bool kAnyHit, class Boxes, class Obs>
    int firstStart(const Boxes& boxes, const BvhEntry& root, const Ray& ray, double tmin,
                   double tmax, TraceContext& ctx, Obs& obs, Hit& hit) const {
        if constexpr (!Boxes::kHasParallel && !Obs::kActive) {
            using Walk = int (Bvh::*)(const Boxes&, const BvhEntry&, const Ray&, double, double,
                                      TraceContext&, Obs&, Hit&) const;
            static constexpr auto kWalks = []<int... k>(std::integer_sequence<int, k...>) {
                return std::array<Walk, 8>{&Bvh::walkFirstStart<kAnyHit, k, Boxes, Obs>...};
            }
            (std::make_integer_sequence<int, 8>());
            return (this->*kWalks[boxes.octant])(boxes, root, ray, tmin, tmax, ctx, obs, hit);
        } else {
            return walkFirstStart<kAnyHit, -1>(boxes, root, ray, tmin, tmax, ctx, obs, hit);
        }
    }
    /// The walk of a union-only scene: each primitive in one leaf only, leaves in order of the
    /// t their box is entered at (a heap), their primitives' spans merged as they come. When a
    /// node is entered at t, every span that starts before t is known (its primitive's box lies
    /// in a leaf entered before it). The union's first boundary after tmin is the first start
    /// when the ray begins outside every primitive, else the end of the stretch it begins in;
    /// either is final once the next node is entered beyond it. (A stretch grows as spans join
    /// it, so a node is culled when taken from the heap, never when pushed.)
    template <class Boxes, class Obs>
    bool walkUnion(const Boxes& boxes, const BvhEntry& root, const Ray& ray, double tmin,
                   double tmax, TraceContext& ctx, Obs& obs, Hit& hit) const;
    /// Inner entry `e`'s children the ray may meet within [tmin, tmax] (float bounds, rounded
    /// outward), pushed far ones first so that the nearest is walked next (kNearFirst; else in
    /// the node's order); told to the observer.
    template <bool kNearFirst, int kOct, class Boxes, class Obs>
    void pushChildren(const Boxes& boxes, const BvhEntry& e, __m128 tmin, __m128 tmax,
                      BvhEntry* stack, int& sp, Obs& obs) const;
    /// Tells the observer inner entry `e`'s children met: c[0, n), in the order walked.
    template <class Obs>
    static void tellChildren(const BvhEntry& e, const BvhEntry* c, int n, Obs& obs);
    /// The spans along `ray` of a union-only scene's entry `x`, into `out` (how many), counted
    /// and told to the observer: a sphere tested from the entry, anything else by the scene.
    template <class Obs>
    int unionSpans(const BvhUnionEntry& x, const Ray& ray, TraceContext& ctx, Obs& obs,
                   Span* out) const {
        const int k = x.r >= 0.0 && ctx.precision == Precision::Double
                          ? sphereSpans(x.c, x.r, ray, x.prim, out)
                          : scene_->primSpans(x.prim, ray, out, ctx.precision);
        ++ctx.counters.primTests;
        obs.primTest(x.prim, out, k);
        return k;
    }
    /// The leaf's visible hit inside [t0, t1] (t > tmin).
    template <class Obs>
    bool hitInLeafBox(const BvhNode& n, const Ray& ray, double tmin, double t0, double t1,
                      TraceContext& ctx, Obs& obs, Hit& hit) const;

    const Scene* scene_ = nullptr;
    GridFrame frame_;
    bool unionOnly_ = false;  ///< the scene's tree has only unions: leaves keep no tree
    int depth_ = 0;
    std::vector<BvhNode> nodes_;
    std::vector<BvhWideNode> wides_;
    /// The root in a wide node's slot 0 (the other slots unused): the walks test it as any node.
    BvhWideNode top_ = BvhWideNode::empty();
    Vec3 anchor_{0.0};
    std::vector<uint32_t> parent_;
    std::vector<uint32_t> primList_;
    std::vector<BvhUnionEntry> unionEntries_;
    CsgTree pool_;

    friend struct BvhBuilder;
};

template <class Obs>
[[gnu::always_inline]] inline bool Bvh::hitInLeafBox(const BvhNode& n, const Ray& ray, double tmin,
                                                     double t0, double t1, TraceContext& ctx,
                                                     Obs& obs, Hit& hit) const {
    const uint32_t* const prims = primList_.data() + n.first;
    if (ctx.precision == Precision::Float) [[unlikely]]
        widenForFloat(ray, t0, t1);
    if (unionOnly_) {
        const bool found =
            hitInUnionLeaf(prims, n.count, ScenePrimTest{scene_, &ray, ctx.precision}, tmin, t0, t1,
                           ctx, obs, hit);
        if constexpr (Obs::kActive) {
            mergeHeldSpans(prims, n.count, ctx);  // the leaf's spans, as the other schemes show
            obs.regionSpans(ctx.result);
        }
        return found;
    }
    if (n.root < 0) return false;
    if (!ctx.useMailboxes) ctx.newStamp();
    // A leaf over more than kLazyLeafPrims primitives evaluates its tree lazily, as hitInLeaf
    // does (eval.h): on builtin:lattice:6 its up-front tests made 253 tests per ray, brute
    // force 149, the lazy tree 89. Smaller ones test their primitives first and evaluate the
    // tree only when one has a boundary inside the leaf's box.
    if (n.count > kLazyLeafPrims) {
        evalTree<Obs, Fetch::Counted>(*scene_, pool_, n.root, ray, ctx, obs, 0, ctx.result);
        if constexpr (Obs::kActive) obs.regionSpans(ctx.result);
        const Boundary* b = firstBoundary(ctx.result, tmin, t0, t1);
        if (b) hit = {b->t, b->prim, b->part, b->flip};
        return b != nullptr;
    }
    // Every boundary of a CSG result is a boundary of one of its primitives: when none of the
    // leaf's primitives has one in the window, the tree is not evaluated. Unlike the regular
    // walk's pending boundaries, this holds whatever order the leaves come in.
    const double from = std::max(t0, tmin);
    bool any = false;
    for (uint32_t i = 0; i < n.count; ++i) {
        const Mailbox& m = mailboxSpans(*scene_, prims[i], ray, ctx, obs);
        for (int k = 0; k < m.count; ++k) {
            const Span& s = m.spans[k];
            any |= (s.in.t >= from && s.in.t > tmin && s.in.t <= t1) ||
                   (s.out.t >= from && s.out.t > tmin && s.out.t <= t1);
        }
    }
    if (!any && !Obs::kActive) return false;  // the observer is shown the spans anyway
    evalTree<Obs, Fetch::Fresh>(*scene_, pool_, n.root, ray, ctx, obs, 0, ctx.result);
    if constexpr (Obs::kActive) obs.regionSpans(ctx.result);
    const Boundary* b = firstBoundary(ctx.result, tmin, t0, t1);
    if (b) hit = {b->t, b->prim, b->part, b->flip};
    return b != nullptr;
}

template <bool kNearFirst, int kOct, class Boxes, class Obs>
[[gnu::always_inline]] inline void Bvh::pushChildren(const Boxes& boxes, const BvhEntry& e,
                                                     __m128 tmin, __m128 tmax, BvhEntry* stack,
                                                     int& sp, Obs& obs) const {
    BvhEntry* const c = stack + sp;
    const int n = boxes.template children<kOct>(e, tmin, tmax, c);
    // Far to near: the nearest on top. At most four, so an insertion sort in place.
    for (int i = 1; kNearFirst && i < n; ++i) {
        const BvhEntry x = c[i];
        int j = i;
        for (; j > 0 && c[j - 1].t0 < x.t0; --j) c[j] = c[j - 1];
        c[j] = x;
    }
    if constexpr (Obs::kActive) {
        BvhEntry walked[kBvhWidth];  // the top of the stack first
        for (int i = 0; i < n; ++i) walked[i] = c[n - 1 - i];
        tellChildren(e, walked, n, obs);
    }
    sp += n;
}

template <class Obs>
void Bvh::tellChildren(const BvhEntry& e, const BvhEntry* c, int n, Obs& obs) {
    uint32_t ids[kBvhWidth];
    double t0s[kBvhWidth];
    for (int i = 0; i < n; ++i) ids[i] = c[i].node, t0s[i] = c[i].t0;
    obs.nodeChildren(e.node, ids, t0s, n);
}

template <bool kAnyHit, int kOct, class Boxes, class Obs>
int Bvh::walkFirstStart(const Boxes& boxes, const BvhEntry& root, const Ray& ray, double tmin,
                        double tmax, TraceContext& ctx, Obs& obs, Hit& hit) const {
    BvhEntry stack[kWalkStack];
    int sp = 0;
    stack[sp++] = root;
    // The first start after tmin so far. The ray begins outside every primitive as long as no
    // span holds tmin; a primitive whose box holds the ray's start is in a leaf entered at
    // tmin (the float interval begins no later), never culled, so a span holding tmin is
    // always met.
    Boundary first{tmax};
    bool found = false, tie = false;
    // Nodes whose box begins beyond `reach` are culled: the nearest start found; with kAnyHit,
    // tmin once a start is found (only the boxes holding the ray's start are left to walk).
    double reach = tmax;
    const __m128 tminV = _mm_set1_ps(floatDown(tmin));  // for the float box tests
    // For the float box tests, and to cull: a node entered after reachF is entered after reach
    // (the few in between are walked for nothing, never culled wrongly).
    float reachF = floatUp(reach);
    __m128 reachV = _mm_set1_ps(reachF);
    Span local[2];  // a primitive's spans (out of the loop: Span's members are initialised)
    while (sp > 0) {
        const BvhEntry e = stack[--sp];
        if (e.t0 > reachF) {
            if constexpr (Obs::kActive) obs.nodeCulled(e.node, e.t0, first.t, kAnyHit && found);
            continue;
        }
        ++ctx.counters.regionVisits;
        obs.region(e.node, e.t0, std::min(double(e.t1), first.t));
        if (!e.leaf()) {
            // A shadow ray's walk ends at any start: the order only costs.
            pushChildren<!kAnyHit, kOct>(boxes, e, tminV, reachV, stack, sp, obs);
            continue;
        }
        // The leaf's entries, read from its slot without its binary node.
        for (const BvhUnionEntry* x = unionEntries_.data() + e.first();; ++x) {
            const int k = unionSpans(*x, ray, ctx, obs, local);
            for (int j = 0; j < k; ++j) {
                const Span& sp2 = local[j];
                if (!(sp2.out.t > tmin)) continue;
                if (!(sp2.in.t > tmin)) return -1;  // the ray begins inside it
                // (tmin, tmax] holds the first start found; then only a nearer one.
                if (found ? sp2.in.t < first.t : sp2.in.t <= tmax) {
                    first = sp2.in;
                    found = true;
                    tie = false;
                    reach = kAnyHit ? tmin : first.t;
                    reachF = floatUp(reach);
                    reachV = _mm_set1_ps(reachF);
                } else if (found && sp2.in.t == first.t) {
                    tie = !kAnyHit;
                }
            }
            if (x->last) break;
        }
        if constexpr (Obs::kActive) {
            ctx.result.clear();
            if (found) ctx.result.push_back({first, first});
            obs.regionSpans(ctx.result);
        }
    }
    if (tie) return -1;
    if (found) hit = {first.t, first.prim, first.part, first.flip};
    return found ? 1 : 0;
}

template <class Boxes, class Obs>
bool Bvh::walkUnion(const Boxes& boxes, const BvhEntry& root, const Ray& ray, double tmin,
                    double tmax, TraceContext& ctx, Obs& obs, Hit& hit) const {
    // A min-heap by entry t, one per thread, reused from ray to ray. The float intervals begin
    // no later than the double ones, so a node is still taken before any span in it starts.
    auto later = [](const BvhEntry& a, const BvhEntry& b) { return a.t0 > b.t0; };
    thread_local std::vector<BvhEntry> heap;
    heap.assign(1, root);
    SpanList& spans = ctx.leafSpans;  // the spans met so far that end after tmin
    spans.clear();
    double best = tmax;  // the union's first boundary after tmin among the spans known
    const float tminF = floatDown(tmin), tmaxF = floatUp(tmax);  // for the float box tests
    bool found = false;
    while (!heap.empty()) {
        std::pop_heap(heap.begin(), heap.end(), later);
        const BvhEntry e = heap.back();
        heap.pop_back();
        if (e.t0 > best) {  // every node left begins beyond it: the boundary is final
            if constexpr (Obs::kActive) obs.nodeCulled(e.node, e.t0, best, false);
            break;
        }
        ++ctx.counters.regionVisits;
        obs.region(e.node, e.t0, std::min(double(e.t1), best));
        if (!e.leaf()) {
            BvhEntry c[kBvhWidth];
            const int n = boxes.children(e, tminF, tmaxF, c);
            for (int k = 0; k < n; ++k) {
                heap.push_back(c[k]);
                std::push_heap(heap.begin(), heap.end(), later);
            }
            if constexpr (Obs::kActive) {
                std::sort(c, c + n,
                          [](const BvhEntry& a, const BvhEntry& b) { return a.t0 < b.t0; });
                tellChildren(e, c, n, obs);
            }
            continue;
        }
        bool added = false;
        for (const BvhUnionEntry* x = unionEntries_.data() + e.first();; ++x) {
            Span local[2];
            const int k = unionSpans(*x, ray, ctx, obs, local);
            for (int j = 0; j < k; ++j)
                if (local[j].out.t > tmin && local[j].in.t <= tmax) {
                    spans.push_back(local[j]);
                    added = true;
                }
            if (x->last) break;
        }
        if (added) {
            flatUnion(spans, ctx.result);  // sorts `spans` in place
            const Boundary* b = firstBoundary(ctx.result, tmin, tmin, tmax);
            found = b != nullptr;
            if (b) hit = {b->t, b->prim, b->part, b->flip};
            best = b ? b->t : tmax;
        }
        if constexpr (Obs::kActive) {
            flatUnion(spans, ctx.result);
            obs.regionSpans(ctx.result);
        }
    }
    return found;
}

template <bool kAnyHit, class Boxes, class Obs>
bool Bvh::walk(const Boxes& boxes, const SlabRay& slab, const Ray& ray, double tmin, double tmax,
               TraceContext& ctx, Obs& obs, Hit& hit) const {
    // Push the far children, go on with the nearest.
    BvhEntry stack[kWalkStack];
    int sp = 0;
    double best = tmax;  // the leaves' windows end at the nearest hit found so far
    const __m128 tminV = _mm_set1_ps(floatDown(tmin));  // for the float box tests
    float bestF = floatUp(best);                        // for the float box tests and the culling
    __m128 bestV = _mm_set1_ps(bestF);
    bool found = false;
    if (!boxes.root(tminV, bestV, stack[sp++])) return false;
    while (sp > 0) {
        const BvhEntry e = stack[--sp];
        if (e.t0 > bestF) {  // its box begins beyond the hit: nothing nearer in it
            if constexpr (Obs::kActive) obs.nodeCulled(e.node, e.t0, best, false);
            continue;
        }
        if (e.leaf()) {
            // A leaf's window is its double box's, exactly: its tree agrees with the scene's
            // only inside that box. A box only the float test meets is passed over.
            const BvhNode& n = nodes_[e.node];
            double t0, t1;
            if (!slab.clip(n, tmin, kInf, t0, t1)) continue;
            if (t0 > best) {
                if constexpr (Obs::kActive) obs.nodeCulled(e.node, t0, best, false);
                continue;
            }
            t1 = std::min(t1, best);
            ++ctx.counters.regionVisits;
            obs.region(e.node, t0, t1);
            Hit h;
            if (hitInLeafBox(n, ray, tmin, t0, t1, ctx, obs, h) && (!found || h.t < best)) {
                hit = h;
                best = h.t;
                bestF = floatUp(best);
                bestV = _mm_set1_ps(bestF);
                found = true;
                if constexpr (kAnyHit) return true;
            }
            continue;
        }
        ++ctx.counters.regionVisits;
        obs.region(e.node, e.t0, std::min(double(e.t1), best));
        pushChildren<!kAnyHit, -1>(boxes, e, tminV, bestV, stack, sp, obs);
    }
    return found;
}

}  // namespace lancer
