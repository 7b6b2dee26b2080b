#include "engine/accel/bvh/bvh.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>

#include "engine/accel/build_guard.h"
#include "engine/model/restriction.h"
#include "engine/util/format.h"

namespace lancer {

namespace {

double halfArea(const Box3& b) {
    const Vec3 e = glm::max(b.extent(), Vec3(0.0));
    return e.x * e.y + e.y * e.z + e.z * e.x;
}

constexpr int kBins = 16;

}  // namespace

/// The build, in named steps: the splits (binned SAH over the primitives' boxes), then each
/// leaf's list (every primitive whose box meets the leaf's) and its restricted tree.
struct BvhBuilder {
    BvhBuilder(const Scene& s, const BvhConfig& c, BuildGuard& g, Bvh& o)
        : scene(s), config(c), guard(g), out(o) {}
    const Scene& scene;
    const BvhConfig& config;
    BuildGuard& guard;
    Bvh& out;
    int maxDepth = kAutomaticBvhDepth;
    double hair = 0.0;             ///< what every box is grown by (see build)
    std::vector<uint32_t> ids;     ///< the live primitives, permuted by the splits
    std::vector<Box3> boxes;       ///< per primitive id: its minimized box
    std::vector<Vec3> centres;     ///< per primitive id: its box's centre
    std::vector<uint32_t> leaves;  ///< node ids of the leaves, in the order made
    /// Per node: its assigned primitives, ids[begin, end) (leaves only; inner nodes too while
    /// they are built).
    std::vector<uint32_t> begin, end;
    double sahCost = 0.0;  ///< the tree's estimated cost per ray entering the root, in tests
    struct Stops {
        size_t maxObjects = 0, maxLevel = 0, cost = 0, unsplittable = 0;
    } stops;

    /// A node over ids[b, e) at `depth`, its box from its primitives'.
    uint32_t makeNode(uint32_t b, uint32_t e, int depth, uint32_t parent) {
        const uint32_t id = uint32_t(out.nodes_.size());
        out.nodes_.emplace_back();
        out.parent_.push_back(parent);
        begin.push_back(b);
        end.push_back(e);
        Box3 box;
        for (uint32_t i = b; i < e; ++i) box.expand(boxes[ids[i]]);
        BvhNode& n = out.nodes_.back();
        for (int a = 0; a < 3; ++a) {
            n.lo[a] = box.lo[a] - hair;
            n.hi[a] = box.hi[a] + hair;
        }
        n.depth = uint16_t(depth);
        out.depth_ = std::max(out.depth_, depth);
        return id;
    }

    /// Where ids[b, e) splits: the binned surface-area split of least estimated cost over the
    /// three axes; returns the first index of the right side, or b when no split is better
    /// than a leaf (with the cost stop) or when the centres cannot be told apart.
    /// The bin of a centre at `f` bins from the low end, within [0, kBins): a model near the
    /// doubles' limit (a part moved by 1e308) makes f infinite or NaN, whose conversion to int
    /// was undefined and indexed far outside the bins (a crash found by fuzz_pipeline).
    static int binOf(double f) {
        if (!(f >= 0.0)) return 0;
        return f < double(kBins) ? int(f) : kBins - 1;
    }

