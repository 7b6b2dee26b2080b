// The regular subdivision (report, section 3): a BSP over the scene box cut at the middle, on x,
// y, z in turn as in the report or on the axes a cost estimate picks level by level (the same
// axis for every node of a level), its leaves reached through a directory at the finest level (full
// table or Tamminen sub-tables), and a ray walk from leaf to leaf by one of two methods:
//  - push (the report's): push the exit point by `delta` across the exit face, edge or corner
//    and locate it; a delta too large skips thin cells, a delta too small stalls;
//  - exact: leaves are aligned on the directory's integer grid, so the next cell's index on the
//    exit axis is known exactly and the other indices come from the exit point clamped into
//    the exit face's range. No epsilon: no skipped cell, no stall. Across a face that one leaf
//    covers, the leaf's rope names it and the directory is not consulted.
// In each leaf, the tree is evaluated only when a primitive boundary lies in the leaf's interval.
#pragma once

#include <nlohmann/json.hpp>
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

#include "engine/accel/build_params.h"
#include "engine/accel/eval.h"
#include "engine/accel/regular/directory.h"
#include "engine/accel/regular/grid_frame.h"

namespace lancer {

class BuildGuard;  // engine/accel/build_guard.h

/// A BSP leaf: its block of the finest grid, [lo, hi) per axis, and its restricted tree; with
/// everything the walk reads of it in one 128-byte block (two cache lines the hardware fetches
/// together): its exit planes, ropes, tree, and up to kInline of its primitives (3.9 on average
/// on balls4), so most leaves need no primList.
struct alignas(128) RegularLeaf {
    static constexpr uint32_t kInline = 5;
    double plane[6] = {};  ///< lo x, y, z then hi x, y, z: the grid planes at lo and hi
    uint32_t lo[3] = {}, hi[3] = {};
    int32_t root = -1;   ///< restricted tree in the shared pool; -1: empty
    uint32_t prims = 0;  ///< primitives in the restricted tree
    uint32_t first = 0;  ///< where they are listed in RegularGrid::primList(), shared like trees
    /// Ropes (Havran): the leaf across each face, 2 * axis + (1 for the hi face), when one leaf
    /// covers the whole face; kSplitFace when several do (the directory finds which one);
    /// kBorder on the grid's border. A rope is a cached directory lookup: the same leaf.
    uint32_t rope[6] = {};
    uint32_t inlined[kInline] = {};  ///< the primitives when prims <= kInline
    /// The leaf's primitives, `prims` of them.
    const uint32_t* primitives(const uint32_t* primList) const {
        return prims <= kInline ? inlined : primList + first;
    }
};
static_assert(sizeof(RegularLeaf) == 128);

/// Four consecutive entries of RegularGrid::primList() (4q .. 4q + 3, whatever leaves list them)
/// as floats, for the walk's first look at a union-only leaf's spheres: the centre, and the radius
/// grown by an allowance for the floats' rounding (RegularGrid::sphereQuads). An entry that is no
/// packed sphere has an infinite radius: it is never rejected.
struct alignas(64) SphereQuad {
    float x[4], y[4], z[4], r[4];
};
static_assert(sizeof(SphereQuad) == 64);

inline constexpr uint32_t kSplitFace = 0xffffffffu;
inline constexpr uint32_t kBorder = 0xfffffffeu;

class RegularGrid {
  public:
    static constexpr SchemeKind kKind = SchemeKind::Regular;  ///< its row of kSchemeTable
    /// Its knobs in `p`.
    static const RegularConfig& config(const BuildParams& p) { return p.regular; }

    /// BSP nodes allowed while building (4M: about 200 MiB of nodes, leaves and tables). An
    /// absurd max-level / max-objects pair is refused after bounded work (a few seconds at
    /// most) even under a large memory budget; the largest useful builds measured (lattice at
    /// level 21, max-objects 1) need 2.7M.
    static constexpr size_t kMaxBspNodes = size_t(1) << 22;
    /// Primitives of a cell whose two halves the build makes as parallel tasks (on balls:6 a
    /// cell of 4096 spheres is about a millisecond of building, far above a task's cost). The
    /// structure does not depend on it, nor on the threads.
    static constexpr size_t kTaskPrims = 4096;

