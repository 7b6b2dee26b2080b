#include "engine/accel/regular/axis_planner.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <variant>

#include "engine/accel/build_guard.h"
#include "engine/scene/scene.h"
#include "engine/util/task_fence.h"

namespace lancer {

namespace regular_build {

namespace {

/// Levels --split-axes cost plans (4 cuts per axis on a cube: they fix the cells' shape); deeper
/// ones cut the longest axis of the level's cells, as the report's order
/// does on a cube. Planning every level cost up to 40% more build time on scenes of thousands of
/// triangles that stay above max-objects around shared vertices (tetra), for the same counters
/// within 2%; 12 levels cost 1-3% more build instructions, and balls4 14% fewer.
constexpr int kPlannedLevels = 12;

/// The longest axis of cells of `size`, the first of equals.
int longestAxis(const Vec3& size) {
    int a = 0;
    if (size.y > size[a]) a = 1;
    if (size.z > size[a]) a = 2;
    return a;
}

/// The planned levels' cells, one level at a time: the cells still cut, their primitives in one
/// array of references, and the chunks those are summed and written in.
class LevelCells {
  public:
    LevelCells(const std::vector<Box3>& primBoxes, const Box3& box,
               const std::vector<uint32_t>& live, const std::vector<uint32_t>& quarters,
               int maxObjects, const BuildGuard& guard)
        : primBoxes_(primBoxes),
          quarters_(quarters),
          maxObjects_(maxObjects),
          guard_(guard),
          cells_{{box, 0, live.size()}},
          refs_(live) {}

    /// Drop the cells that stop at this level, as they stop in the build; false when none is left.
    bool dropStopped();
    /// Each chunk's tests and counts in its cell's two children, for the three axes in one pass.
    void sumChunks();
    /// The axis whose cut costs the level least, its cells of `size`.
    int cheapestAxis(const Vec3& size) const;
    /// The next level's cells: each cell cut on `axis`, low child then high.
    void cut(int axis);

  private:
    /// Cell c holds refs_[begin, end).
    struct Cell {
        Box3 box;
        size_t begin, end;
    };
    /// A stretch of one cell's references, the unit of parallel work: for each axis, the tests
    /// its references make in the cell's children and how many go to each child; then where in
    /// the next level's array it writes each child's references.
    struct Chunk {
        size_t cell, begin, end;
        double tests[3];
        size_t count[3][2];
        size_t out[2];
    };
    static constexpr size_t kChunk = 16384;

    /// The children's offsets in the next level's array, cell by cell, low then high, each
    /// child's chunks in order; their total.
    size_t placeChildren(int axis);

