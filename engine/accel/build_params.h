// What a structure is built from: the scheme, the knobs common to every scheme, and each
// scheme's own knobs in a Config of its own. Plain structs the command line, the viewer and the
// tests fill in; app/cli/param_table.* describes each field to the command line, the viewer's
// panel and its ini file.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/accel/bvh/bvh_config.h"

namespace lancer {

/// The schemes, in kSchemeTable's order (and Accelerator::Impl's alternatives').
enum class SchemeKind : uint8_t { Brute, Regular, Irregular, Bvh };

/// One scheme as the command line, the viewer, the dumps and the bench name and describe it.
struct SchemeInfo {
    SchemeKind kind;
    const char* name;     ///< --scheme, the ini, --stats, trace JSON, bench rows
    const char* title;    ///< a heading: what the scheme is
    const char* regions;  ///< what one of its regions is called, plural ("leaves", "zones")
    const char* help;     ///< one line for --help and the Parameters panel
};

/// Every scheme, one row each: a scheme added here (with its SchemeKind, its class in
/// Accelerator::Impl meeting AccelerationScheme, and its Config in BuildParams) is offered by
/// --scheme, the viewer's panel, `lancer bench` and the report without another change.
inline constexpr std::array kSchemeTable = {
    SchemeInfo{SchemeKind::Brute, "brute", "Brute force", "regions",
               "every primitive and the whole tree for every ray (the reference)"},
    SchemeInfo{SchemeKind::Regular, "regular", "Regular subdivision", "leaves",
               "3-axis BSP over the scene, a directory of its leaves, restricted trees "
               "(the report's section 3)"},
    SchemeInfo{SchemeKind::Irregular, "irregular", "Irregular subdivision", "zones",
               "2D screen BSP, depth slabs, corner pointers (the report's section 2)"},
    SchemeInfo{SchemeKind::Bvh, "bvh", "Bounding volume hierarchy", "nodes",
               "binned surface-area BVH over the minimized boxes, restricted trees in its "
               "leaves (the modern baseline)"},
};
inline constexpr int kSchemeCount = int(kSchemeTable.size());
static_assert(
    [] {
        for (int k = 0; k < kSchemeCount; ++k)
            if (kSchemeTable[k].kind != SchemeKind(k)) return false;
        return true;
    }(),
    "kSchemeTable lists the schemes in SchemeKind's order");

/// The table's row of scheme `k`.
constexpr const SchemeInfo& schemeInfo(SchemeKind k) { return kSchemeTable[size_t(k)]; }
/// The scheme named `name` (kSchemeTable's names), if any.
std::optional<SchemeKind> schemeFromName(std::string_view name);
/// Every scheme's name, in the table's order.
std::vector<std::string> schemeNames();
enum class StepMethod : uint8_t { Exact, Push };
enum class BspHeuristic : uint8_t { First, Balanced, FewestCuts };
/// Regular scheme: the axis each level of the BSP cuts. Cycle: x, y, z in turn (the report's);
/// cost: per level, the axis of least estimated cost (axis_planner.cpp, planSchedule).
enum class SplitAxes : uint8_t { Cycle, Cost };
/// Irregular scheme: primary rays walk the camera-frame structure, or the projective zones.
enum class IrregularFrame : uint8_t { Camera, Projective };

const char* schemeName(SchemeKind k);
const char* stepName(StepMethod s);
const char* heuristicName(BspHeuristic h);
const char* splitAxesName(SplitAxes s);
const char* irregularFrameName(IrregularFrame f);

/// max-objects' automatic value (RegularConfig, IrregularConfig; `--max-objects auto`): cells of
/// at most kAutoObjectsCount primitives stop, and the cost stop decides above that.
inline constexpr int kAutoObjects = -1;
inline constexpr int kAutoObjectsCount = 4;

/// The regular scheme's knobs (report, section 3). Defaults measured in docs/regular.md
/// ("Cost-driven splits", "Axis order", "Where push goes wrong"): a cell is split while the
/// split lowers the estimated cost of the rays crossing it, down to a depth that grows with the
/// scene; split axes `cost` takes 25% fewer render instructions than `cycle` on balls4, at most
/// 4% more on the SPD scenes; push matches brute force on every test ray at delta 1e-6, 0.05
/// skips thin cells, 1e-19 stalls.
///
/// The cost stop belongs to the automatic mode (max-level 0 and max-objects kAutoObjects): an
/// explicit max-level or max-objects builds by the report's rule, a cell split while it holds
/// more than max-objects primitives and is above max-level (docs/regular.md, "Explicit knobs").
struct RegularConfig {
    /// Deepest BSP level (one axis cut per level); 0: automatic (effectiveMaxLevel()).
    int maxLevel = 0;
    /// A cell with at most this many primitives stops; kAutoObjects: automatic (objects()).
    int maxObjects = kAutoObjects;
    StepMethod step = StepMethod::Exact;    ///< next-leaf method: exact, or the report's push
    double delta = 1e-6;                    ///< push distance, relative to the box's extent
    SplitAxes splitAxes = SplitAxes::Cost;  ///< the axis each BSP level cuts
    bool fullTable = false;                 ///< one full directory instead of sub-tables
    /// Build in a turned subtree's frame when chooseGridFrame() finds one (false: --world-frame,
    /// the world's axes always; docs/regular.md, "Turned scenes").
    bool turnedFrame = true;
    /// In the automatic mode, stop a cell where no split lowers the estimated cost (false: the
    /// report's rule alone, max-objects and max-level, with cells inside all their primitives'
    /// boxes kept whole). An explicit max-level or max-objects turns it off (usesCostStop()).
    bool costStop = true;
    /// Cost of a leaf the walk crosses, in primitive tests: callgrind instructions per region
    /// visit over those per sphere test, fitted on balls4 (docs/regular.md, "Cost-driven splits").
    double stepCost = 1.5;
    /// Cost of one primitive test (a sphere's; a polygon's weighs 1 + vertices / 4 of it).
    double testCost = 1.0;
    /// With the automatic depth and the cost stop: from gainLevel() on, a split is made only
    /// where it saves at least this many tests per ray crossing a cell of that level (its
    /// saving per ray crossing the cell, times the cell's area over such a cell's). The
    /// surface area estimate keeps splitting cells of many primitives much smaller than the
    /// scene, at a regular level every cell alike; this floor takes the dense ones deeper than
    /// the others (balls:6: 17% fewer tests per ray for 16% more leaves; docs/regular.md,
    /// "Cost-driven splits").
    double minGain = 8.0;
    /// Levels the automatic depth is lowered by; not a knob: RegularGrid sets it when the
    /// automatic depth would pass the builder's node limit, and builds again (docs/regular.md,
    /// "The node limit in the automatic mode").
    int autoLevelDrop = 0;

