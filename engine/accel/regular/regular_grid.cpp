#include "engine/accel/regular/regular_grid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <stdexcept>

#include "engine/accel/accelerator.h"
#include "engine/accel/build_guard.h"
#include "engine/accel/regular/axis_planner.h"
#include "engine/accel/regular/regular_builder.h"
#include "engine/util/format.h"
#include "engine/util/task_fence.h"

namespace lancer {

namespace {

/// Refuse parameters out of range, naming the option.
void checkRegularParams(const RegularConfig& params) {
    if (params.maxLevel < 0 || params.maxLevel > 48)
        throw std::invalid_argument("--max-level " + std::to_string(params.maxLevel) +
                                    ": must be in 0..48 for the regular scheme (0: automatic)");
    if (params.maxObjects < 1 && params.maxObjects != kAutoObjects)
        throw std::invalid_argument("--max-objects " + std::to_string(params.maxObjects) +
                                    ": must be at least 1 for the regular scheme (or auto)");
    if (params.step != StepMethod::Exact && !(params.delta > 0.0 && params.delta < 1.0))
        throw std::invalid_argument("--delta " + std::to_string(params.delta) +
                                    ": must be in (0, 1) (relative to the scene size)");
}

/// The grid's figures for --stats, `b` and `out` what built it, `fullBytes` the full table's
/// estimated size.
nlohmann::json regularStats(const RegularGrid& g, const RegularConfig& params,
                            const RegularBuilder& b, const RegularBuilder::Layout& out,
                            size_t fullBytes) {
    const RegularBuilder::LeafCounts& n = out.counts;
    const int finest = out.bsp.nodes[0].height;
    const size_t leaves = g.leaves().size();
    int depth[3];
    for (int a = 0; a < 3; ++a) depth[a] = g.schedule().cuts(finest, a);
    return {
        {"directory", params.fullTable ? "full" : "sub-tables"},
        {"directory_bytes", g.directory().memoryBytes()},
        {"full_table_bytes",
         fullBytes == SIZE_MAX ? nlohmann::json(nullptr) : nlohmann::json(fullBytes)},
        {"sub_tables", g.directory().tableCount()},
        {"leaves", leaves},
        {"empty_leaves", n.emptyLeaves},
        {"covered_leaves", n.coveredLeaves},
        {"solid_cells", n.solidCells},
        {"cost_leaves", n.costLeaves},
        {"gain_leaves", n.gainLeaves},
        // Why each leaf's cell was not split (docs/regular.md, "Stop reasons"): covered cells,
        // whose parts would all hold the same primitives, count as cost; a build over its memory
        // budget is refused, never stopped.
        {"stop_reasons",
         {{"max_objects", n.objectsLeaves},
          {"max_level", n.levelLeaves},
          {"cost", n.coveredLeaves + n.costLeaves},
          {"memory", 0}}},
        {"cost_stop", params.usesCostStop()},
        {"effective_max_level", b.maxLevel},
        {"gain_level",
         b.gainLevel < b.maxLevel ? nlohmann::json(b.gainLevel) : nlohmann::json(nullptr)},
        {"bsp_nodes", out.bsp.nodes.size()},
        {"finest_level", finest},
        {"depth_xyz", {depth[0], depth[1], depth[2]}},
        {"split_axes", splitAxesName(params.splitAxes)},
        {"axis_schedule", g.schedule().toString(finest)},
        {"distinct_trees", out.pool.size() - 1},  // the empty set has no tree
        {"tree_pool_nodes", g.treePool().nodes.size()},
        {"prims_per_leaf", leaves == 0 ? 0.0 : double(n.primRefs) / double(leaves)},
        {"max_prims_per_leaf", n.maxPrims},
        {"sphere_quad_bytes", g.sphereQuads().size() * sizeof(SphereQuad)},
    };
}

}  // namespace

RegularGrid::RegularGrid(const Scene& scene, const RegularConfig& params, BuildGuard* guardIn)
    : scene_(&scene), exact_(params.step == StepMethod::Exact) {
    // A union-only tree restricts to unions: every leaf's spans are its primitives' merged.
    unionOnly_ = scene.tree.unionOnly();
    BuildGuard ownGuard;
    BuildGuard& guard = guardIn ? *guardIn : ownGuard;
    checkRegularParams(params);
    nlohmann::json frameStats = {{"turned", false}};
    setBox(chooseFrame(params, frameStats), params.delta);

    // The automatic mode is the build's own choice of depth, so it keeps within the node limit
    // rather than being refused: a build that would pass it is made again with the automatic
    // depth kGainDepth levels shallower (example020's twisted spring: 159,193 nodes before the
    // cost estimate counted the mailboxes' savings, over 4M after; 2 levels left 3.0M).
    // Explicit knobs are the user's, refused with the options named.
    RegularConfig config = params;
    std::unique_ptr<RegularBuilder> built;
    RegularBuilder::Layout out;
    for (;;) {
        built = std::make_unique<RegularBuilder>(scene, config, *this, guard);
        // The axes come first: the builder cuts on them and its cost estimate reads them.
        if (config.splitAxes == SplitAxes::Cost)
            schedule_ = regular_build::planSchedule(boxes(), box_, built->live, built->quarters,
                                                    built->maxLevel, config.objects(), guard);
        try {
            RegularBuilder::Fragment root = built->buildFragments();
            out = built->layOut(root);
            break;
        } catch (const NodeLimitError&) {
            if (!config.automatic() || built->maxLevel <= kMinAutoLevel) throw;
            config.autoLevelDrop += kGainDepth;
        }
    }
    RegularBuilder& b = *built;
    // The finest level reached fixes the directory's resolution, and so the leaves' planes.
    const int finest = out.bsp.nodes[0].height;
    setResolution(finest);
    b.placeLeaves(out);
    leaves_ = std::move(out.leaves);
    pool_ = std::move(out.pool.trees);
    primList_ = std::move(out.pool.lists);

    const size_t fullBytes = buildDirectory(out.bsp, finest, params.fullTable, b.maxLevel, guard);
    makeRopes(guard);
    // The quads are a copy the walk reads instead of the spheres: made only within the budget
    // (the walk tests the spheres themselves without them), and said so in --stats.
    const size_t quadBytes = (primList_.size() + 3) / 4 * sizeof(SphereQuad);
    const bool quadsFit = memoryBytes() + quadBytes <= guard.budget();
    if (unionOnly_ && quadsFit) makeSphereQuads();

    extra_ = regularStats(*this, config, b, out, fullBytes);
    extra_["auto_level_drop"] = config.autoLevelDrop;
    if (unionOnly_ && !quadsFit)
        extra_["sphere_quads_left_out"] = formatBytes(quadBytes) + " would pass the memory budget";
    extra_["frame"] = std::move(frameStats);
}

Box3 RegularGrid::chooseFrame(const RegularConfig& params, nlohmann::json& stats) {
    if (!params.turnedFrame) return scene_->bounds;
    FrameChoice fc = chooseGridFrame(*scene_);
    stats["candidates"] = fc.candidates;
    stats["world_box_area"] = fc.worldArea;
    stats["frame_box_area"] = fc.frameArea;
    if (!fc.frame.turned) return scene_->bounds;
    frame_ = fc.frame;
    frameBoxes_ = std::move(fc.boxes);
    stats["turned"] = true;
    for (int a = 0; a < 3; ++a)
        stats["axes"].push_back({frame_.axes[a].x, frame_.axes[a].y, frame_.axes[a].z});
    return fc.bounds;
}

void RegularGrid::setBox(const Box3& bounds, double delta) {
    // Widened so that every axis can be cut.
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
    delta_ = delta * std::max({ext_.x, ext_.y, ext_.z});
}

void RegularGrid::setResolution(int finest) {
    for (int a = 0; a < 3; ++a) {
        const int depth = schedule_.cuts(finest, a);
        n_[a] = 1u << depth;
        scale_[a] = double(n_[a]) / ext_[a];
        // The builder's cut planes at the finest level (the last one exactly max).
        planes_[a].resize(size_t(n_[a]) + 1);
        for (uint32_t k = 0; k <= n_[a]; ++k) planes_[a][k] = planeAt(a, k, depth);
    }
    // Longest exact walk: one step per grid plane crossed, plus degenerate steps at edges.
    maxSteps_ = 4 * (size_t(n_[0]) + n_[1] + n_[2]) + 16;
}

size_t RegularGrid::buildDirectory(const BspNodes& bsp, int finest, bool full, int maxLevel,
                                   BuildGuard& guard) {
    // Estimated before it is allocated.
    const size_t fullBytes = Directory::estimateBytes(bsp, finest, true);
    const size_t dirBytes = full ? fullBytes : Directory::estimateBytes(bsp, finest, false);
    const size_t otherBytes = memoryBytes();  // everything but the directory, not built yet
    const size_t budget = guard.budget();
    if (dirBytes > budget || dirBytes + otherBytes > budget) {
        std::string what = full ? "--full-table" : "--max-level " + std::to_string(maxLevel);
        throw std::invalid_argument(
            what + ": the regular directory at level " + std::to_string(finest) + " would take " +
            (dirBytes == SIZE_MAX ? std::string("2^") + std::to_string(finest + 2) + " bytes"
                                  : formatBytes(dirBytes)) +
            ", over the memory budget of " + guard.describe() + " (--memory-budget)" +
            (full ? "; use sub-tables (drop --full-table)" : "; lower --max-level"));
    }
    guard.poll();
    dir_.build(bsp, schedule_, finest, full, &guard);
    return fullBytes;
}

void RegularGrid::makeRopes(BuildGuard& guard) {
    // Across each face, the cell at the face's low corner names the neighbour leaf; it is the
    // only one when it covers the face on the other two axes. Each leaf's own ropes, from the
    // directory: independent, so in parallel.
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