    uint32_t split(uint32_t node, uint32_t b, uint32_t e) {
        const uint32_t count = e - b;
        Box3 cb;
        for (uint32_t i = b; i < e; ++i) cb.expand(centres[ids[i]]);
        const double area = halfArea(out.nodes_[node].box());
        double bestCost = kInf;
        int bestAxis = -1, bestBin = 0;
        for (int a = 0; a < 3; ++a) {
            const double lo = cb.lo[a], ext = cb.hi[a] - cb.lo[a];
            if (!(ext > 0.0)) continue;
            const double scale = kBins / ext;
            Box3 binBox[kBins];
            uint32_t binCount[kBins] = {};
            for (uint32_t i = b; i < e; ++i) {
                const uint32_t p = ids[i];
                const int k = binOf((centres[p][a] - lo) * scale);
                binBox[k].expand(boxes[p]);
                ++binCount[k];
            }
            // Areas and counts of every left side, then sweep the right sides.
            double leftArea[kBins];
            uint32_t leftCount[kBins];
            Box3 acc;
            uint32_t n = 0;
            for (int k = 0; k < kBins; ++k) {
                acc.expand(binBox[k]);
                n += binCount[k];
                leftArea[k] = n ? halfArea(acc) : 0.0;
                leftCount[k] = n;
            }
            acc = Box3();
            n = 0;
            for (int k = kBins - 1; k > 0; --k) {
                acc.expand(binBox[k]);
                n += binCount[k];
                if (n == 0 || leftCount[k - 1] == 0) continue;
                const double c = leftArea[k - 1] * leftCount[k - 1] + halfArea(acc) * n;
                if (c < bestCost) bestCost = c, bestAxis = a, bestBin = k;
            }
        }
        if (bestAxis < 0) return b;  // every centre in one place
        const double cost = config.stepCost + (area > 0.0 ? bestCost / area : double(count));
        if (config.usesCostStop() && count <= uint32_t(kCostLeafPrims) && cost >= double(count)) {
            ++stops.cost;
            return e;
        }
        const double lo = cb.lo[bestAxis], scale = kBins / (cb.hi[bestAxis] - lo);
        const auto mid = std::partition(ids.begin() + b, ids.begin() + e, [&](uint32_t p) {
            return binOf((centres[p][bestAxis] - lo) * scale) < bestBin;
        });
        return uint32_t(mid - ids.begin());
    }

    /// Node `node` (over ids[b, e)) and its subtree; nodes are made depth first, each node's
    /// two children next to each other.
    void build(uint32_t node, int depth) {
        // The nodes, their parents and ranges: at most two per primitive, reserved up front.
        const size_t bytes = out.nodes_.capacity() * (sizeof(BvhNode) + 3 * sizeof(uint32_t));
        if (!guard.fits(bytes))
            throw std::invalid_argument("--memory-budget: the BVH's nodes would pass " +
                                        guard.describe() + " (" + formatBytes(bytes) + ")");
        guard.poll("BVH", bytes, out.nodes_.size());
        const uint32_t b = begin[node], e = end[node], count = e - b;
        uint32_t m = b;
        if (count <= uint32_t(config.objects())) {
            ++stops.maxObjects;
        } else if (depth >= maxDepth) {
            ++stops.maxLevel;
        } else {
            m = split(node, b, e);
            if (m == b) {
                ++stops.unsplittable;
            } else if (m == e) {
                m = b;  // the cost stop (counted by split)
            }
        }
        if (m == b) {
            out.nodes_[node].leaf = 1;
            out.nodes_[node].assigned = uint8_t(std::min<uint32_t>(count, 255));
            leaves.push_back(node);
            return;
        }
        const uint32_t l = makeNode(b, m, depth + 1, node);
        makeNode(m, e, depth + 1, node);
        out.nodes_[node].first = l;
        build(l, depth + 1);
        build(l + 1, depth + 1);
    }

    /// Every primitive whose box meets leaf `leaf`'s box, sorted: the tree's leaves' assigned
    /// primitives, found from the root.
    void listOf(uint32_t leaf, std::vector<uint32_t>& list, std::vector<uint32_t>& stack) const {
        const Box3 q = out.nodes_[leaf].box();
        list.clear();
        stack.assign(1, 0);
        while (!stack.empty()) {
            const uint32_t id = stack.back();
            stack.pop_back();
            const BvhNode& n = out.nodes_[id];
            if (!n.box().overlaps(q)) continue;
            if (!n.leaf) {
                stack.push_back(n.first);
                stack.push_back(n.first + 1);
                continue;
            }
            for (uint32_t i = begin[id]; i < end[id]; ++i) {
                const Box3& pb = boxes[ids[i]];
                Box3 grown = pb;
                grown.lo -= Vec3(hair);
                grown.hi += Vec3(hair);
                if (grown.overlaps(q)) list.push_back(ids[i]);
            }
        }
        std::sort(list.begin(), list.end());
    }

