// The irregular scheme's 2D step: a Fuchs BSP of the screen plane, fed with the edges of the
// primitives' rectangles (their camera-frame boxes projected along depth). Every edge is
// horizontal or vertical, so every splitting line is too and every zone is an axis-aligned
// rectangle inside the structure's screen rectangle.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer {

enum class BspHeuristic : uint8_t;  // build_params.h
class BuildGuard;                   // build_guard.h
class PrimitiveHulls;               // primitive_hulls.h
enum class ZoneColumn : uint8_t;    // primitive_hulls.h

struct ScreenBspParams {
    BspHeuristic heuristic{};  ///< the choice of splitting line
    int stopObjects = 0;  ///< a cell overlapping at most this many rectangles is a zone (0: never)
    /// Cost of the zone a split adds, in primitive tests (0: no cost stop). A cell is split only
    /// where stepCost + (area-weighted rectangles of the two children) is below its own count.
    double stepCost = 0.0;
    /// Stop splitting at about this many zones (0: no limit): the cells left become zones.
    size_t maxZones = 0;
    /// Stop splitting once the BSP, the lists of the cells waiting and what its zones will cost
    /// at least, `zoneBytes` a zone and `refBytes` a primitive reference, take this many bytes
    /// (0: no limit). Cells are split best first (the largest gain of the cost estimate), so
    /// the cells the limit leaves whole are spread over the whole screen.
    size_t maxBytes = 0;
    size_t zoneBytes = 0, refBytes = 0;
    BuildGuard* guard = nullptr;  ///< polled for cancellation and progress (null: never)
    /// A cell lists only the primitives whose hull's outline (seen along `column`) meets it,
    /// not every one whose rectangle does (null: rectangles alone).
    const PrimitiveHulls* hulls = nullptr;
    ZoneColumn column{};   ///< the rays a cell stands for, for `hulls`
    double hullPad = 0.0;  ///< padding of the depth ranges the hulls give a zone (narrowZones)
    /// What testing each primitive costs, in sphere tests (testWeights(): a polygon weighs
    /// 1 + vertices / 4), for the cost stop's counts (null: every test alike).
    const std::vector<float>* weights = nullptr;
};

/// The screen BSP and its leaves, the zones, each with the primitives whose rectangle it touches.
struct ScreenBsp {
    struct Node {
        uint8_t axis;  ///< 0: the line x = value, 1: the line y = value
        double value;
        int32_t child[2];  ///< [0] below the line, [1] above; >= 0 a node, < 0 the zone ~child
    };
    std::vector<Node> nodes;
    int32_t root = ~0;  ///< a node, or ~zone when the BSP is a single zone
    std::vector<glm::dvec2> zoneLo, zoneHi;
    std::vector<uint32_t> zoneFirst;  ///< zone z holds zonePrims[zoneFirst[z] .. zoneFirst[z + 1])
    std::vector<uint32_t> zonePrims;
    size_t segments = 0;   ///< rectangle edges fed to the BSP
    size_t cuts = 0;       ///< segments cut in two by a splitting line
    size_t costStops = 0;  ///< cells left whole because no split paid (stepCost)
    /// Zones by why their cell was not split, besides costStops: at most stopObjects
    /// rectangles; no segment left (the cell inside all its rectangles); the zone or byte limit.
    /// The four add up to the zones.
    size_t objectStops = 0, coveredStops = 0, limitStops = 0;
    int depth = 0;  ///< deepest node
    bool stopped =
        false;  ///< the zone or byte limit stopped the splitting before the segments ran out

    size_t zoneCount() const { return zoneLo.size(); }
    /// The zone holding the point (x, y), or for a point on a line, the zone on the side given by
    /// (sx, sy) (+1 above the line, -1 below, 0 either).
    uint32_t locate(double x, double y, int sx, int sy) const;
    size_t memoryBytes() const;

    /// Build over the rectangles rect[p].xy of the primitives `prims`, inside [lo, hi].
    static ScreenBsp build(const std::vector<Box3>& rect, const std::vector<uint32_t>& prims,
                           glm::dvec2 lo, glm::dvec2 hi, const ScreenBspParams& params);
    /// The most a build over `prims` rectangles holds before its first split (the root cell's
    /// lists and the scratch scoring its line): the least any budget must leave it.
    static size_t rootBytes(size_t prims);
};

}  // namespace lancer
