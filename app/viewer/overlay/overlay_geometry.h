// What the overlays draw over the image, as batches (no GL): the screen BSP's cut lines by
// depth in cut order, zones filled by primitive or slab count, slabs, regular leaves and the
// directory grid, all in world space (projected with the current camera, so a zone of the
// projective frame or of an orthographic camera frame lands on its pixels, and a perspective
// camera frame's BSP is drawn in perspective). Also picking: the region under a pixel.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>
#include <string>

#include "app/viewer/gl/batch.h"
#include "app/viewer/region_filter.h"
#include "engine/accel/structure_view.h"
#include "engine/render/image.h"
#include "engine/render/region_costs.h"

namespace lancer::viewer::overlay {

/// What colours a zone's fill: its primitives, its slabs, or the cost of the last complete
/// image in its slabs (region visits, primitive tests; region_costs.h).
enum class ZoneFill : uint8_t { Prims, Slabs, Visits, Tests };
/// What colours a leaf's (or BVH node's) wireframe: its level, its primitives, or the cost of
/// the last complete image in it.
enum class LeafColor : uint8_t { Level, Prims, Visits, Tests };
/// What colours a slab's wireframe: its order in depth in its zone, or the cost in it.
enum class SlabColor : uint8_t { Order, Visits, Tests };
/// What a layer's colouring counts: nothing of the image, its region visits or its tests.
enum class CostKind : uint8_t { None, Visits, Tests };
inline CostKind costKindOf(ZoneFill f) {
    return f == ZoneFill::Visits  ? CostKind::Visits
           : f == ZoneFill::Tests ? CostKind::Tests
                                  : CostKind::None;
}
inline CostKind costKindOf(LeafColor c) {
    return c == LeafColor::Visits  ? CostKind::Visits
           : c == LeafColor::Tests ? CostKind::Tests
                                   : CostKind::None;
}
inline CostKind costKindOf(SlabColor c) {
    return c == SlabColor::Visits  ? CostKind::Visits
           : c == SlabColor::Tests ? CostKind::Tests
                                   : CostKind::None;
}
/// "region visits", "prim tests" (the names of the heat maps' counters).
const char* costKindName(CostKind k);
/// What colours the directory grid's blocks: sub-table blocks against single entries, the BSP
/// level (an entry's leaf's, a sub-table's node's), or the depth of the table holding the entry.
enum class GridColor : uint8_t { Kind, Level, TableDepth };

/// The layers and what selects their geometry; a change rebuilds the batches.
struct OverlayOptions {
    bool bsp = false;     ///< irregular: the screen BSP's cut lines
    bool zones = false;   ///< irregular: zones filled
    bool slabs = false;   ///< irregular: slabs' wireframes
    bool leaves = false;  ///< regular: the leaves' wireframes
    bool grid = false;    ///< regular: the directory's entries and sub-table blocks
    ZoneFill zoneFill = ZoneFill::Prims;
    LeafColor leafColor = LeafColor::Level;
    SlabColor slabColor = SlabColor::Order;
    /// The rays whose cost the Visits and Tests colourings count.
    CostRays costRays = CostRays::All;
    /// Irregular: the projective zones (when primary rays walk them), else the camera frame.
    bool projective = true;
    GridColor gridColor = GridColor::Kind;
    /// Regular: the BSP levels drawn (a leaf's, RegionInfo::level; a directory block's,
    /// DirectoryBlock::level).
    int levelMin = 0, levelMax = 64;
    /// Most regions (leaves, slabs, blocks) and cuts drawn; the visible ones first.
    size_t cap = 100000;
    /// Leaves, slabs and BVH nodes drawn: all, or only the played ray's (not saved).
    RegionFilter only;
    bool operator==(const OverlayOptions&) const = default;
    /// Any layer on.
    bool any() const { return bsp || zones || slabs || leaves || grid; }
    /// A layer on is coloured by the image's cost on the structure (it needs the counts).
    bool usesCosts() const {
        return (zones && costKindOf(zoneFill) != CostKind::None) ||
               (slabs && costKindOf(slabColor) != CostKind::None) ||
               (leaves && costKindOf(leafColor) != CostKind::None);
    }
};

/// The batches of one structure, camera, image size and options.
struct OverlayGeometry {
    gl::Batch cuts;          ///< cut lines in cut order, linesPerCut each
    size_t linesPerCut = 1;  ///< 2 for a perspective camera frame (its near and far depth)
    size_t cutsTotal = 0;    ///< cuts of the BSP (cuts.lineCount() / linesPerCut drawn)
    int maxCutDepth = 0;
    gl::Batch fills;  ///< zones, filled (alpha 1: the draw's opacity makes them translucent)
    /// Leaves, blocks, slabs; the regular scheme's edges merged (gl::mergeCollinearLines).
    gl::Batch wires;
    /// The same lines, longest first (in world units): a prefix of it is what the layer draws
    /// while the camera moves (OverlayLook::movingLines).
    gl::Batch wiresLongestFirst;
    size_t regionsTotal = 0;  ///< regions (or blocks) the options select
    size_t regionsDrawn = 0;  ///< of them, drawn (visible, under the cap)
    size_t zonesTotal = 0, zonesDrawn = 0;
    bool cameraDependent = false;  ///< culled or capped by visibility: rebuild when it moves
    /// What the keys list: the levels (or cut depths, sub-table depths) drawn in level colours
    /// (levelLo > levelHi: none), the largest count drawn in count colours, the deepest slab
    /// index drawn (-1: no slab).
    int levelLo = 1 << 30, levelHi = -1;
    size_t countMax = 0;
    int slabMax = -1;
    /// The cost colourings drawn (each layer's; None: none), and whether their counts were
    /// there (else every region is drawn in kNoCostColor, the key saying so).
    CostKind leafCost = CostKind::None, zoneCost = CostKind::None, slabCost = CostKind::None;
    bool costsKnown = false;
    uint64_t costMax = 0;  ///< the largest count drawn
    /// Record that level `l` was drawn in its level colour.
    void noteLevel(int l) {
        levelLo = std::min(levelLo, l);
        levelHi = std::max(levelHi, l);
    }
};

/// Build the layers `options` asks for, for a width x height image seen by `view`. `costs`:
/// the last complete image's counts on this structure (options.costRays'), null when there
/// are none (yet): a cost colouring then draws its regions in kNoCostColor.
OverlayGeometry buildOverlayGeometry(const StructureView& sv, const Camera& view, int width,
                                     int height, const OverlayOptions& options,
                                     const RegionCosts* costs = nullptr);

/// Near and far depths that keep the whole structure inside the clip volume of `view`.
std::pair<double, double> clipDepths(const StructureView& sv, const Camera& view);

/// What lies under a pixel: the region its primary ray is in at the depth it hits (or, on a
/// miss, where it enters the structure), and for the irregular scheme the zone.
struct PickResult {
    uint32_t region = 0;
    int64_t zone = -1;  ///< irregular: the zone of `frame` under the pixel
    ZoneFrameKind frame = ZoneFrameKind::Camera;
    /// Projective zones: the depth along the camera's axis (F) of the hit the region was
    /// picked at (none on a miss: the region is the zone's first slab).
    std::optional<double> frameDepth;
};
/// Pick at continuous image point (x, y) of a width x height image seen by `view`; `depth` is
/// the primary hit distance along the unit ray there (+inf on a miss). Nothing when the pixel
/// sees no region.
std::optional<PickResult> pick(const StructureView& sv, const Camera& view, int width, int height,
                               double x, double y, float depth, bool projective = true);

/// A zone's depth slabs laid along one line: the image's depth strip. A projective zone's slabs
/// all project onto the zone's rectangle, so the image cannot show them otherwise; the strip
/// shows where along the depth each begins and ends, and which one the cursor or the selection
/// is in.
struct DepthStrip {
    /// One slab of the zone.
    struct Slab {
        uint32_t region = 0;        ///< its region id
        double z0 = 0.0, z1 = 0.0;  ///< its depth range along F
        size_t prims = 0;           ///< primitives listed
    };
    std::vector<Slab> slabs;  ///< by increasing depth, each beginning where the one before ends
    int current = -1;         ///< the slab holding the depth or region asked for (-1: none)
    /// The depth range of the slabs.
    double z0() const { return slabs.empty() ? 0.0 : slabs.front().z0; }
    double z1() const { return slabs.empty() ? 0.0 : slabs.back().z1; }
    /// Where depth z falls along the bar, in [0, 1]: each slab takes an equal share, in depth
    /// order, and z is placed linearly inside its slab. On a depth scale the slab reaching the
    /// far plane (which lists a floor, say) takes most of the bar and the slabs near the
    /// objects a few pixels.
    double at(double z) const;
};
/// Zone `zone`'s slabs of frame `fr`, the current one being the slab of region `region` when
/// given, else the one holding depth `depth` (the first of two that share it as a boundary).
DepthStrip depthStrip(const ZoneFrameView& fr, uint32_t zone, std::optional<double> depth,
                      std::optional<uint32_t> region = std::nullopt);

/// The frame the irregular overlays draw: the projective one when asked and present.
const ZoneFrameView* overlayFrame(const StructureView& sv, bool projective);

}  // namespace lancer::viewer::overlay