    /// Neither max-level nor max-objects is set: the depth and the stops are the build's choice.
    bool automatic() const { return maxLevel == 0 && maxObjects == kAutoObjects; }
    /// The max-objects the build stops cells at.
    int objects() const { return maxObjects == kAutoObjects ? kAutoObjectsCount : maxObjects; }
    /// Whether the cost stop (and the gain floor) decide: in the automatic mode, unless turned off.
    bool usesCostStop() const { return costStop && automatic(); }
};

/// The automatic depth's base level for a scene of `primitives` live primitives:
/// 16 + 0.65 log2 N, rounded, within 8..48 (docs/regular.md, "Cost-driven splits"); from it on,
/// splits pass the gain floor (RegularConfig::minGain).
int automaticMaxLevel(size_t primitives);
/// Levels the automatic depth goes below automaticMaxLevel() where the gain floor allows.
inline constexpr int kGainDepth = 4;
/// The max-level a build over `primitives` uses: the configured one; automatically
/// automaticMaxLevel() + kGainDepth with the cost stop (the gain floor bounds it), the base
/// level without (the report's rule alone would split every cell down to the cap; so with an
/// explicit max-objects).
int effectiveMaxLevel(const RegularConfig& config, size_t primitives);
/// The level from which the gain floor holds: automaticMaxLevel() with the cost stop
/// (RegularConfig::usesCostStop()); otherwise none (INT_MAX).
int gainLevel(const RegularConfig& config, size_t primitives);

/// The irregular scheme's knobs (report, section 2). Defaults measured in docs/irregular.md
/// ("Growth", "Segment heuristics", "Projective zones for primary rays"):
/// `balanced` makes 30% fewer zones than `first` and fewer region visits per ray than `first` or
/// `fewest-cuts`; the projective zones save 2-26% of the instructions per ray. max-objects 4 is
/// the regular scheme's value; the cost stop (stepCost 4, "Budget and stopping rule") leaves
/// balls4 a tenth of the zones and halves its region visits per ray.
/// As the regular scheme's, the cost stop belongs to the automatic mode: an explicit
/// max-objects builds by the report's rule alone (docs/irregular.md, "Explicit max-objects").
struct IrregularConfig {
    /// A screen cell over at most this many rectangles is a zone (0: never; kAutoObjects:
    /// automatic, objects()).
    int maxObjects = kAutoObjects;
    BspHeuristic heuristic = BspHeuristic::Balanced;    ///< choice of the splitting segment
    IrregularFrame frame = IrregularFrame::Projective;  ///< what primary rays walk
    /// With the automatic max-objects, leave a screen cell whole where no split lowers the
    /// estimated tests per ray (false: the report's rule alone, max-objects).
    bool costStop = true;
    /// Cost of the zone a screen split adds, in primitive tests (2, 4 and 8 measured: 4 renders
    /// balls4 and lattice:12 fastest for their build). The camera frame's cost stop; the
    /// projective structures' follows their walk (ZoneWalkModel) and splits where this one
    /// pays as well.
    double stepCost = 4.0;

