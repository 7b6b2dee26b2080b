#include "engine/accel/irregular/screen_bsp.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>

#include "engine/accel/accelerator.h"
#include "engine/accel/build_guard.h"
#include "engine/accel/irregular/camera_frame.h"
#include "engine/accel/irregular/primitive_hulls.h"
#include "engine/scene/scene.h"

namespace lancer {

namespace {

/// A piece of a rectangle edge: the line p[axis] == c, from lo to hi along the other axis.
struct Segment {
    double c, lo, hi;
    uint8_t axis;
};

struct Split {
    uint8_t axis;
    double c;
};

/// A cell's segments kept in the orders its split choice reads, so that no cell sorts them
/// (docs/irregular.md, "Build speed"): the cell's `segs` holds the segments of axis 0 then
/// those of axis 1, each run by increasing c, and lo(a) (hi(a)) the indices in `segs` of the
/// segments of axis 1 - a by increasing lo (hi), their extent along a. A split keeps every
/// order by filtering it, the cut pieces' new ends (the line's c) going to the end of the lower
/// piece's hi order and the start of the upper piece's lo order (splitOrders). Empty: not
/// presorted.
struct SegmentOrders {
    /// lo(0), hi(0), lo(1), hi(1), in one allocation.
    std::vector<uint32_t> index;
    uint32_t n0 = 0, n1 = 0;  ///< the cell's segments of axis 0, of axis 1