    /// The leaves' lists and restricted trees, equal sets sharing theirs (RestrictedTreePool).
    void fillLeaves() {
        // A union-only scene: each leaf lists its own primitives (Bvh::walkUnion), in the
        // order the splits left them.
        if (out.unionOnly_) {
            for (uint32_t leaf : leaves) {
                out.nodes_[leaf].first = begin[leaf];
                out.nodes_[leaf].count = end[leaf] - begin[leaf];
            }
            out.primList_ = ids;
            listedTotal = ids.size();
            sharedSets = leaves.size();
            fillUnionEntries();
            return;
        }
        std::vector<std::vector<uint32_t>> lists(leaves.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, leaves.size(), 256),
                          [&](const tbb::blocked_range<size_t>& r) {
                              guard.poll();
                              std::vector<uint32_t> stack;
                              for (size_t i = r.begin(); i < r.end(); ++i)
                                  listOf(leaves[i], lists[i], stack);
                          });
        std::optional<TreeRestrictor> restrictor;
        if (!out.unionOnly_) restrictor.emplace(scene.tree);
        RestrictedTreePool pool;
        size_t listed = 0;
        for (size_t i = 0; i < leaves.size(); ++i) {
            const RestrictedTreePool::Entry en = pool.share(lists[i], [&](CsgTree& dst) {
                return restrictor ? restrictor->restrict(lists[i], dst) : -1;
            });
            BvhNode& n = out.nodes_[leaves[i]];
            n.first = pool.listFirst[en.list];
            n.count = uint32_t(lists[i].size());
            n.root = en.root;
            listed += lists[i].size();
            const size_t bytes = out.nodes_.size() * sizeof(BvhNode) + pool.bytes();
            if (!guard.fits(bytes))
                throw std::invalid_argument("--memory-budget: the BVH's leaf lists would pass " +
                                            guard.describe() + " (" + formatBytes(bytes) +
                                            " after " + std::to_string(i + 1) + " of " +
                                            std::to_string(leaves.size()) + " leaves)");
            if (i % 1024 == 0) guard.poll("BVH leaves", bytes, i);
        }
        out.primList_ = std::move(pool.lists);
        out.pool_ = std::move(pool.trees);
        listedTotal = listed;
        sharedSets = pool.size();
    }
    size_t listedTotal = 0, sharedSets = 0;

    /// A union-only scene's entries (Bvh::unionEntries): primList's primitives with their
    /// spheres, each leaf's last one marked.
    void fillUnionEntries() {
        const std::vector<PackedSphere>& packed = scene.packedSpheres;
        std::vector<BvhUnionEntry>& x = out.unionEntries_;
        x.resize(out.primList_.size());
        for (size_t i = 0; i < x.size(); ++i) {
            const uint32_t p = out.primList_[i];
            const bool sphere = p < packed.size() && packed[p].r >= 0.0;
            x[i] = {sphere ? packed[p].c : Vec3(0.0), sphere ? packed[p].r : -1.0, p, 0};
        }
        for (uint32_t leaf : leaves) x[end[leaf] - 1].last = 1;
    }

