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
//
// Its files: regular_grid.cpp builds the grid step by step; regular_builder.h the BSP (with
// axis_planner.h, the axes of --split-axes cost, and set_pool.h, the leaves' primitive sets);
// directory.h the directory; grid_frame.h a turned scene's frame; sphere_quads.cpp the quads;
// regular_walk.h the walk.
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>

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
    /// The automatic depth is lowered (buildBsp()) no further than this.
    static constexpr int kMinAutoLevel = 8;
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
    // The walk's steps (regular_walk.h).
    struct WalkExit;
    struct WalkStep;
    /// intersect() for one step method.
    template <bool kExact, class Obs>
    bool walk(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
              Hit& hit) const;
    /// The leaf holding the walk's first point, at `tStart` on `fr` (the ray in the grid's frame).
    template <class Obs>
    uint32_t startLeaf(const Ray& fr, double tStart, Obs& obs) const;
    /// Where the stretches told to an active observer start: where the ray enters the grid's
    /// own box, at or after `tStart`.
    template <class Obs>
    double shownStart(const Ray& fr, double tStart) const;
    /// A walk error counted and told: false, the walk's end without a hit.
    template <class Obs>
    static bool walkError(TraceContext& ctx, Obs& obs, const char* what);
    /// The leaf across the exit face by --step exact, into `s` (`up`: the ray goes up the exit
    /// axis, `rope`: the rope across the face): the rope's leaf when one leaf covers the face,
    /// else the directory's; `s.last` at the grid's border.
    template <class Obs>
    void stepExact(const RegularLeaf& L, const Ray& fr, const WalkExit& exit, bool up,
                   uint32_t rope, WalkStep& s) const;
    /// The leaf across the exit by --step push, into `s` (`up`: the ray goes up each axis): the
    /// exit point pushed by delta and located; `s.last` when it left the grid, `s.stalled` when
    /// it is still in the leaf.
    template <class Obs>
    void stepPush(const RegularLeaf& L, const Ray& fr, const WalkExit& exit, const bool up[3],
                  WalkStep& s) const;
    /// The nearest hit in leaf `L` over [t0, t1] (`primList`: primList()'s data), by the leaf
    /// test the scene and the observer call for.
    template <class Obs>
    bool hitInRegion(const RegularLeaf& L, const uint32_t* primList, bool quads, QuadRay& qr,
                     const Ray& ray, double tmin, double tIn, double t0, double t1,
                     TraceContext& ctx, Obs& obs, Hit& hit) const;
    /// How the walk left `leaf` (`exits`: by a face before the ray's end; `rope`: the rope
    /// across the exit face), told to an active observer after the leaf's own events.
    template <class Obs>
    void tellExit(uint32_t leaf, bool exits, const WalkExit& exit, uint32_t rope, const WalkStep& s,
                  const Ray& ray, Obs& obs) const;
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

    // The constructor's steps, in its order (regular_grid.cpp).
    /// The frame the grid is built in, a turned subtree's where its boxes are much smaller, its
    /// figures into `stats`: the scene's bounds in that frame.
    Box3 chooseFrame(const RegularConfig& params, nlohmann::json& stats);
    /// The grid's box from `bounds`, widened where they are flat, its clip box and push distance.
    void setBox(const Box3& bounds, double delta);
    /// The directory's resolution, 2^n cells per axis at the `finest` level, and its planes.
    void setResolution(int finest);
    /// The directory of `bsp`, refused over the memory budget: the full table's estimated bytes.
    size_t buildDirectory(const BspNodes& bsp, int finest, bool full, int maxLevel,
                          BuildGuard& guard);
    /// Each leaf's ropes, from the directory.
    void makeRopes(BuildGuard& guard);
    /// Fill quads_ from primList_ (union-only scenes with packed spheres; sphere_quads.cpp).
    void makeSphereQuads();
    /// Plane `i` of the grid cut `cuts` times on `axis` (i in 0..2^cuts); at the finest level the
    /// same as plane(), since i / 2^c == (i 2^(n-c)) / 2^n exactly in floating point.
    double planeAt(int axis, uint32_t i, int cuts) const {
        return i == (1u << cuts) ? box_.hi[axis]
                                 : box_.lo[axis] + ext_[axis] * std::ldexp(double(i), -cuts);
    }

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

}  // namespace lancer

#include "engine/accel/regular/regular_walk.h"  // the walk's templates