    /// The max-objects the screen BSP stops cells at.
    int objects() const { return maxObjects == kAutoObjects ? kAutoObjectsCount : maxObjects; }
    /// Whether the cost stop decides: with the automatic max-objects, unless turned off.
    bool usesCostStop() const { return costStop && maxObjects == kAutoObjects; }
    bool operator==(const IrregularConfig&) const = default;  ///< every knob equal
};

/// Builder parameters: the scheme, the knobs every scheme reads, and each scheme's Config.
struct BuildParams {
    SchemeKind scheme = SchemeKind::Brute;  ///< the command line's default is regular
    bool mailboxes = true;                  ///< --no-mailbox turns them off to measure their effect
    /// Accelerated schemes: shorten shadow rays with the light buffer (light_buffer.h);
    /// --no-light-buffer turns it off to measure its effect. Brute force never uses it.
    bool lightBuffer = true;
    /// Bytes the structure may take while it is built (--memory-budget); 0: defaultMemoryBudget()
    /// (build_guard.h). A build over it stops subdividing or is refused, naming the budget.
    size_t memoryBudget = 0;
    RegularConfig regular;      ///< read by the regular scheme only
    IrregularConfig irregular;  ///< read by the irregular scheme only
    BvhConfig bvh;              ///< read by the BVH only
};

/// A max-objects as the command line writes it: "auto" for kAutoObjects, else the number.
std::string maxObjectsText(int maxObjects);
/// The knobs the scheme in use reads, as command-line options: "regular --max-level 0
/// --max-objects auto --step exact --split-axes cost" (and --delta, --full-table,
/// --no-cost-stop, --no-mailbox, --no-light-buffer where they apply and differ from the
/// defaults).
std::string toString(const BuildParams& p);
std::ostream& operator<<(std::ostream& os, const BuildParams& p);

}  // namespace lancer
