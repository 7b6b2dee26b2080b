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
struct Scene;                       // scene.h
struct CameraFrame;                 // camera_frame.h

/// The cost of a ray in a zone it walks in depth (the projective zones: the zone located once,
/// then its slabs front to back until the first hit), in instructions of the render, and what
/// a zone costs to build. With it the screen BSP splits a cell where the rays expected through
/// it save, walking its children instead, more than the split adds to the build
/// (docs/irregular.md, "A cost estimate that follows the walk").
struct ZoneWalkModel {
    double visit = 0.0;  ///< a slab visited
    double test = 0.0;   ///< a primitive test of weight 1 (ScreenBspParams::weights)
    double level = 0.0;  ///< a level of the BSP descended to locate the zone
    /// The share of a primitive's rectangle where a ray ends on it, for primitives without a
    /// share of their own (ScreenBspParams::stops).
    double fill = 0.0;
    double raysPerArea = 0.0;  ///< rays expected per unit area of the screen rectangle
    /// Rays expected over the zones' whole rectangle, spread evenly (0: raysPerArea as given);
    /// a light's structure, whose shadow rays start where the primary rays hit.
    double rays = 0.0;
    double zone = 0.0;  ///< building a zone
    double ref = 0.0;   ///< building a zone's reference to a primitive (its depth range, slabs)
};

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
    /// The walk's cost model (null: the count model of stepCost). Rectangles then carry each
    /// primitive's depth range in z.
    const ZoneWalkModel* walk = nullptr;
    /// Per primitive, the share of its rectangle where a ray ends on it, for the walk model
    /// (stopShares(); null: walk->fill for every one).
    const std::vector<float>* stops = nullptr;
    /// Cells keep their segments presorted from cell to cell instead of sorting their
    /// endpoints at each split: the same lines, in O(n) a cell (docs/irregular.md, "Build
    /// speed"). false: every cell sorts, as a check of the presorted build.
    bool presorted = true;
    /// Check every presorted cell's orders against a fresh sort of its segments, and every walk
    /// model cost against the sweep of its depth events sorted themselves by std::sort, bit for
    /// bit (tests); a mismatch throws std::logic_error.
    bool checkOrders = false;
};

/// Per primitive of `scene`, the share of its screen rectangle where a ray from `frame`'s origin
/// ends on it, as the walk model takes it: the share its shape fills of its bounding rectangle
/// (a sphere pi/4; a triangle or polygon in world coordinates, the area of its vertices
/// projected from the origin over their rectangle's, so a face seen edge-on stops nothing),
/// halved under each intersection (the ray ends only where the other side holds too), none
/// for what a difference takes away (a ray goes on through it).
std::vector<float> stopShares(const Scene& scene, const CameraFrame& frame);

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
    size_t costStops = 0;  ///< cells left whole because no split paid (stepCost, walk)
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