    /// Build over a prepared scene. Throws std::invalid_argument naming the option when the
    /// parameters are invalid or the structure would pass the guard's memory budget (estimated
    /// as the BSP grows, so the refusal comes early), BuildCancelled when `guard`'s stop is
    /// requested. `guard` null: a default BuildGuard (the default budget, no cancellation).
    RegularGrid(const Scene& scene, const RegularConfig& params, BuildGuard* guard = nullptr);
    /// The same, in the build shape every scheme has; the scheme's figures go to `extra`.
    static RegularGrid build(const Scene& scene, const RegularConfig& config, nlohmann::json& extra,
                             BuildGuard* guard = nullptr) {
        RegularGrid g(scene, config, guard);
        extra = g.extra();
        return g;
    }

    /// Nearest visible hit with t in (tmin, tmax], walking the leaves in ray order.
    template <class Obs>
    bool intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                   Hit& hit) const;

    size_t regionCount() const { return leaves_.size(); }
    size_t memoryBytes() const {
        return leaves_.size() * sizeof(RegularLeaf) + pool_.nodes.size() * sizeof(CsgNode) +
               primList_.size() * sizeof(uint32_t) + quads_.size() * sizeof(SphereQuad) +
               (planes_[0].size() + planes_[1].size() + planes_[2].size()) * sizeof(double) +
               dir_.memoryBytes();
    }
    bool usesMailboxes() const { return true; }

    /// Scheme-specific figures for `--stats` (full-table size, leaves, depth per axis...).
    nlohmann::json extra() const { return extra_; }
    const std::vector<RegularLeaf>& leaves() const { return leaves_; }
    const CsgTree& treePool() const { return pool_; }
    /// Primitives of the leaves' trees: leaf L's are primList()[L.first, L.first + L.prims).
    const std::vector<uint32_t>& primList() const { return primList_; }
    const Directory& directory() const { return dir_; }
    /// The grid's box in its frame: the scene bounds, widened on an axis where they are flat.
    const Box3& box() const { return box_; }
    /// The frame the grid's cells, box, planes and leaves are in (grid_frame.h): the world's
    /// axes, or a turned subtree's.
    const GridFrame& frame() const { return frame_; }
    /// Each primitive's minimized box in the grid's frame (the scene's minBox when not turned).
    const std::vector<Box3>& boxes() const { return frame_.turned ? frameBoxes_ : scene_->minBox; }
    /// Directory cells per axis, 2^n.
    uint32_t cells(int axis) const { return n_[axis]; }
    /// The axis each level of the BSP cuts.
    const AxisSchedule& schedule() const { return schedule_; }
    /// Coordinate of grid plane k (0..2^n) on `axis`; plane 2^n is exactly box().hi.
    double plane(int axis, uint32_t k) const { return planes_[axis][k]; }
    /// The report's point location, 0-based: floor((x - min) / (max - min) * 2^n), clamped; the
    /// quotient is a product by the precomputed 2^n / (max - min). Truncation is the floor here,
    /// the quotient being positive.
    uint32_t locate(int axis, double x) const {
        const double f = (x - box_.lo[axis]) * scale_[axis];
        if (!(f >= 0.0)) return 0;  // also NaN
        return f >= double(n_[axis]) ? n_[axis] - 1 : uint32_t(f);
    }
    /// "leaf 12 cells [8,12)x[0,8)x[8,16) Box3{..} 2 prims (p1 − p11)": for messages and traces.
    std::string describeLeaf(uint32_t id) const;
    /// Leaf holding a world point (clamped into the grid).
    uint32_t leafAt(const Vec3& world) const {
        const Vec3 p = frame_.toFrame(world);
        return dir_.lookup(locate(0, p.x), locate(1, p.y), locate(2, p.z));
    }