    const std::vector<Box3>& primBoxes_;
    const std::vector<uint32_t>& quarters_;
    const int maxObjects_;
    const BuildGuard& guard_;
    std::vector<Cell> cells_, next_;
    std::vector<uint32_t> refs_, nextRefs_;
    std::vector<Chunk> chunks_;
    std::vector<char> open_;
};

bool LevelCells::dropStopped() {
    open_.assign(cells_.size(), 0);
    TaskFence fence;
    // Polled per cell and per chunk: a level's passes over the references take a quarter
    // of a second on balls:5 at --max-objects 1 under ThreadSanitizer.
    tbb::parallel_for(size_t(0), cells_.size(), fence.task([&](size_t k) {
        guard_.poll();
        const Cell& c = cells_[k];
        open_[k] = c.end - c.begin > size_t(maxObjects_) &&
                   !coveredByAll(primBoxes_, {refs_.data() + c.begin, c.end - c.begin}, c.box);
    }));
    fence.acquire();
    size_t kept = 0;
    for (size_t k = 0; k < cells_.size(); ++k)
        if (open_[k]) cells_[kept++] = cells_[k];
    cells_.resize(kept);
    return !cells_.empty();
}

void LevelCells::sumChunks() {
    // The tests are sums of multiples of a quarter (testWeights()), exact in any order: the
    // chunks' sums are the serial sums.
    chunks_.clear();
    for (size_t k = 0; k < cells_.size(); ++k)
        for (size_t b = cells_[k].begin; b < cells_[k].end; b += kChunk)
            chunks_.push_back({k, b, std::min(cells_[k].end, b + kChunk), {}, {}, {}});
    TaskFence fence;
    tbb::parallel_for(size_t(0), chunks_.size(), fence.task([&](size_t k) {
        guard_.poll();
        Chunk& ch = chunks_[k];
        const Box3& cb = cells_[ch.cell].box;
        const double mid[3] = {0.5 * (cb.lo.x + cb.hi.x), 0.5 * (cb.lo.y + cb.hi.y),
                               0.5 * (cb.lo.z + cb.hi.z)};
        // Sums held locally: stored to the chunk each time, they would be reloaded after
        // every store. Tests in quarters (testQuarters()).
        uint64_t tests[3] = {0, 0, 0};
        size_t count[3][2] = {};
        const Box3* const boxes = primBoxes_.data();
        const uint32_t* const weights = quarters_.data();
        for (size_t i = ch.begin; i < ch.end; ++i) {
            const Box3& b = boxes[refs_[i]];
            const uint64_t w = weights[refs_[i]];
            for (int a = 0; a < 3; ++a) {
                const int lo = b.lo[a] <= mid[a], hi = b.hi[a] >= mid[a];
                count[a][0] += size_t(lo);
                count[a][1] += size_t(hi);
                tests[a] += w * uint64_t(lo + hi);
            }
        }
        for (int a = 0; a < 3; ++a) {
            ch.tests[a] = double(tests[a]) * 0.25;
            ch.count[a][0] = count[a][0];
            ch.count[a][1] = count[a][1];
        }
    }));
    fence.acquire();
}

int LevelCells::cheapestAxis(const Vec3& size) const {
    double best = kInf;
    int axis = 0;
    for (int a = 0; a < 3; ++a) {
        Vec3 child = size;
        child[a] *= 0.5;
        const double area = child.x * child.y + child.y * child.z + child.z * child.x;
        double tests = 0.0;
        for (const Chunk& ch : chunks_) tests += ch.tests[a];
        const double total = area * (2.0 * double(cells_.size()) + tests);
        if (total < best) best = total, axis = a;
    }
    return axis;
}

size_t LevelCells::placeChildren(int axis) {
    next_.clear();
    size_t total = 0;
    for (size_t k = 0, first = 0; k < cells_.size(); ++k) {
        const Cell& c = cells_[k];
        const double mid = 0.5 * (c.box.lo[axis] + c.box.hi[axis]);
        size_t last = first;
        while (last < chunks_.size() && chunks_[last].cell == k) ++last;
        for (int side = 0; side < 2; ++side) {
            Cell child{c.box, total, 0};
            (side ? child.box.lo : child.box.hi)[axis] = mid;
            for (size_t h = first; h < last; ++h)
                chunks_[h].out[side] = total, total += chunks_[h].count[axis][side];
            child.end = total;
            next_.push_back(child);
        }
        first = last;
    }
    return total;
}

void LevelCells::cut(int axis) {
    // Each child's references in their order, written by the chunks at offsets summed in that
    // order.
    nextRefs_.resize(placeChildren(axis));
    TaskFence fence;
    tbb::parallel_for(size_t(0), chunks_.size(), fence.task([&](size_t k) {
        guard_.poll();
        Chunk& ch = chunks_[k];
        const Box3& cb = cells_[ch.cell].box;
        const double mid = 0.5 * (cb.lo[axis] + cb.hi[axis]);
        const Box3* const boxes = primBoxes_.data();
        uint32_t* lo = nextRefs_.data() + ch.out[0];
        uint32_t* hi = nextRefs_.data() + ch.out[1];
        for (size_t i = ch.begin; i < ch.end; ++i) {
            const uint32_t r = refs_[i];
            const Box3& b = boxes[r];
            if (coord(b.lo, axis) <= mid) *lo++ = r;
            if (coord(b.hi, axis) >= mid) *hi++ = r;
        }
    }));
    fence.acquire();
    cells_.swap(next_);
    refs_.swap(nextRefs_);
}

}  // namespace

std::vector<float> testWeights(const Scene& scene) {
    std::vector<float> w(scene.prims.size(), 1.0f);
    for (size_t i = 0; i < w.size(); ++i)
        if (const Polygon* pg = std::get_if<Polygon>(&scene.prims[i].shape))
            w[i] = float(1.0 + double(pg->p.size()) / 4.0);
    return w;
}

std::vector<uint32_t> testQuarters(const std::vector<float>& weights) {
    std::vector<uint32_t> q(weights.size());
    for (size_t i = 0; i < q.size(); ++i) q[i] = uint32_t(double(weights[i]) * 4.0);
    return q;
}

AxisSchedule planSchedule(const std::vector<Box3>& primBoxes, const Box3& box,
                          const std::vector<uint32_t>& live, const std::vector<uint32_t>& quarters,
                          int maxLevel, int maxObjects, const BuildGuard& guard) {
    LevelCells cells(primBoxes, box, live, quarters, maxObjects, guard);
    Vec3 size = box.extent();  // of every cell of the level
    std::vector<int> axes;
    for (int level = 0; level < maxLevel; ++level) {
        int axis;
        if (level >= kPlannedLevels) {
            axis = longestAxis(size);
        } else {
            guard.poll();
            if (!cells.dropStopped()) break;
            cells.sumChunks();
            axis = cells.cheapestAxis(size);
            cells.cut(axis);
        }
        axes.push_back(axis);
        size[axis] *= 0.5;
    }
    return AxisSchedule(axes);
}

}  // namespace regular_build

}  // namespace lancer