    /// The wide nodes the walks read (bvh_boxes.h): from the root down, each inner node's
    /// children, the inner one of largest area replaced by its own two children until there
    /// are four (as Embree collapses its BVH2 into a BVH4), so that a wide node holds the
    /// nodes most rays that enter it go on into. The root itself is the one slot of Bvh::top_.
    void buildWide() {
        if (out.nodes_.empty()) return;
        out.anchor_ = out.nodes_[0].box().center();
        if (!out.nodes_[0].leaf) out.wides_.reserve(out.nodes_.size() / 2);
        out.top_ = BvhWideNode::empty();
        setSlot(out.top_, 0, 0);
        if (!out.nodes_[0].leaf) fillWide(0, 0);
    }
    /// Slot k of `wn` holds binary node `id`: its box less the anchor, rounded outward, and its
    /// wide node (made here, filled by fillWide) or, for a leaf, its first entry.
    void setSlot(BvhWideNode& wn, int k, uint32_t id) {
        const BvhNode& c = out.nodes_[id];
        wn.node[k] = id;
        // Outward: the float nearest below (above) the box's side less the anchor, then one
        // float further, for the double subtraction's own rounding.
        for (int a = 0; a < 3; ++a) {
            wn.lo[a][k] = floatBelow(floatDown(c.lo[a] - out.anchor_[a]));
            wn.hi[a][k] = floatAbove(floatUp(c.hi[a] - out.anchor_[a]));
        }
        if (c.leaf) {
            wn.wide[k] = kWideLeaf | c.first;
        } else {
            wn.wide[k] = uint32_t(out.wides_.size());
            out.wides_.emplace_back();
        }
    }
    /// Wide node `w`, standing for inner binary node `bin`, and the wide nodes below it.
    void fillWide(uint32_t w, uint32_t bin) {
        const std::vector<BvhNode>& nodes = out.nodes_;
        uint32_t slots[kBvhWidth] = {nodes[bin].first, nodes[bin].first + 1};
        int n = 2;
        while (n < kBvhWidth) {
            int widest = -1;
            double area = -1.0;
            for (int k = 0; k < n; ++k)
                if (!nodes[slots[k]].leaf && halfArea(nodes[slots[k]].box()) > area)
                    widest = k, area = halfArea(nodes[slots[k]].box());
            if (widest < 0) break;
            const uint32_t first = nodes[slots[widest]].first;
            slots[widest] = first;
            slots[n++] = first + 1;
        }
        BvhWideNode wn = BvhWideNode::empty();
        for (int k = 0; k < n; ++k) setSlot(wn, k, slots[k]);
        out.wides_[w] = wn;
        for (int k = 0; k < n; ++k)
            if (!(wn.wide[k] & kWideLeaf)) fillWide(wn.wide[k], wn.node[k]);
    }

    /// The surface-area estimate of the built tree, in tests per ray that enters the root.
    void estimateCost() {
        const double rootArea = halfArea(out.nodes_[0].box());
        if (!(rootArea > 0.0)) return;
        for (const BvhNode& n : out.nodes_) {
            const double w = halfArea(n.box()) / rootArea;
            sahCost += w * (n.leaf ? double(n.count) : config.stepCost);
        }
    }
};