    /// primList() as SphereQuads, four entries each: empty unless the scene is union-only and
    /// holds packed spheres.
    const std::vector<SphereQuad>& sphereQuads() const { return quads_; }
    /// The ray as the quads' test takes it: a point of it in floats (the walk's point in the
    /// leaf), its direction as a unit vector in floats, and an allowance for the rounding of the
    /// exact test far from the ray's origin.
    struct QuadRay {
        using F4 = float __attribute__((vector_size(16)));
        F4 p[3], d[3];  ///< each coordinate in the four lanes
        F4 allowance;
        /// Set the point to `at`.
        void at(const Vec3& at) {
            for (int a = 0; a < 3; ++a) {
                const float x = float(at[a]);
                p[a] = F4{x, x, x, x};
            }
        }
    };
    /// The ray for the quads' test, its point at the ray's origin (QuadRay::p is set to a point
    /// near each leaf the walk tests).
    QuadRay quadRay(const Ray& ray) const;
    /// Bit j set: entry 4q + j of primList() is a sphere whose exact test (Scene::primSpans)
    /// finds no span along the ray, as the floats of quad q tell. A clear bit says nothing.
    static uint32_t quadMisses(const SphereQuad& q, const QuadRay& r);
    /// Bit i set: entry `from` + i of primList() is such a sphere, for i < `count` <= 60.
    uint64_t entryMisses(uint32_t from, uint32_t count, const QuadRay& r) const {
        const SphereQuad* const q = quads_.data();
        uint64_t bits = 0;
        for (uint32_t k = 0, n = (from % 4 + count + 3) / 4; k < n; ++k)
            bits |= uint64_t(quadMisses(q[from / 4 + k], r)) << (4 * k);
        return (bits >> (from % 4)) & ((uint64_t(1) << count) - 1);
    }

  private:
    /// intersect() for one step method.
    template <bool kExact, class Obs>
    bool walk(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
              Hit& hit) const;
    /// hitInUnionLeaf for leaf `L` of a union-only scene with sphere quads, the same hit: the
    /// leaf's spheres are first looked at in floats four at a time (quadMisses), and only those
    /// the floats cannot reject go through the mailboxes and the exact test. A rejected sphere
    /// is a test each time a leaf lists it, its mailbox untouched (most of the tags' cache misses
    /// spared): the counts differ from hitInUnionLeaf's by the mailbox hits of rejected spheres,
    /// counted as tests here. An active observer is told each test and mailbox hit, and the
    /// leaf's merged spans.
    template <class Obs>
    bool hitInSphereLeaf(const RegularLeaf& L, QuadRay& qr, const Ray& ray, double tmin, double tIn,
                         double t0, double t1, TraceContext& ctx, Obs& obs, Hit& hit) const;
    /// Fill quads_ from primList_ (union-only scenes with packed spheres).
    void makeSphereQuads();

    const Scene* scene_;
    bool exact_ = true;       ///< --step exact (else push)
    bool unionOnly_ = false;  ///< the scene's tree has only unions: so has every leaf's
    double delta_ = 0.0;      ///< absolute push distance
    GridFrame frame_;
    std::vector<Box3> frameBoxes_;  ///< boxes() when the frame is turned
    Box3 box_;
    Box3 clipBox_;  ///< box_ grown by a hair: a grazing ray whose hit rounds outside still enters
    Vec3 ext_{0.0};
    AxisSchedule schedule_;
    uint32_t n_[3] = {1, 1, 1};
    double scale_[3] = {1.0, 1.0, 1.0};  ///< 2^n / extent, for locate
    std::vector<double> planes_[3];      ///< grid plane coordinates, 2^n + 1 per axis
    size_t maxSteps_ = 16;
    std::vector<RegularLeaf> leaves_;
    CsgTree pool_;  ///< restricted trees of all leaves, shared between equal primitive sets
    std::vector<uint32_t> primList_;  ///< each distinct primitive set once, as leaves list it
    std::vector<SphereQuad> quads_;   ///< primList_ in floats, four entries a quad
    double quadScale_ = 0.0;          ///< the grid's largest coordinate, for a ray's allowance
    Directory dir_;
    nlohmann::json extra_;

