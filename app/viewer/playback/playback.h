// Ray playback: a picked pixel's ray tree (tracePixel, engine/render/ray_tree.h) played region by
// region. The steps are the Region events the walk recorded, nothing else: the playback reads
// the one traversal that renders and that `lancer trace` prints, and walks nothing itself. No GL
// and no ImGui here, so tests drive it as the panel does.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

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

    /// The current step's Region event (nullptr when the ray walks no region).
    const WalkEvent* region() const;
    /// Index in the ray's events of each step's Region event.
    const std::vector<size_t>& steps() const { return steps_; }

    /// Counts of ray k before the last rebuild (retrace()), when there was one and the tree had
    /// that ray.
    std::optional<WalkCounts> previousCounts(int k) const;

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
};

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

/// The `lancer trace` line for the picked pixel: scene, --camera FILE (the camera JSON the caller
/// writes to `cameraFile`), size, scheme and the structure and shading parameters.
std::string traceCommand(const std::string& scene, const std::string& cameraFile,
                         const PickedPixel& px, const BuildParams& build,
                         const ShadingOptions& shading);

}  // namespace lancer::viewer::playback