Bvh Bvh::build(const Scene& scene, const BvhConfig& config, nlohmann::json& extra,
               BuildGuard* guard) {
    if (config.maxObjects < 1 && config.maxObjects != -1)
        throw std::invalid_argument("--max-objects: the BVH needs at least 1 or auto (got " +
                                    std::to_string(config.maxObjects) + ")");
    if (config.maxLevel < 0 || config.maxLevel > kAutomaticBvhDepth)
        throw std::invalid_argument("--max-level: the BVH takes 0 (automatic) to " +
                                    std::to_string(kAutomaticBvhDepth) + " (got " +
                                    std::to_string(config.maxLevel) + ")");
    BuildGuard fallback;
    BuildGuard& g = guard ? *guard : fallback;
    Bvh out;
    out.scene_ = &scene;
    out.unionOnly_ = scene.tree.unionOnly();
    BvhBuilder b(scene, config, g, out);
    b.maxDepth = config.maxLevel > 0 ? config.maxLevel : kAutomaticBvhDepth;
    // Every box is grown by a hair of the scene's size: a hit on a face of a primitive whose box
    // bounds its leaf's computes a t that rounding may put a hair outside the leaf's box. The
    // lists are taken with the grown boxes, so the leaves' trees hold inside them too.
    b.hair = 1e-9 * scene.scale();
    b.boxes.assign(scene.prims.size(), Box3());
    b.centres.assign(scene.prims.size(), Vec3(0.0));
    // Along a turned subtree's axes where its boxes are much smaller (grid_frame.h).
    FrameChoice fc;
    if (config.turnedFrame) fc = chooseGridFrame(scene);
    out.frame_ = fc.frame;
    const std::vector<Box3>& from = fc.frame.turned ? fc.boxes : scene.minBox;
    for (uint32_t p : scene.livePrimitives()) {
        if (from[p].isEmpty()) continue;
        b.ids.push_back(p);
        b.boxes[p] = from[p];
        b.centres[p] = from[p].center();
    }
    if (!b.ids.empty()) {
        out.nodes_.reserve(2 * b.ids.size());
        out.parent_.reserve(2 * b.ids.size());
        b.begin.reserve(2 * b.ids.size());
        b.end.reserve(2 * b.ids.size());
        b.makeNode(0, uint32_t(b.ids.size()), 0, kNoNode);
        b.build(0, 0);
        b.fillLeaves();
        // A wide node's leaf slot holds the leaf's first entry in 31 bits (kWideLeaf).
        if (out.primList_.size() >= kWideLeaf)
            throw std::invalid_argument("the BVH's leaves list more than 2^31 primitives");
        b.buildWide();
        b.estimateCost();
    }
    extra["frame"] = {{"turned", fc.frame.turned}};
    for (int a = 0; a < 3 && fc.frame.turned; ++a)
        extra["frame"]["axes"].push_back(
            {fc.frame.axes[a].x, fc.frame.axes[a].y, fc.frame.axes[a].z});
    extra["nodes"] = out.nodes_.size();
    extra["wide_nodes"] = out.wides_.size();
    extra["leaves"] = b.leaves.size();
    extra["depth"] = out.depth_;
    extra["listed_primitives"] = b.listedTotal;
    extra["distinct_lists"] = b.sharedSets;
    extra["sah_cost"] = b.sahCost;
    extra["stop_reasons"] = {{"max_objects", b.stops.maxObjects},
                             {"max_level", b.stops.maxLevel},
                             {"cost", b.stops.cost},
                             {"memory", 0},
                             {"unsplittable", b.stops.unsplittable}};
    return out;
}

uint32_t Bvh::leafAt(const Vec3& world) const {
    if (nodes_.empty()) return kNoNode;
    const Vec3 p = frame_.toFrame(world);
    uint32_t best = kNoNode;
    double bestVolume = kInf, bestDist = kInf;
    for (uint32_t i = 0; i < nodes_.size(); ++i) {
        const BvhNode& n = nodes_[i];
        if (!n.leaf) continue;
        const Box3 b = n.box();
        const Vec3 q = glm::clamp(p, b.lo, b.hi);
        const double dist = glm::length(q - p);
        const Vec3 e = b.extent();
        const double volume = e.x * e.y * e.z;
        if (dist < bestDist || (dist == bestDist && volume < bestVolume))
            best = i, bestDist = dist, bestVolume = volume;
    }
    return best;
}

std::string Bvh::describe(uint32_t id) const {
    const BvhNode& n = nodes_.at(id);
    std::string s = std::string(n.leaf ? "leaf " : "node ") + std::to_string(id) + " depth " +
                    std::to_string(n.depth) + " " + n.box().toString();
    if (n.leaf)
        return s + " " + std::to_string(n.count) + " prims (" + std::to_string(n.assigned) +
               " assigned)";
    return s + " children " + std::to_string(n.first) + ", " + std::to_string(n.first + 1);
}

}  // namespace lancer