    friend struct RegularBuilder;
};

template <class Obs>
bool RegularGrid::intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                            Hit& hit) const {
    return exact_ ? walk<true>(ray, tmin, tmax, ctx, obs, hit)
                  : walk<false>(ray, tmin, tmax, ctx, obs, hit);
}

template <bool kExact, class Obs>
bool RegularGrid::walk(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                       Hit& hit) const {
    // The cells are walked with the ray in the grid's frame (`fr`, the same t for the same
    // point), the primitives tested with the world ray; points told are the world's.
    Ray mapped;
    if (frame_.turned) mapped = frame_.toFrame(ray);
    const Ray& fr = frame_.turned ? mapped : ray;
    double tA, tB;
    if (!clipLine(fr, clipBox_, tA, tB)) return false;
    const double tStart = std::max(tmin, tA), tEnd = std::min(tmax, tB);
    if (!(tStart <= tEnd)) return false;
    Vec3 p = std::isfinite(tStart) ? fr.at(tStart) : fr.o;
    uint32_t leaf = dir_.lookup(locate(0, p.x), locate(1, p.y), locate(2, p.z));
    if constexpr (Obs::kActive) {
        const uint32_t cell[3] = {locate(0, p.x), locate(1, p.y), locate(2, p.z)};
        obs.lookup(frame_.toWorld(p), cell, leaf);
    }
    // Per ray, held locally (the loop's stores to mailboxes and counters could otherwise alias
    // the ray and the arrays, and each step would reload them): the origin, 1/d, so each exit
    // plane costs a product, not a division, and the side a cell is left by on each axis. An axis
    // the ray runs parallel to is never an exit: its plane gets a factor 0 and a bias of +inf;
    // on the others the bias is 0, which leaves the product bit for bit unchanged.
    const double o[3] = {fr.o.x, fr.o.y, fr.o.z};
    const bool up[3] = {fr.d.x > 0.0, fr.d.y > 0.0, fr.d.z > 0.0};
    double inv[3], bias[3];
    uint32_t
        side[3];  // where a leaf's exit plane on each axis is in RegularLeaf::plane: lo a, hi 3 + a
    uint32_t rope[3];  // the rope across that plane
    for (int a = 0; a < 3; ++a) {
        const bool parallel = fr.d[a] == 0.0;
        inv[a] = parallel ? 0.0 : 1.0 / fr.d[a];
        bias[a] = parallel ? kInf : 0.0;
        side[a] = up[a] ? 3 + a : a;
        rope[a] = 2 * a + up[a];
    }
    const RegularLeaf* const leaves = leaves_.data();
    const uint32_t* const primList = primList_.data();
    const bool quads = !quads_.empty();
    QuadRay qr = quads ? quadRay(ray) : QuadRay{};
    // The first region is evaluated from tmin and the last one up to tmax: every primitive lies
    // inside the grid, so this only admits hits that rounding puts a hair outside the box.
    double t0 = tmin, tIn = tStart;
    // The stretches told start where the ray enters the grid's own box: the clip of the grown
    // box comes a hair before it, and a grazing ray runs outside the box for that hair.
    [[maybe_unused]] double tShown = tStart;
    if constexpr (Obs::kActive) {
        double a, b;
        if (clipLine(fr, box_, a, b)) tShown = std::max(tStart, a);
    }
    ctx.pending.clear();
    const size_t maxSteps = maxSteps_;
    for (size_t step = 0;; ++step) {
        if (step > maxSteps) {
            ++ctx.counters.walkErrors;
            obs.walkError("regular: step bound exceeded");
            return false;
        }
        const RegularLeaf& L = leaves[leaf];
        // Exit: the nearest of the cell's exit planes; ties are edges and corners.
        const double* const P = L.plane;
        double tAxis[3];
        double tExit = kInf;
        int exitAxis = 0;
        for (int a = 0; a < 3; ++a) {
            tAxis[a] = (P[side[a]] - o[a]) * inv[a] + bias[a];
            if (tAxis[a] < tExit) tExit = tAxis[a], exitAxis = a;
        }
        bool last = !(tExit < tEnd);
        bool stalled = false;
        uint32_t next[3];
        uint32_t nextLeaf = leaf;
        // How the walk leaves the leaf, told to an active observer after the leaf's own events.
        [[maybe_unused]] const bool leaves = !last;
        [[maybe_unused]] int how = 0;    // 1 rope, 2 index step + lookup, 3 push + lookup
        [[maybe_unused]] Vec3 pushed{};  // set before use; initialised for -Wmaybe-uninitialized
        if (!last) {
            if constexpr (kExact) {
                // The exit face lies on grid plane L.hi or L.lo of exitAxis: the next index there
                // is exact; the other indices are the exit point's, kept on the face. When one
                // leaf covers the whole face, the leaf's rope names it and no lookup is needed.
                const int a = exitAxis;
                const uint32_t across = L.rope[rope[a]];
                if (across == kBorder) {
                    last = true;
                } else if (across != kSplitFace) {
                    nextLeaf = across;
                    if constexpr (Obs::kActive) how = 1;
                } else {
                    const Vec3 q = fr.at(tExit);
                    next[a] = up[a] ? L.hi[a] : L.lo[a] - 1;
                    for (int b = 0; b < 3; ++b)
                        if (b != a) next[b] = std::clamp(locate(b, q[b]), L.lo[b], L.hi[b] - 1);
                    nextLeaf = dir_.lookup(next[0], next[1], next[2]);
                    if constexpr (Obs::kActive) how = 2;
                }
            } else {
                // The report's method: the exit point, taken on the cell's box (rounding can put
                // ray.at(tExit) a hair outside it), is pushed by delta across every face it
                // leaves through, then located. Off the pushed axes it stays in the cell's range,
                // so the walk cannot bounce back into the previous cell.
                const Vec3 q = fr.at(tExit);
                for (int a = 0; a < 3; ++a) {
                    double x = std::clamp(q[a], P[a], P[3 + a]);
                    if (tAxis[a] == tExit) {
                        x += up[a] ? delta_ : -delta_;
                        if (x < box_.lo[a] || x > box_.hi[a]) last = true;  // left the grid
                        next[a] = locate(a, x);
                    } else {
                        next[a] = std::clamp(locate(a, x), L.lo[a], L.hi[a] - 1);
                    }
                    if constexpr (Obs::kActive) pushed[a] = x;
                }
                if (!last) {
                    nextLeaf = dir_.lookup(next[0], next[1], next[2]);
                    stalled = nextLeaf == leaf;
                    if constexpr (Obs::kActive) how = 3;
                }
            }
        }
        const double t1 = last ? tmax : std::max(tExit, tIn);
        ++ctx.counters.regionVisits;
        if (!last) __builtin_prefetch(leaves_.data() + nextLeaf);
        // The stretch told ends where the ray leaves the leaf: at the clip of the grown box only
        // when that comes first. A ray leaving the grid through an edge or a corner may cross
        // the tied interior face as it leaves, so past the leaf's exit it is outside the leaf.
        if constexpr (Obs::kActive) {
            const double shownEnd = last ? std::min(tEnd, std::max(tExit, tIn)) : t1;
            obs.region(leaf, std::min(std::max(tIn, tShown), shownEnd), shownEnd);
        }
        // A union-only scene's leaf: its hit straight from its primitives' spans, through the
        // sphere quads when the grid has them, for every observer (what an observer sees is the
        // walk made: the same tests and mailbox hits); without quads, an active observer is
        // shown the tree's evaluation (hitInLeaf), with the same counts as hitInUnionLeaf.
        bool found;
        if (quads) {
            found = L.prims != 0 && hitInSphereLeaf(L, qr, ray, tmin, tIn, t0, t1, ctx, obs, hit);
        } else if constexpr (!Obs::kActive) {
            found = unionOnly_ ? hitInUnionLeaf(L.primitives(primList), L.prims,
                                                ScenePrimTest{scene_, &ray, ctx.precision}, tmin,
                                                t0, t1, ctx, obs, hit)
                               : hitInLeaf(*scene_, &pool_, L.root, L.primitives(primList), L.prims,
                                           ray, tmin, t0, t1, ctx, obs, hit);
        } else {
            found = hitInLeaf(*scene_, &pool_, L.root, L.primitives(primList), L.prims, ray, tmin,
                              t0, t1, ctx, obs, hit, unionOnly_);
        }
        if (found) return true;
        if constexpr (Obs::kActive) {
            int ties = 0;
            for (int a = 0; a < 3; ++a) ties |= int(tAxis[a] == tExit) << a;
            if (leaves) obs.regionExit(tExit, ray.at(tExit), exitAxis, ties);
            if (how == 1) obs.rope(leaf, int(rope[exitAxis]), nextLeaf);
            if (how == 2) obs.indexStep(exitAxis, next);
            if (how == 3) obs.push(frame_.toWorld(pushed), ties);
            if (how >= 2)
                obs.lookup(how == 3 ? frame_.toWorld(pushed) : ray.at(tExit), next, nextLeaf);
        }
        if (last) return false;
        if (stalled) {
            ++ctx.counters.walkErrors;
            obs.walkError("regular push: the pushed exit point is still in the same leaf");
            return false;
        }
        t0 = tIn = t1;
        leaf = nextLeaf;
    }
}

