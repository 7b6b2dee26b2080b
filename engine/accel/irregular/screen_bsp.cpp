#include "engine/accel/irregular/screen_bsp.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "engine/accel/accelerator.h"
#include "engine/accel/build_guard.h"

namespace lancer {

namespace {

/// A piece of a rectangle edge: the line p[axis] == c, from lo to hi along the other axis.
struct Segment {
    double c, lo, hi;
    uint8_t axis;
};

/// A cell still to be split: its rectangle, the segments strictly inside it and the primitives
/// whose rectangle touches it.
struct Cell {
    glm::dvec2 lo, hi;
    std::vector<Segment> segs;
    std::vector<uint32_t> prims;
    int32_t parent;  ///< node whose child this cell becomes (-1: the root); nodes may reallocate
    int side;
    int depth;
};

/// Levels of the screen BSP split whatever the cost estimate says.
constexpr int kAlwaysSplitLevels = 4;

struct Split {
    uint8_t axis;
    double c;
};

/// The line to split on. `first`: the first segment's line (the report's "on choisit un
/// segment", read literally). `balanced`: the line that minimizes the larger side (segments on
/// it plus the pieces cut), then the cuts. `fewest-cuts`: the line that cuts fewest segments,
/// then the larger side. Each axis is scored in O(n log n) from sorted endpoints.
Split chooseSplit(const std::vector<Segment>& segs, BspHeuristic h, const BuildGuard* guard) {
    if (h == BspHeuristic::First) return {segs[0].axis, segs[0].c};
    Split best{segs[0].axis, segs[0].c};
    size_t bestMain = SIZE_MAX, bestTie = SIZE_MAX;
    std::vector<double> lines, lo, hi;
    for (uint8_t a = 0; a < 2; ++a) {
        lines.clear();
        lo.clear();
        hi.clear();
        for (const Segment& s : segs) {
            if (s.axis == a) {
                lines.push_back(s.c);
            } else {
                lo.push_back(s.lo);
                hi.push_back(s.hi);
            }
        }
        if (lines.empty()) continue;
        if (guard) guard->poll();  // a root cell of millions of segments sorts for a while
        std::sort(lines.begin(), lines.end());
        if (guard) guard->poll();
        std::sort(lo.begin(), lo.end());
        if (guard) guard->poll();
        std::sort(hi.begin(), hi.end());
        if (guard) guard->poll();
        for (size_t i = 0; i < lines.size(); ++i) {
            if (guard && (i & 8191) == 0) guard->poll();
            if (i > 0 && lines[i] == lines[i - 1]) continue;
            double c = lines[i];
            size_t below = i;
            size_t above = size_t(lines.end() - std::upper_bound(lines.begin(), lines.end(), c));
            size_t crossLow = size_t(std::upper_bound(hi.begin(), hi.end(), c) - hi.begin());
            size_t crossHigh = size_t(lo.end() - std::lower_bound(lo.begin(), lo.end(), c));
            size_t cut = lo.size() - crossLow - crossHigh;
            size_t larger = std::max(below + crossLow, above + crossHigh) + cut;
            size_t mainCost = h == BspHeuristic::Balanced ? larger : cut;
            size_t tieCost = h == BspHeuristic::Balanced ? cut : larger;
            if (mainCost < bestMain || (mainCost == bestMain && tieCost < bestTie)) {
                bestMain = mainCost;
                bestTie = tieCost;
                best = {a, c};
            }
        }
    }
    return best;
}

/// The rectangle's interior meets the cell's. A rectangle that only touches the cell is left
/// out: boxes are padded far beyond rounding (irregular.cpp), so its primitive has no point
/// and no hit within the cell; including it would add every neighbour across an edge.
bool overlapsOpen(const Box3& r, glm::dvec2 lo, glm::dvec2 hi) {
    return r.lo.x < hi.x && lo.x < r.hi.x && r.lo.y < hi.y && lo.y < r.hi.y;
}

}  // namespace

ScreenBsp ScreenBsp::build(const std::vector<Box3>& rect, const std::vector<uint32_t>& prims,
                           glm::dvec2 lo, glm::dvec2 hi, const ScreenBspParams& params) {
    ScreenBsp bsp;
    bsp.zoneFirst.push_back(0);
    Cell top{lo, hi, {}, {}, -1, 0, 0};
    // The four edges of each rectangle, in primitive order; an edge on the cell's border splits
    // nothing and is left out.
    for (uint32_t p : prims) {
        if (params.guard && (p & 8191) == 0) params.guard->poll();
        const Box3& r = rect[p];
        Segment e[4] = {{r.lo.x, r.lo.y, r.hi.y, 0},
                        {r.hi.x, r.lo.y, r.hi.y, 0},
                        {r.lo.y, r.lo.x, r.hi.x, 1},
                        {r.hi.y, r.lo.x, r.hi.x, 1}};
        for (const Segment& s : e) {
            uint8_t o = 1 - s.axis;
            Segment c{s.c, std::max(s.lo, lo[o]), std::min(s.hi, hi[o]), s.axis};
            if (c.c > lo[s.axis] && c.c < hi[s.axis] && c.lo < c.hi) top.segs.push_back(c);
        }
        top.prims.push_back(p);
    }
    bsp.segments = top.segs.size();

    // Depth first, smaller child first, so at most O(log n) large cells wait on the stack.
    std::vector<Cell> stack;
    // Bytes of the cells waiting on the stack, and their primitive references. The lists are
    // transient, about as large as the input at any time (the root's, then halves): splitting
    // is stopped by what it adds, the BSP and the least its zones will cost.
    size_t waiting = 0, waitingRefs = 0;
    auto cellBytes = [](const Cell& c) {
        return sizeof(Cell) + c.segs.capacity() * sizeof(Segment) +
               c.prims.capacity() * sizeof(uint32_t);
    };
    auto bspBytes = [&] {
        return bsp.nodes.capacity() * sizeof(Node) +
               bsp.zoneLo.capacity() * 2 * sizeof(glm::dvec2) +
               bsp.zoneFirst.capacity() * sizeof(uint32_t) +
               bsp.zonePrims.capacity() * sizeof(uint32_t) +
               (bsp.zoneLo.size() + stack.size()) * params.zoneBytes +
               (bsp.zonePrims.size() + waitingRefs) * params.refBytes;
    };
    waiting += cellBytes(top);
    waitingRefs += top.prims.size();
    stack.push_back(std::move(top));
    while (!stack.empty()) {
        Cell cell = std::move(stack.back());
        stack.pop_back();
        const size_t bytes = bspBytes();  // what splitting adds (not the transient lists)
        waiting -= cellBytes(cell);
        waitingRefs -= cell.prims.size();
        if (params.guard) params.guard->poll("screen BSP", bytes + waiting, bsp.zoneLo.size());
        int32_t& slot = cell.parent < 0 ? bsp.root : bsp.nodes[cell.parent].child[cell.side];
        bsp.depth = std::max(bsp.depth, cell.depth);
        bool stop = cell.segs.empty() ||
                    (params.stopObjects > 0 && cell.prims.size() <= size_t(params.stopObjects));
        // Over a limit, the BSP stops: this cell and every one still waiting become zones
        // (the waiting ones are at most O(log n), each a zone once popped).
        if (!stop &&
            ((params.maxZones && bsp.zoneLo.size() + stack.size() + 1 >= params.maxZones) ||
             (params.maxBytes && bytes >= params.maxBytes))) {
            stop = true;
            bsp.stopped = true;
        }
        // The cell becomes a zone: its rectangle and its primitives.
        auto makeZone = [&] {
            slot = ~int32_t(bsp.zoneLo.size());
            bsp.zoneLo.push_back(cell.lo);
            bsp.zoneHi.push_back(cell.hi);
            bsp.zonePrims.insert(bsp.zonePrims.end(), cell.prims.begin(), cell.prims.end());
            bsp.zoneFirst.push_back(uint32_t(bsp.zonePrims.size()));
        };
        if (stop) {
            makeZone();
            continue;
        }
        Split sp = chooseSplit(cell.segs, params.heuristic, params.guard);
        // Children: segments on the line are used up, segments across it are cut in two.
        Cell below{cell.lo, cell.hi, {}, {}, -1, 0, cell.depth + 1};
        Cell above{cell.lo, cell.hi, {}, {}, -1, 1, cell.depth + 1};
        below.hi[sp.axis] = sp.c;
        above.lo[sp.axis] = sp.c;
        // Large cells take a while here (their children's lists grow by copies, and fresh pages
        // fault in): poll as in the loop.
        size_t polled = 0;
        for (uint32_t p : cell.prims) {
            if (params.guard && (++polled & 32767) == 0) params.guard->poll();
            if (overlapsOpen(rect[p], below.lo, below.hi)) below.prims.push_back(p);
            if (overlapsOpen(rect[p], above.lo, above.hi)) above.prims.push_back(p);
        }
        // The first levels always split (at most 16 cells): with a handful of primitives the
        // estimate would leave one zone, and the scheme would have no screen structure at all.
        if (params.stepCost > 0.0 && cell.depth >= kAlwaysSplitLevels) {
            // A ray through the cell (the area of a side is its share of the rays) tests its
            // rectangles; split, it crosses one more zone and tests one side's.
            const double area = (cell.hi.x - cell.lo.x) * (cell.hi.y - cell.lo.y);
            const double aBelow = (below.hi.x - below.lo.x) * (below.hi.y - below.lo.y);
            const double aAbove = (above.hi.x - above.lo.x) * (above.hi.y - above.lo.y);
            const double split =
                params.stepCost +
                (aBelow * double(below.prims.size()) + aAbove * double(above.prims.size())) / area;
            if (area > 0.0 && !(split < double(cell.prims.size()))) {
                ++bsp.costStops;
                makeZone();
                continue;
            }
        }
        int32_t node = int32_t(bsp.nodes.size());
        slot = node;
        bsp.nodes.push_back({sp.axis, sp.c, {0, 0}});
        below.parent = above.parent = node;
        for (const Segment& s : cell.segs) {
            if (params.guard && (++polled & 32767) == 0) params.guard->poll();
            if (s.axis == sp.axis) {
                if (s.c < sp.c)
                    below.segs.push_back(s);
                else if (s.c > sp.c)
                    above.segs.push_back(s);
            } else if (s.hi <= sp.c) {
                below.segs.push_back(s);
            } else if (s.lo >= sp.c) {
                above.segs.push_back(s);
            } else {
                ++bsp.cuts;
                below.segs.push_back({s.c, s.lo, sp.c, s.axis});
                above.segs.push_back({s.c, sp.c, s.hi, s.axis});
            }
        }
        cell = Cell{};  // free the parent's lists before descending
        if (below.segs.size() < above.segs.size()) std::swap(below, above);
        waiting += cellBytes(below) + cellBytes(above);
        waitingRefs += below.prims.size() + above.prims.size();
        stack.push_back(std::move(below));  // the larger one waits
        stack.push_back(std::move(above));
    }
    return bsp;
}

uint32_t ScreenBsp::locate(double x, double y, int sx, int sy) const {
    int32_t n = root;
    while (n >= 0) {
        const Node& node = nodes[n];
        double q = node.axis == 0 ? x : y;
        int s = node.axis == 0 ? sx : sy;
        n = node.child[q > node.value || (q == node.value && s > 0)];
    }
    return uint32_t(~n);
}

size_t ScreenBsp::memoryBytes() const {
    return nodes.size() * sizeof(Node) + zoneLo.size() * 2 * sizeof(glm::dvec2) +
           zoneFirst.size() * sizeof(uint32_t) + zonePrims.size() * sizeof(uint32_t);
}

}  // namespace lancer