    bool empty() const { return index.empty(); }
    size_t bytes() const { return index.capacity() * sizeof(uint32_t); }
    /// The segments an order along a holds: those of the other axis.
    size_t along(int a) const { return a == 0 ? n1 : n0; }
    const uint32_t* lo(int a) const { return index.data() + (a == 0 ? 0 : 2 * size_t(n1)); }
    const uint32_t* hi(int a) const { return lo(a) + along(a); }
    uint32_t* lo(int a) { return index.data() + (a == 0 ? 0 : 2 * size_t(n1)); }
    uint32_t* hi(int a) { return lo(a) + along(a); }
    /// Sized for n0 and n1 segments, the orders to be written.
    void resize(uint32_t axis0, uint32_t axis1) {
        n0 = axis0;
        n1 = axis1;
        index.resize(2 * (size_t(n0) + n1));
    }
};

/// A cell still to be split: its rectangle, the segments strictly inside it and the primitives
/// whose rectangle touches it, and once it waits, the line it is to be split on.
struct Cell {
    glm::dvec2 lo, hi;
    std::vector<Segment> segs;
    std::vector<uint32_t> prims;
    int32_t parent;  ///< node whose child this cell becomes (-1: the root); nodes may reallocate
    int side;
    int depth;
    Split split{};
    size_t primsBelow = 0, primsAbove = 0;  ///< the split's children's primitive counts
    /// The walk's cost of a ray through the cell (walkCost; < 0: not known yet), and of its
    /// split's children.
    double walk = -1.0, walkBelow = 0.0, walkAbove = 0.0;
    /// Empty, or `segs` is presorted (SegmentOrders) and these are its orders.
    SegmentOrders orders{};
};

/// A cell waiting in the best-first queue: the larger gain first, then the older cell.
struct Waiting {
    double gain;
    uint64_t order;
    uint32_t cell;
    bool operator<(const Waiting& o) const {
        return gain < o.gain || (gain == o.gain && order > o.order);
    }
};

/// A waiting cell's primitive references carry in their top bits the sides of its split they
/// belong to (meets, decided when the split is chosen), so the split does not decide it again.
constexpr uint32_t kBelowBit = 1u << 31, kAboveBit = 1u << 30, kPrimMask = kAboveBit - 1;

/// Levels of the screen BSP split whatever the cost estimate says.
constexpr int kAlwaysSplitLevels = 4;

/// Sort v in increasing order (key, tmp: scratch). Large arrays by a radix sort of the doubles'
/// bits, six passes of 11 bits over keys mapped to unsigned integers in the doubles' order (the
/// screen BSP's root sorts millions of endpoints, which std::sort took a fifth of a build on);
/// NaN does not occur (boxes are finite).
void sortValues(std::vector<double>& v, std::vector<uint64_t>& key, std::vector<uint64_t>& tmp) {
    if (v.size() < 4096) {
        std::sort(v.begin(), v.end());
        return;
    }
    const size_t n = v.size();
    key.resize(n);
    tmp.resize(n);
    for (size_t i = 0; i < n; ++i) {
        uint64_t u;
        std::memcpy(&u, &v[i], sizeof u);
        key[i] = u >> 63 ? ~u : u | (uint64_t(1) << 63);  // negatives reversed, below positives
    }
    std::vector<uint32_t> count(2048);
    for (int shift = 0; shift < 64; shift += 11) {
        std::fill(count.begin(), count.end(), 0u);
        for (uint64_t k : key) ++count[(k >> shift) & 2047];
        uint32_t sum = 0;
        for (uint32_t& c : count) {
            const uint32_t here = c;
            c = sum;
            sum += here;
        }
        for (uint64_t k : key) tmp[count[(k >> shift) & 2047]++] = k;
        key.swap(tmp);
    }
    for (size_t i = 0; i < n; ++i) {
        const uint64_t u = key[i] >> 63 ? key[i] & ~(uint64_t(1) << 63) : ~key[i];
        std::memcpy(&v[i], &u, sizeof u);
    }
}

/// Cells of twice this many segments or more choose their line from a sample of them.
constexpr size_t kSplitSample = 32768;

/// chooseSplit's arrays, kept from one cell to the next: allocated afresh, the large ones of the
/// first levels came from the system each time and every page faulted in again.
struct SplitScratch {
    std::vector<double> lines, lo, hi;
    std::vector<uint64_t> key, tmp;
};

/// Scores the lines of axis a, line(i) for i < lines in increasing order, against the ends
/// along a of the segments of the other axis, lo(k) and hi(k) for k < others each in increasing
/// order, and keeps the best in `best` (chooseSplit's costs; the first line wins a tie). Each
/// count comes from a pointer that only moves forward: the end of the run of lines at c, the
/// segments ending at or before c, those starting before c.
template <class Line, class Lo, class Hi>
void scoreLines(uint8_t a, size_t lines, Line line, size_t others, Lo lo, Hi hi, BspHeuristic h,
                const BuildGuard* guard, Split& best, size_t& bestMain, size_t& bestTie) {
    size_t next = 0, ending = 0, starting = 0;
    for (size_t i = 0, polled = 0; i < lines; i = next) {
        if (guard && (++polled & 8191) == 0) guard->poll();
        const double c = line(i);
        while (next < lines && line(next) == c) ++next;
        while (ending < others && hi(ending) <= c) ++ending;
        while (starting < others && lo(starting) < c) ++starting;
        size_t below = i;
        size_t above = lines - next;
        size_t crossLow = ending;
        size_t crossHigh = others - starting;
        size_t cut = others - crossLow - crossHigh;
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

/// The line to split on. `first`: the first segment's line (the report's "on choisit un
/// segment", read literally). `balanced`: the line that minimizes the larger side (segments on
/// it plus the pieces cut), then the cuts. `fewest-cuts`: the line that cuts fewest segments,
/// then the larger side. Each axis is scored from its endpoints in increasing order: a
/// presorted cell's (`orders` not empty) read in O(n), the others' sorted in O(n log n), a cell
/// of 2 kSplitSample segments or more from a sample of them. The scores depend on the sorted
/// values alone, so both give the same line.
Split chooseSplit(const std::vector<Segment>& segs, const SegmentOrders& orders, BspHeuristic h,
                  const BuildGuard* guard, SplitScratch& scratch) {
    if (h == BspHeuristic::First) return {segs[0].axis, segs[0].c};
    Split best{segs[0].axis, segs[0].c};
    size_t bestMain = SIZE_MAX, bestTie = SIZE_MAX;
    if (!orders.empty()) {
        for (uint8_t a = 0; a < 2; ++a) {
            // segs[0, n0) are the lines of axis 0 by c, segs[n0, ..) those of axis 1.
            const Segment* line = segs.data() + (a == 0 ? 0 : orders.n0);
            const size_t lines = a == 0 ? orders.n0 : orders.n1;
            if (lines == 0) continue;
            const uint32_t* lo = orders.lo(a);
            const uint32_t* hi = orders.hi(a);
            scoreLines(
                a, lines, [&](size_t i) { return line[i].c; }, orders.along(a),
                [&](size_t k) { return segs[lo[k]].lo; }, [&](size_t k) { return segs[hi[k]].hi; },
                h, guard, best, bestMain, bestTie);
        }
        return best;
    }
    auto& [lines, lo, hi, key, tmp] = scratch;
    // A cell of 2 kSplitSample segments or more is scored on every stride-th of them (between
    // kSplitSample and 2 kSplitSample of them): the line is then about as good (the counts are
    // proportional), and the first levels of a large scene no longer sort millions of
    // endpoints each.
    const size_t stride = std::max<size_t>(1, segs.size() / kSplitSample);
    for (uint8_t a = 0; a < 2; ++a) {
        lines.clear();
        lo.clear();
        hi.clear();
        for (size_t j = 0; j < segs.size(); j += stride) {
            const Segment& s = segs[j];
            if (s.axis == a) {
                lines.push_back(s.c);
            } else {
                lo.push_back(s.lo);
                hi.push_back(s.hi);
            }
        }
        if (lines.empty()) continue;
        if (guard) guard->poll();  // a root cell of millions of segments sorts for a while
        sortValues(lines, key, tmp);
        if (guard) guard->poll();
        sortValues(lo, key, tmp);
        if (guard) guard->poll();
        sortValues(hi, key, tmp);
        if (guard) guard->poll();
        scoreLines(
            a, lines.size(), [&](size_t i) { return lines[i]; }, lo.size(),
            [&](size_t k) { return lo[k]; }, [&](size_t k) { return hi[k]; }, h, guard, best,
            bestMain, bestTie);
    }
    return best;
}

/// Presorts a cell's segments in place (SegmentOrders): by axis, then c, and the orders of
/// their ends along the other axis.
void presort(std::vector<Segment>& segs, SegmentOrders& orders) {
    std::sort(segs.begin(), segs.end(), [](const Segment& x, const Segment& y) {
        return x.axis < y.axis || (x.axis == y.axis && x.c < y.c);
    });
    const uint32_t n0 =
        uint32_t(std::partition_point(segs.begin(), segs.end(),
                                      [](const Segment& x) { return x.axis == 0; }) -
                 segs.begin());
    orders.resize(n0, uint32_t(segs.size()) - n0);
    for (uint8_t a = 0; a < 2; ++a) {
        // Along a, the segments of the other axis: segs[n0, ..) for a = 0.
        uint32_t* lo = orders.lo(a);
        uint32_t* hi = orders.hi(a);
        const uint32_t first = a == 0 ? n0 : 0;
        for (uint32_t k = 0; k < orders.along(a); ++k) lo[k] = hi[k] = first + k;
        std::sort(lo, lo + orders.along(a),
                  [&](uint32_t x, uint32_t y) { return segs[x].lo < segs[y].lo; });
        std::sort(hi, hi + orders.along(a),
                  [&](uint32_t x, uint32_t y) { return segs[x].hi < segs[y].hi; });
    }
}

/// Throws std::logic_error unless `orders` are those of the presorted `segs` (SegmentOrders):
/// the segments by axis then c, and each order every segment of its axis once, by its end,
/// so that it reads the values a fresh sort gives (ScreenBspParams::checkOrders).
void checkOrders(const std::vector<Segment>& segs, const SegmentOrders& orders) {
    auto fail = [](const char* what) {
        throw std::logic_error(std::string("screen BSP: presorted segments: ") + what);
    };
    for (size_t i = 1; i < segs.size(); ++i)
        if (segs[i].axis < segs[i - 1].axis ||
            (segs[i].axis == segs[i - 1].axis && segs[i].c < segs[i - 1].c))
            fail("segments not by axis then line");
    if (size_t(orders.n0) + orders.n1 != segs.size() || orders.index.size() != 2 * segs.size() ||
        (orders.n0 > 0 && segs[orders.n0 - 1].axis != 0) ||
        (orders.n0 < segs.size() && segs[orders.n0].axis != 1))
        fail("counts differ from the segments'");
    for (uint8_t a = 0; a < 2; ++a) {
        for (int k = 0; k < 2; ++k) {
            const uint32_t* order = k == 0 ? orders.lo(a) : orders.hi(a);
            std::vector<double> fresh, read;
            for (const Segment& x : segs)
                if (x.axis != a) fresh.push_back(k == 0 ? x.lo : x.hi);
            std::sort(fresh.begin(), fresh.end());
            std::vector<uint8_t> seen(segs.size(), 0);
            for (size_t j = 0; j < orders.along(a); ++j) {
                const uint32_t i = order[j];
                if (i >= segs.size() || segs[i].axis == a || seen[i]++) fail("not a permutation");
                read.push_back(k == 0 ? segs[i].lo : segs[i].hi);
            }
            if (read != fresh) fail("an order differs from a fresh sort");
        }
    }
}

/// The orders of a presorted cell's child on `side` (0 below the line `sp`, 1 above): the
/// child's segments `child` are the parent's in its order, `cuts` of them cut in two by the
/// line, segment i at index at[i] of the child where it goes there.
void splitOrders(const std::vector<Segment>& segs, const SegmentOrders& orders, Split sp, int side,
                 const std::vector<uint32_t>& at, size_t cuts, const std::vector<Segment>& child,
                 SegmentOrders& out) {
    const uint8_t a = sp.axis, b = uint8_t(1 - a);
    const double c = sp.c;
    const uint32_t n0 =
        uint32_t(std::partition_point(child.begin(), child.end(),
                                      [](const Segment& x) { return x.axis == 0; }) -
                 child.begin());
    out.resize(n0, uint32_t(child.size()) - n0);
    // Along a, the segments of axis b: the lower child takes those starting before c (the cut
    // ones now ending at c, after every other end), the upper one those ending after c (the
    // cut ones now starting at c, before every other start).
    const uint32_t* lo = orders.lo(a);
    const uint32_t* hi = orders.hi(a);
    const size_t n = orders.along(a), m = out.along(a);
    uint32_t* toLo = out.lo(a);
    uint32_t* toHi = out.hi(a);
    if (side == 0) {
        for (size_t k = 0; k < m; ++k) toLo[k] = at[lo[k]];  // the first m start before c
        uint32_t* whole = toHi;
        uint32_t* cut = toHi + (m - cuts);
        for (size_t k = 0; k < n; ++k) {
            const Segment& x = segs[hi[k]];
            if (x.hi <= c)
                *whole++ = at[hi[k]];
            else if (x.lo < c)
                *cut++ = at[hi[k]];
        }
    } else {
        uint32_t* cut = toLo;
        uint32_t* whole = toLo + cuts;
        for (size_t k = 0; k < n; ++k) {
            const Segment& x = segs[lo[k]];
            if (x.lo >= c)
                *whole++ = at[lo[k]];
            else if (x.hi > c)
                *cut++ = at[lo[k]];
        }
        for (size_t k = n - m; k < n; ++k) toHi[k - (n - m)] = at[hi[k]];  // the last m end after c
    }
    // Along b, the lines of axis a: each child takes those on its side, the line's own used up.
    for (int k = 0; k < 2; ++k) {
        const uint32_t* from = k == 0 ? orders.lo(b) : orders.hi(b);
        uint32_t* to = k == 0 ? out.lo(b) : out.hi(b);
        for (size_t j = 0; j < orders.along(b); ++j) {
            const double x = segs[from[j]].c;
            if (side == 0 ? x < c : x > c) *to++ = at[from[j]];
        }
    }
}

/// Cells of at most this many primitives take their depth ranges from the hulls (walkCost).
constexpr size_t kNarrowedCellPrims = 64;

/// What the walk model sees along depth (walkCost): a slab cut (`cut`, where a primitive's
/// range starts or ends), the test of a primitive whose range starts there (`weight`), and the
/// share of the rays still going that end there (`kill`).
struct DepthEvent {
    double z;
    double weight, kill;
    bool cut;
};

/// An event's depth and its index among walkCost's events: what the sweep's order is sorted on,
/// half an event's bytes to move.
struct DepthKey {
    double z;
    uint32_t event;
};

/// walkCost's events and their order, kept from one cell to the next.
struct DepthEvents {
    std::vector<DepthEvent> events;
    std::vector<DepthKey> keys;
};

/// The expected cost of a ray through the cell [lo, hi] that lists `prims` (ZoneWalkModel),
/// walking the cell's slabs front to back: every slab costs a visit and every primitive a
/// test, each times the share of the rays still going there. A primitive ends the rays that
/// meet its filled share of the cell (its stop share times the share of the cell its
/// rectangle covers) between its nearest depth and the middle of its range, half at each:
/// its front surface lies there (a sphere's up to its centre), and the slabs cut in between
/// are visited by the rays that meet it further on.
double walkCost(const std::vector<uint32_t>& prims, glm::dvec2 lo, glm::dvec2 hi,
                const std::vector<Box3>& rect, const ScreenBspParams& params,
                DepthEvents& scratch) {
    const ZoneWalkModel& model = *params.walk;
    std::vector<DepthEvent>& events = scratch.events;
    std::vector<DepthKey>& keys = scratch.keys;
    const double area = (hi.x - lo.x) * (hi.y - lo.y);
    if (!(area > 0.0)) return model.visit;
    // Three events a primitive at most, written in place (the scratch only grows: a resize
    // from empty would clear them all again at every cell).
    if (events.size() < 3 * prims.size()) {
        events.resize(3 * prims.size());
        keys.resize(3 * prims.size());
    }
    size_t n = 0;  // events written
    // Small cells take each primitive's depth range over their column from its hull, as the
    // slabs will (narrowZones): a large turned box is shallow over a small cell.
    const bool narrow = params.hulls && prims.size() <= kNarrowedCellPrims;
    for (uint32_t p : prims) {
        const Box3& r = rect[p];
        const double cx = std::min(r.hi.x, hi.x) - std::max(r.lo.x, lo.x);
        const double cy = std::min(r.hi.y, hi.y) - std::max(r.lo.y, lo.y);
        const double cover = std::clamp(cx * cy / area, 0.0, 1.0);
        const double w = params.weights ? double((*params.weights)[p]) : 1.0;
        glm::dvec2 z(r.lo.z, r.hi.z);
        if (narrow) {
            z = params.hulls->depthIn(p, params.column, lo, hi, r.lo.z, z);
            if (z.x > z.y) continue;  // its bound misses the column
        }
        const double stop = (params.stops ? double((*params.stops)[p]) : model.fill) * cover;
        const double mid = 0.5 * (z.x + z.y);
        events[n] = {z.x, w, 0.5 * stop, true};
        events[n + 1] = {mid, 0.0, stop < 1.0 ? 0.5 * stop / (1.0 - 0.5 * stop) : 1.0, false};
        events[n + 2] = {z.y, 0.0, 0.0, true};
        keys[n] = {z.x, uint32_t(n)};
        keys[n + 1] = {mid, uint32_t(n + 1)};
        keys[n + 2] = {z.y, uint32_t(n + 2)};
        n += 3;
    }
    // The sweep's products follow the order among equal depths, so the keys are sorted by
    // std::sort with the events' comparison: its moves depend on the comparisons alone, so the
    // keys come out in the permutation sorting the events themselves gives, for half the bytes
    // moved (ScreenBspParams::checkOrders compares the two).
    std::sort(keys.begin(), keys.begin() + ptrdiff_t(n),
              [](const DepthKey& a, const DepthKey& b) { return a.z < b.z; });
    // The cost of the events in the order event(0), event(1), ..
    auto sweep = [&](auto event) {
        double alive = 1.0, cost = model.visit;  // the slab in front of the first cut
        double lastCut = -kInf;
        for (size_t i = 0; i < n && alive > 1e-6; ++i) {
            const DepthEvent& e = event(i);
            if (e.cut && e.z != lastCut) {
                cost += alive * model.visit;
                lastCut = e.z;
            }
            cost += alive * model.test * e.weight;
            alive *= 1.0 - e.kill;
        }
        return cost;
    };
    const double cost = sweep([&](size_t i) -> const DepthEvent& { return events[keys[i].event]; });
    if (params.checkOrders) {
        std::vector<DepthEvent> sorted(events.begin(), events.begin() + ptrdiff_t(n));
        std::sort(sorted.begin(), sorted.end(),
                  [](const DepthEvent& a, const DepthEvent& b) { return a.z < b.z; });
        const double plain = sweep([&](size_t i) -> const DepthEvent& { return sorted[i]; });
        for (size_t i = 0; i < n; ++i) {
            const DepthEvent &a = events[keys[i].event], &b = sorted[i];
            if (std::memcmp(&a.z, &b.z, sizeof a.z) != 0 || a.weight != b.weight ||
                a.kill != b.kill || a.cut != b.cut || std::memcmp(&cost, &plain, sizeof cost))
                throw std::logic_error("walkCost: the keys' order is not the events' sort's");
        }
    }
    return cost;
}

/// The rectangle's interior meets the cell's. A rectangle that only touches the cell is left
/// out: boxes are padded far beyond rounding (irregular.cpp), so its primitive has no point
/// and no hit within the cell; including it would add every neighbour across an edge.
bool overlapsOpen(const Box3& r, glm::dvec2 lo, glm::dvec2 hi) {
    return r.lo.x < hi.x && lo.x < r.hi.x && r.lo.y < hi.y && lo.y < r.hi.y;
}

/// Number the nodes and zones of a BSP built best first as a depth-first build numbers them
/// (preorder, the child `firstSide[node]` first): a build that no limit stops is then the same
/// structure, ids included, whatever the order its cells were split in.
void renumber(ScreenBsp& bsp, const std::vector<uint8_t>& firstSide, const BuildGuard* guard) {
    if (bsp.root < 0) return;  // a single zone
    std::vector<ScreenBsp::Node> nodes;
    std::vector<glm::dvec2> zoneLo, zoneHi;
    std::vector<uint32_t> zoneFirst{0}, zonePrims;
    nodes.reserve(bsp.nodes.size());
    zoneLo.reserve(bsp.zoneLo.size());
    zoneHi.reserve(bsp.zoneHi.size());
    zoneFirst.reserve(bsp.zoneFirst.size());
    zonePrims.reserve(bsp.zonePrims.size());
    struct Item {
        int32_t ref;     ///< a node, or ~zone, of the build's numbering
        int32_t parent;  ///< its parent in the new numbering (-1: the root)
        int side;
    };
    std::vector<Item> stack{{bsp.root, -1, 0}};
    // Every zone's list is copied (millions of references on balls:6): polled as the build is.
    for (size_t polled = 0; !stack.empty();) {
        if (guard && (++polled & 8191) == 0) guard->poll();
        const Item it = stack.back();
        stack.pop_back();
        int32_t ref;
        if (it.ref >= 0) {
            const ScreenBsp::Node& n = bsp.nodes[it.ref];
            ref = int32_t(nodes.size());
            nodes.push_back({n.axis, n.value, {0, 0}});
            const int first = firstSide[it.ref];
            stack.push_back({n.child[1 - first], ref, 1 - first});
            stack.push_back({n.child[first], ref, first});
        } else {
            const uint32_t z = uint32_t(~it.ref);
            ref = ~int32_t(zoneLo.size());
            zoneLo.push_back(bsp.zoneLo[z]);
            zoneHi.push_back(bsp.zoneHi[z]);
            zonePrims.insert(zonePrims.end(), bsp.zonePrims.begin() + bsp.zoneFirst[z],
                             bsp.zonePrims.begin() + bsp.zoneFirst[z + 1]);
            zoneFirst.push_back(uint32_t(zonePrims.size()));
        }
        (it.parent < 0 ? bsp.root : nodes[it.parent].child[it.side]) = ref;
    }
    bsp.nodes = std::move(nodes);
    bsp.zoneLo = std::move(zoneLo);
    bsp.zoneHi = std::move(zoneHi);
    bsp.zoneFirst = std::move(zoneFirst);
    bsp.zonePrims = std::move(zonePrims);
}

}  // namespace

size_t ScreenBsp::rootBytes(size_t prims) {
    // Four edges a rectangle. Scoring the root's line puts each segment's line or both its ends
    // in arrays of doubles that may double, and sorts the lines with two 64-bit keys each.
    const size_t segs = 4 * prims;
    return segs * sizeof(Segment) + prims * sizeof(uint32_t) + 2 * 2 * segs * sizeof(double) +
           2 * segs * sizeof(uint64_t);
}

ScreenBsp ScreenBsp::build(const std::vector<Box3>& rect, const std::vector<uint32_t>& prims,
                           glm::dvec2 lo, glm::dvec2 hi, const ScreenBspParams& params) {
    if (rect.size() > kPrimMask)
        throw std::invalid_argument("the screen BSP takes at most " + std::to_string(kPrimMask) +
                                    " primitives");
    ScreenBsp bsp;
    bsp.zoneFirst.push_back(0);
    Cell top{lo, hi, {}, {}, -1, 0, 0};
    top.segs.reserve(4 * prims.size());
    top.prims.reserve(prims.size());
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

    // Best first: the cells waiting to be split are taken in order of the cost estimate's gain
    // (the area-weighted tests a split saves), so a limit that stops the splitting stops it
    // across the whole screen at once, every waiting cell about as coarse as the others. Taken
    // depth first, the first cells split to the end and, once the limit is reached, the cells
    // still waiting became zones however large (lattice:30: 2,726 tests per ray).
    std::vector<Cell> cells;          // the waiting cells (a moved-from cell is a free slot)
    std::vector<uint32_t> freeSlots;  // free slots of `cells`
    std::vector<Waiting> queue;       // a max-heap of the waiting cells by gain
    uint64_t order = 0;
    SplitScratch scratch;
    std::vector<uint32_t> listBelow, listAbove;  // a cell's children's lists, for the walk model
    // Presorted cells (SegmentOrders): where each segment of the cell being split goes in its
    // children, and the bytes of the waiting cells' orders. The orders take 8 bytes a segment
    // and are kept while they take at most an eighth of the byte limit beside it (uncharged, as
    // the sorts' scratch they replace was, so the limit stops the BSP where it did); past it, or
    // for a cell sampled (2 kSplitSample segments or more) or split on its first segment, the
    // cell sorts its endpoints.
    std::vector<uint32_t> atBelow, atAbove;
    size_t orderBytes = 0;
    auto presortable = [&](const std::vector<Segment>& segs) {
        return params.presorted && params.heuristic != BspHeuristic::First &&
               segs.size() < 2 * kSplitSample &&
               (!params.maxBytes ||
                orderBytes + 2 * segs.size() * sizeof(uint32_t) <= params.maxBytes / 8);
    };
    // A cell that add() makes a zone at once: nothing splits it, or few enough primitives.
    auto settled = [&](const Cell& c) {
        return c.segs.empty() ||
               (params.stopObjects > 0 && c.prims.size() <= size_t(params.stopObjects));
    };
    DepthEvents events;
    // Which child of each node was split first in depth-first order (the one with fewer
    // segments, the upper one on a tie): the final numbering follows it (see below).
    std::vector<uint8_t> firstSide;
    // Bytes of the waiting cells' lists, and their primitive references. Splitting is stopped
    // by what it adds (the BSP and the least its zones will cost) and by those lists, which
    // hold every segment piece of the waiting cells.
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
               (bsp.zoneLo.size() + queue.size()) * params.zoneBytes +
               (bsp.zonePrims.size() + waitingRefs) * params.refBytes;
    };
    // Primitive p belongs to the cell [lo, hi]: its rectangle's interior meets the cell's and
    // its hull's outline meets the cell.
    auto meets = [&](uint32_t p, glm::dvec2 lo, glm::dvec2 hi) {
        return overlapsOpen(rect[p], lo, hi) &&
               (!params.hulls || params.hulls->touches(p, params.column, lo, hi));
    };
    // The cell becomes a zone: its rectangle and its primitives.
    auto makeZone = [&](const Cell& cell) {
        int32_t& slot = cell.parent < 0 ? bsp.root : bsp.nodes[cell.parent].child[cell.side];
        slot = ~int32_t(bsp.zoneLo.size());
        bsp.zoneLo.push_back(cell.lo);
        bsp.zoneHi.push_back(cell.hi);
        // Inserted as a range (the vector grows as it did: the byte limit counts its capacity),
        // then cleared of the split's side bits.
        const size_t at = bsp.zonePrims.size();
        bsp.zonePrims.insert(bsp.zonePrims.end(), cell.prims.begin(), cell.prims.end());
        for (size_t i = at; i < bsp.zonePrims.size(); ++i) bsp.zonePrims[i] &= kPrimMask;
        bsp.zoneFirst.push_back(uint32_t(bsp.zonePrims.size()));
    };
    // A new cell: a zone now when nothing splits it or no split pays, else it waits with its
    // split and the split's gain.
    auto add = [&](Cell&& cell) {
        bsp.depth = std::max(bsp.depth, cell.depth);
        if (settled(cell)) {
            // At most max-objects rectangles (an empty cell holds at most any), else no edge
            // crosses the cell: it lies inside all its rectangles.
            ++(cell.prims.size() <= size_t(std::max(params.stopObjects, 0)) ? bsp.objectStops
                                                                            : bsp.coveredStops);
            makeZone(cell);
            return;
        }
        if (cell.orders.empty() && presortable(cell.segs)) presort(cell.segs, cell.orders);
        if (params.checkOrders && !cell.orders.empty()) checkOrders(cell.segs, cell.orders);
        cell.split = chooseSplit(cell.segs, cell.orders, params.heuristic, params.guard, scratch);
        glm::dvec2 bHi = cell.hi, aLo = cell.lo;
        bHi[cell.split.axis] = cell.split.c;
        aLo[cell.split.axis] = cell.split.c;
        size_t nBelow = 0, nAbove = 0, polled = 0;
        // The tests of each side and of the cell, each weighing what it costs (sums of
        // quarters, exact in any order).
        double wBelow = 0.0, wAbove = 0.0, wCell = 0.0;
        listBelow.clear();
        listAbove.clear();
        const double cellArea = (cell.hi.x - cell.lo.x) * (cell.hi.y - cell.lo.y);
        if (params.walk && cellArea > 0.0 && cell.walk < 0.0)
            cell.walk = walkCost(cell.prims, cell.lo, cell.hi, rect, params, events);
        for (uint32_t& ref : cell.prims) {
            if (params.guard && (++polled & 32767) == 0) params.guard->poll();
            const uint32_t p = ref;
            const double w = params.weights ? double((*params.weights)[p]) : 1.0;
            const bool b = meets(p, cell.lo, bHi), a = meets(p, aLo, cell.hi);
            // Kept for the split, which sorts the primitives to the same sides.
            ref = p | (b ? kBelowBit : 0u) | (a ? kAboveBit : 0u);
            nBelow += b;
            nAbove += a;
            wBelow += b ? w : 0.0;
            wAbove += a ? w : 0.0;
            wCell += w;
            if (params.walk && b) listBelow.push_back(p);
            if (params.walk && a) listAbove.push_back(p);
        }
        // A ray through the cell (the area of a side is its share of the rays) tests its
        // rectangles; split, it crosses one more zone and tests one side's. The gain is the
        // tests saved, over the cell's area.
        const double area = (cell.hi.x - cell.lo.x) * (cell.hi.y - cell.lo.y);
        const double aBelow = (bHi.x - cell.lo.x) * (bHi.y - cell.lo.y);
        const double aAbove = (cell.hi.x - aLo.x) * (cell.hi.y - aLo.y);
        const double split = params.stepCost + (aBelow * wBelow + aAbove * wAbove) / area;
        double gain = area > 0.0 ? area * (wCell - split) : 0.0;
        bool pays = split < wCell;
        if (params.walk && area > 0.0) {
            // The walk model: the instructions the rays expected through the cell save by
            // walking its children (one level deeper to locate), less what building the split
            // adds (a zone, and a reference for each primitive it cuts in two).
            const ZoneWalkModel& m = *params.walk;
            cell.walkBelow = walkCost(listBelow, cell.lo, bHi, rect, params, events);
            cell.walkAbove = walkCost(listAbove, aLo, cell.hi, rect, params, events);
            const double saved =
                cell.walk - (aBelow * cell.walkBelow + aAbove * cell.walkAbove) / area - m.level;
            const double built =
                m.zone + m.ref * (double(nBelow + nAbove) - double(cell.prims.size()));
            // Where the count model (stepCost) pays and the walk model does not, the split is
            // made all the same (its gain in instructions: the tests it saves): the walk model
            // misjudges where rays end on many faces at once (gears2's eye zones, alone: 9.8
            // slabs a primary ray against 5.2 with the count model, 3.2 with both).
            const double countGain = gain * m.raysPerArea * m.test;
            gain = area * m.raysPerArea * saved - built;
            if (pays && countGain > gain) gain = countGain;
            pays = gain > 0.0;
        }
        cell.primsBelow = nBelow;
        cell.primsAbove = nAbove;
        // The first levels always split (at most 16 cells): with a handful of primitives the
        // estimate would leave one zone, and the scheme would have no screen structure at all.
        const bool always = cell.depth < kAlwaysSplitLevels;
        const bool costStop = params.stepCost > 0.0 || params.walk;
        if (costStop && !always && area > 0.0 && !pays) {
            ++bsp.costStops;
            makeZone(cell);
            return;
        }
        uint32_t slot;
        if (freeSlots.empty()) {
            slot = uint32_t(cells.size());
            cells.emplace_back();
        } else {
            slot = freeSlots.back();
            freeSlots.pop_back();
        }
        waiting += cellBytes(cell);
        waitingRefs += cell.prims.size();
        orderBytes += cell.orders.bytes();
        cells[slot] = std::move(cell);
        queue.push_back({always ? kInf : gain, order++, slot});
        std::push_heap(queue.begin(), queue.end());
    };
    add(std::move(top));
    while (!queue.empty()) {
        const size_t bytes = bspBytes();  // what splitting adds, with the waiting lists
        if (params.guard) params.guard->poll("screen BSP", bytes + waiting, bsp.zoneLo.size());
        std::pop_heap(queue.begin(), queue.end());
        const uint32_t slot = queue.back().cell;
        queue.pop_back();
        Cell cell = std::move(cells[slot]);
        cells[slot] = Cell{};
        freeSlots.push_back(slot);
        waiting -= cellBytes(cell);
        waitingRefs -= cell.prims.size();
        orderBytes -= cell.orders.bytes();
        // Over a limit, the BSP stops: this cell and every one still waiting become zones.
        if ((params.maxZones && bsp.zoneLo.size() + queue.size() + 1 >= params.maxZones) ||
            (params.maxBytes && bytes + waiting >= params.maxBytes)) {
            bsp.stopped = true;
            ++bsp.limitStops;
            makeZone(cell);
            continue;
        }
        const Split sp = cell.split;
        // Children: segments on the line are used up, segments across it are cut in two.
        Cell below{cell.lo, cell.hi, {}, {}, -1, 0, cell.depth + 1};
        Cell above{cell.lo, cell.hi, {}, {}, -1, 1, cell.depth + 1};
        below.hi[sp.axis] = sp.c;
        above.lo[sp.axis] = sp.c;
        // The children's lists are sized first: grown by doubling, the large ones were copied
        // and faulted in again at each step. Large cells take a while here: poll as in the loop.
        size_t polled = 0, segsBelow = 0, segsAbove = 0;
        for (const Segment& s : cell.segs) {
            if (params.guard && (++polled & 32767) == 0) params.guard->poll();
            if (s.axis == sp.axis) {
                segsBelow += s.c < sp.c;
                segsAbove += s.c > sp.c;
            } else {
                segsBelow += s.lo < sp.c;
                segsAbove += s.hi > sp.c;
            }
        }
        below.segs.reserve(segsBelow);
        above.segs.reserve(segsAbove);
        below.prims.reserve(cell.primsBelow);
        above.prims.reserve(cell.primsAbove);
        for (uint32_t ref : cell.prims) {
            if (ref & kBelowBit) below.prims.push_back(ref & kPrimMask);
            if (ref & kAboveBit) above.prims.push_back(ref & kPrimMask);
        }
        int32_t node = int32_t(bsp.nodes.size());
        (cell.parent < 0 ? bsp.root : bsp.nodes[cell.parent].child[cell.side]) = node;
        bsp.nodes.push_back({sp.axis, sp.c, {0, 0}});
        below.parent = above.parent = node;
        if (params.walk) {
            below.walk = cell.walkBelow;
            above.walk = cell.walkAbove;
        }
        // A presorted cell's children keep its order: where each segment goes is noted for
        // their orders.
        const bool sorted = !cell.orders.empty();
        const size_t cutsBefore = bsp.cuts;
        if (sorted) {
            atBelow.resize(cell.segs.size());
            atAbove.resize(cell.segs.size());
        }
        for (size_t i = 0; i < cell.segs.size(); ++i) {
            if (params.guard && (++polled & 32767) == 0) params.guard->poll();
            const Segment& s = cell.segs[i];
            if (sorted) {
                atBelow[i] = uint32_t(below.segs.size());
                atAbove[i] = uint32_t(above.segs.size());
            }
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
        if (sorted) {
            for (Cell* child : {&below, &above}) {
                if (settled(*child) || !presortable(child->segs)) continue;
                const int side = child == &below ? 0 : 1;
                splitOrders(cell.segs, cell.orders, sp, side, side == 0 ? atBelow : atAbove,
                            bsp.cuts - cutsBefore, child->segs, child->orders);
            }
        }
        cell = Cell{};  // free the parent's lists
        firstSide.push_back(below.segs.size() < above.segs.size() ? 0 : 1);
        add(std::move(below));
        add(std::move(above));
    }
    renumber(bsp, firstSide, params.guard);
    return bsp;
}

std::vector<float> stopShares(const Scene& scene, const CameraFrame& frame) {
    std::vector<float> share(scene.prims.size(), 0.0f);
    const CsgTree& tree = scene.tree;
    if (tree.empty()) return share;
    // The share of their rectangle that vertices projected from the origin enclose (shoelace),
    // or `none` when one lies behind it.
    auto projected = [&](std::span<const Vec3> pts, float none) {
        glm::dvec2 lo(kInf), hi(-kInf);
        double twice = 0.0;
        std::vector<glm::dvec2> q;
        for (const Vec3& p : pts) {
            const Vec3 c = frame.point(p);
            if (!(c.z > 0.0)) return none;
            q.push_back({c.x / c.z, c.y / c.z});
            lo = glm::min(lo, q.back());
            hi = glm::max(hi, q.back());
        }
        for (size_t i = 0; i < q.size(); ++i) {
            const glm::dvec2 a = q[i], b = q[(i + 1) % q.size()];
            twice += a.x * b.y - a.y * b.x;
        }
        const double rect = (hi.x - lo.x) * (hi.y - lo.y);
        return rect > 0.0 ? float(std::clamp(0.5 * std::abs(twice) / rect, 0.0, 1.0)) : 0.0f;
    };
    // What each shape fills of its bounding rectangle, seen from about any side.
    auto fill = [&](const Primitive& prim) {
        const Shape& s = prim.shape;
        if (std::holds_alternative<Sphere>(s)) return 0.785f;
        if (std::holds_alternative<Block>(s)) return 0.9f;
        if (const Triangle* t = std::get_if<Triangle>(&s))
            return prim.hasXf ? 0.5f : projected(t->p, 0.5f);
        if (const Polygon* pg = std::get_if<Polygon>(&s))
            return prim.hasXf ? 0.7f : projected(pg->p, 0.7f);
        if (std::holds_alternative<Torus>(s)) return 0.5f;
        return 0.7f;  // cones and cylinders, polytopes
    };
    std::vector<std::pair<int, float>> stack{{tree.root, 1.0f}};
    while (!stack.empty()) {
        const auto [n, f] = stack.back();
        stack.pop_back();
        const CsgNode& node = tree.nodes[size_t(n)];
        switch (node.op) {
            case Op::Primitive:
                share[node.prim] = std::max(share[node.prim], f * fill(scene.prims[node.prim]));
                break;
            case Op::Union:
                stack.push_back({node.left, f});
                stack.push_back({node.right, f});
                break;
            case Op::Intersection:
                stack.push_back({node.left, 0.5f * f});
                stack.push_back({node.right, 0.5f * f});
                break;
            case Op::Difference:
                stack.push_back({node.left, f});
                stack.push_back({node.right, 0.0f});
                break;
        }
    }
    return share;
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