inline RegularGrid::QuadRay RegularGrid::quadRay(const Ray& ray) const {
    QuadRay r;
    const Vec3 u = ray.d / glm::length(ray.d);
    r.at(ray.o);
    for (int a = 0; a < 3; ++a) r.d[a] = QuadRay::F4{} + float(u[a]);
    // The exact test computes the line's distance to the centre from the ray's origin: its
    // rounding grows with that distance, some 1e-15 of it (the allowance is a thousand times
    // that).
    const double far = std::max({std::abs(ray.o.x), std::abs(ray.o.y), std::abs(ray.o.z)});
    r.allowance = QuadRay::F4{} + float(1e-12 * (far + quadScale_));
    return r;
}

inline uint32_t RegularGrid::quadMisses(const SphereQuad& q, const QuadRay& r) {
    using F4 = QuadRay::F4;
    using I4 = int32_t __attribute__((vector_size(16)));
    // The vector from the ray's point to each centre, and the line's distance to the centre
    // as |f x d| (d a unit vector): no cancellation but that of the cross product's terms.
    const F4 fx = *reinterpret_cast<const F4*>(q.x) - r.p[0];
    const F4 fy = *reinterpret_cast<const F4*>(q.y) - r.p[1];
    const F4 fz = *reinterpret_cast<const F4*>(q.z) - r.p[2];
    const F4 gx = fy * r.d[2] - fz * r.d[1];
    const F4 gy = fz * r.d[0] - fx * r.d[2];
    const F4 gz = fx * r.d[1] - fy * r.d[0];
    const F4 dist2 = gx * gx + gy * gy + gz * gz;
    // The floats' rounding: a few 1e-7 of |f| (bounded by its 1-norm) from f, d and the cross
    // product, besides the centre's and the point's own (in the stored radius, see
    // makeSphereQuads); allowed for ten times over.
    const I4 absMask = {0x7fffffff, 0x7fffffff, 0x7fffffff, 0x7fffffff};
    const F4 norm1 = reinterpret_cast<F4>(reinterpret_cast<I4>(fx) & absMask) +
                     reinterpret_cast<F4>(reinterpret_cast<I4>(fy) & absMask) +
                     reinterpret_cast<F4>(reinterpret_cast<I4>(fz) & absMask);
    const F4 reach = *reinterpret_cast<const F4*>(q.r) + r.allowance + 4e-6f * norm1;
    // NaN and infinities compare false: such a sphere is not rejected.
    const I4 miss = dist2 > reach * reach;
#if defined(__SSE2__)
    return uint32_t(_mm_movemask_ps(reinterpret_cast<__m128>(miss)));
#else
    return uint32_t(miss[0] & 1) | uint32_t(miss[1] & 2) | uint32_t(miss[2] & 4) |
           uint32_t(miss[3] & 8);
#endif
}

