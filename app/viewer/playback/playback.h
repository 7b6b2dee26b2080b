// Ray playback: a picked pixel's ray tree (tracePixel, engine/render/ray_tree.h) played region by
// region. The steps are the Region events the walk recorded, nothing else: the playback reads
// the one traversal that renders and that `lancer trace` prints, and walks nothing itself. No GL
// and no ImGui here, so tests drive it as the panel does.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "engine/render/ray_csg.h"
#include "engine/render/ray_tree.h"

namespace lancer::viewer::playback {

/// The pixel and the view it was traced in: what `lancer trace` needs to trace it again.
struct PickedPixel {
    int x = 0, y = 0;           ///< y = 0 on the top row
    int width = 0, height = 0;  ///< the image size the pixel belongs to
};

/// Where the playback stands: comparable, so tests check that stepping back and forth returns
/// the same states.
struct PlaybackState {
    int ray = 0;            ///< index in the tree's rays
    int step = -1;          ///< index among the ray's region steps; -1: the ray walks no region
    size_t eventBegin = 0;  ///< the step's events in the ray's events: [eventBegin, eventEnd)
    size_t eventEnd = 0;
    bool operator==(const PlaybackState&) const = default;
};

/// A walk's work, to compare the walk before a rebuild with the walk after it.
struct WalkCounts {
    uint64_t primTests = 0, mailboxHits = 0, regions = 0;
    bool operator==(const WalkCounts&) const = default;
};

/// Counts of one ray from its events.
WalkCounts countsOf(const TracedRay& r);

class RayPlayback {
  public:
    /// A new pick: its tree replaces the last one; ray 0 (the primary), its first step, paused.
    void setTree(const PickedPixel& pixel, RayTree tree);
    /// The same pixel traced again in a new structure: the current ray (when the tree still has
    /// it) and step (clamped) are kept, and the old walks' counts are kept for comparison.
    void retrace(RayTree tree);
    /// Forget the pick.
    void clear();

    bool empty() const { return tree_.rays.empty(); }
    const PickedPixel& pixel() const { return pixel_; }
    const RayTree& tree() const { return tree_; }
    /// The ray played.
    const TracedRay& ray() const { return tree_.rays[size_t(state_.ray)]; }
    const PlaybackState& state() const { return state_; }

    /// Choose ray k of the tree (0: the primary); its first step.
    void selectRay(int k);
    /// Region steps of the current ray.
    int stepCount() const { return int(steps_.size()); }
    /// Go to step k (clamped to the ray's steps).
    void seek(int k);
    void first() { seek(0); }
    void last() { seek(stepCount() - 1); }
    /// One step forward / back; false (and no move) at the end / the start.
    bool forward();
    bool back();

    /// Playing moves forward `speed` steps per second of advance(); at the last step it pauses.
    void play();
    void pause() { playing_ = false; }
    bool playing() const { return playing_; }
    double speed() const { return speed_; }
    void setSpeed(double stepsPerSecond);
    /// Time passes (the frame's delta, seconds): while playing, the steps it covers are taken.
    /// True when the step changed.
    bool advance(double seconds);

    /// The current step's region event (nullptr when the ray walks no region).
    const walk::Region* region() const;
    /// Index in the ray's events of each step's Region event.
    const std::vector<size_t>& steps() const { return steps_; }

    /// Counts of ray k before the last rebuild (retrace()), when there was one and the tree had
    /// that ray.
    std::optional<WalkCounts> previousCounts(int k) const;
    /// Changes whenever the tree does (a pick, a retrace, clear): caches of a tree's analysis
    /// compare it.
    uint64_t treeVersion() const { return version_; }

  private:
    void setState(int ray, int step);

    PickedPixel pixel_;
    RayTree tree_;
    std::vector<size_t> steps_;  ///< the current ray's regionSteps()
    PlaybackState state_;
    std::vector<WalkCounts> previous_;  ///< per ray, the walk before the rebuild
    bool playing_ = false;
    double speed_ = 2.0;
    double carried_ = 0.0;  ///< seconds played not yet worth a whole step
    uint64_t version_ = 0;
};

/// The regions the played ray walks (its Region events), sorted and unique; none when nothing
/// is picked.
std::vector<uint32_t> visitedRegions(const RayPlayback& play);

/// One row of the CSG strip: a primitive's spans along the ray, or the region tree's combined
/// spans.
struct SpanRow {
    uint32_t prim = kNoPrim;  ///< kNoPrim: the region tree's combined spans
    bool mailbox = false;     ///< the spans came from the mailbox (tested in an earlier region)
    SpanList spans;
};

/// The CSG along the ray in the current step: each primitive tested (or found in the mailbox,
/// with the spans of its earlier test), in order, then the region tree's combined spans when
/// the walk evaluated it. Read from the step's events.
std::vector<SpanRow> stepSpans(const RayPlayback& play);

/// The played ray's CSG (rayCsg: each step's node spans) and wasted work, computed once per
/// ray and tree.
class RayCsgCache {
  public:
    /// The analysis of the ray `play` plays, traced in `view` (computed when the ray or the tree
    /// changed). Empty steps when nothing is picked.
    const std::vector<StepCsg>& steps(const RayPlayback& play, const StructureView& view);
    /// The wasted work of the same ray (after steps()).
    const RayWaste& waste() const { return waste_; }

  private:
    uint64_t version_ = ~uint64_t(0);
    int ray_ = -1;
    const StructureView* view_ = nullptr;
    std::vector<StepCsg> steps_;
    RayWaste waste_;
};

/// One row of the CSG strip: a primitive's spans as a step read them, or a node of the region's
/// restricted tree with its spans (item by item as StepCsg has them).
struct StripRow {
    bool node = false;          ///< a node of the restricted tree (else a primitive the step read)
    Op op = Op::Primitive;      ///< nodes: the operator, or Primitive for a leaf
    uint32_t prim = kNoPrim;    ///< primitives and leaves
    int depth = 0;              ///< nodes: the root is 0
    bool mailbox = false;       ///< primitives: read from the mailbox (no test)
    bool evaluated = true;      ///< nodes: the walk's evaluator reached it
    bool onHit = false;         ///< holds the ray's visible hit as a boundary (the hit's chain)
    Waste waste = Waste::None;  ///< primitives tested: why the test was wasted, if it was
    SpanList spans;
};

/// The strip of step `k` of `steps`: the primitives read (tested, or from the mailbox, with
/// the waste class of each test), then the restricted tree's nodes in pre-order; the rows
/// holding the ray's hit as a boundary marked, in the step that found it.
std::vector<StripRow> regionStrip(const std::vector<StepCsg>& steps, const RayWaste& waste,
                                  const TracedRay& ray, int k);

/// A region's stretch on the whole ray's strip.
struct StripBand {
    double t0 = 0.0, t1 = 0.0;
    uint32_t region = 0;
    int step = 0;  ///< the playback step that region is
};

/// The whole ray's strip: each region's stretch; one row per primitive the ray read (its
/// spans, mailbox when it was never tested, its first test's waste class), then the result
/// row: each step's root spans clipped to the step's window, as `spans` of a row with `node`
/// set and depth 0.
struct RayStrip {
    std::vector<StripBand> bands;
    std::vector<StripRow> rows;
};
RayStrip rayStrip(const std::vector<StepCsg>& steps, const RayWaste& waste, const TracedRay& ray);

/// The minimized boxes of the primitives read in the current step (StructureView's scene).
struct TestedBox {
    uint32_t prim = kNoPrim;
    Box3 box;
    bool mailbox = false;  ///< read from the mailbox, not tested
};
std::vector<TestedBox> testedBoxes(const RayPlayback& play, const Scene& scene);

/// The `lancer trace` line for the picked pixel: scene, --camera FILE (the camera JSON the caller
/// writes to `cameraFile`), size, scheme and the structure and shading parameters.
std::string traceCommand(const std::string& scene, const std::string& cameraFile,
                         const PickedPixel& px, const BuildParams& build,
                         const ShadingOptions& shading);

}  // namespace lancer::viewer::playback