template <class Obs>
[[gnu::always_inline]] inline bool RegularGrid::hitInSphereLeaf(const RegularLeaf& L, QuadRay& qr,
                                                                const Ray& ray, double tmin,
                                                                double tIn, double t0, double t1,
                                                                TraceContext& ctx, Obs& obs,
                                                                Hit& hit) const {
    if (!ctx.useMailboxes) ctx.newStamp();
    const uint32_t* const keys = L.primitives(primList_.data());
    const uint32_t count = L.prims;
    TraceContext::Tag* const tags = ctx.tags.data();
    // The quads' floats are near the leaf: the walk's point in it (the ray's origin for a first
    // leaf entered from an infinite tmin).
    if (std::isfinite(tIn)) qr.at(ray.at(tIn));
    const uint32_t rayId = ctx.rayId;
    UnionFirstStart start{tmin, t0, t1};
    for (uint32_t from = 0; from < count; from += 60) {
        const uint32_t n = std::min(count - from, 60u);
        const uint64_t misses = entryMisses(L.first + from, n, qr);
        // A rejected sphere has no span: its mailbox is neither read nor written (most of the
        // tags' cache misses spared), and it is a test each time a leaf lists it. All n are
        // counted as tests here and the mailbox hits below taken back: without -mpopcnt a
        // popcount is a call.
        ctx.counters.primTests += n;
        const uint64_t take = ~misses & ((uint64_t(1) << n) - 1);
        // The others' tags and spheres, fetched together rather than one miss at a time.
        for (uint64_t b = take; b; b &= b - 1) {
            const uint32_t key = keys[from + uint32_t(__builtin_ctzll(b))];
            __builtin_prefetch(tags + key);
            __builtin_prefetch(scene_->packedSpheres.data() + key);
        }
        if constexpr (Obs::kActive)
            for (uint64_t b = misses; b; b &= b - 1)
                obs.primTest(keys[from + uint32_t(__builtin_ctzll(b))], nullptr, 0);
        for (uint64_t b = take; b; b &= b - 1) {
            const uint32_t key = keys[from + uint32_t(__builtin_ctzll(b))];
            TraceContext::Tag& tag = tags[key];
            const Mailbox* m;
            if (tag.stamp == rayId) {
                --ctx.counters.primTests;
                ++ctx.counters.mailboxHits;
                obs.mailboxHit(key);
                if (tag.slot == 0) continue;  // tested and missed
                m = &ctx.held[tag.slot];
            } else {
                // Storage for the spans the test writes, not cleared first (Span's members
                // have defaults: a declared array costs its clearing in each test).
                alignas(Span) std::byte room[2 * sizeof(Span)];
                Span* const spans = reinterpret_cast<Span*>(room);
                const int k = scene_->primSpans(key, ray, spans, ctx.precision);
                obs.primTest(key, spans, k);
                if (k == 0) {
                    tag = {rayId, 0};  // the empty mailbox, as ctx.heldEmpty
                    continue;
                }
                m = holdSpans(key, spans, k, ctx);
            }
            start.add(*m);
        }
    }
    if constexpr (Obs::kActive) {
        mergeHeldSpans(keys, count, ctx);  // the leaf's spans, as hitInLeaf shows them
        obs.regionSpans(ctx.result);
    }
    return start.hit(keys, count, ctx, hit);
}

}  // namespace lancer
