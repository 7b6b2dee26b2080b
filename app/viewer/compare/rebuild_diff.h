// The A/B of a rebuild, as data (no GL, no ImGui): when a parameter change replaces the
// structure, the per-pixel counters of the last complete image (A, the old structure's) are kept,
// and the image of the new structure (B) is compared with them pixel for pixel: primitive tests,
// region visits and time, old minus new, and their totals. Two images compare only when they are
// of the same scene, camera, size and shading: only the structure differs.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "app/viewer/colormap.h"
#include "engine/render/progressive.h"

namespace lancer::viewer::compare {

/// What the heat map shows of the A/B: the new image's counter (the current one), the old
/// image's, or old minus new.
enum class AbView : uint8_t { New, Old, Diff };
inline constexpr int kAbViewCount = 3;
/// "new", "old", "diff" (the --ab values).
const char* abViewKey(AbView v);
/// The view of `key`; nullopt for another word.
std::optional<AbView> abViewOf(const std::string& key);

/// What an image is a render of, besides its structure: images compare pixel for pixel only
/// when these are equal.
struct RenderKey {
    std::string spec;  ///< the scene
    Camera camera;
    int width = 0, height = 0;
    ShadingOptions shading;
    bool operator==(const RenderKey& o) const;
};

/// A counter summed over some pixels.
struct CounterSums {
    uint64_t primTests = 0, regionVisits = 0;
    double timeUs = 0.0;  ///< the pixels' own times added up (not wall time)
    size_t pixels = 0;
};

/// The counters of a complete image, kept as A.
struct CounterImage {
    int width = 0, height = 0;
    std::vector<uint32_t> primTests, regionVisits;
    std::vector<float> timeUs;
    RayCounters counters;   ///< the job's passes added up (rays, tests, visits of the image)
    double renderMs = 0.0;  ///< the passes' render times added up (wall time)
    BuildParams params;     ///< the structure that rendered it
    RenderKey key;

    /// The counters of `img`, rendered of `key` by a structure of `params` in `passes`.
    static CounterImage of(const Image& img, const RenderKey& key, const BuildParams& params,
                           const std::vector<PassRecord>& passes);
};

/// Sums of rows [0, rows) of an image's counters.
CounterSums sumRows(const Image& img, int rows);
CounterSums sumRows(const CounterImage& img, int rows);

/// The counter `mode` of A for rows [rowBegin, rowEnd), as floats (heatChannel's layout).
std::vector<float> counterChannel(const CounterImage& a, ViewMode mode, int rowBegin, int rowEnd);
/// Old minus new of the counter `mode`, for rows [rowBegin, rowEnd) (-1: to the last) of images
/// of the same size; rows at or after `validRows` (which `b` has not reached) hold kNoDiff.
std::vector<float> diffChannel(const CounterImage& a, const Image& b, ViewMode mode, int rowBegin,
                               int rowEnd, int validRows);
/// A scale that fits a difference channel: the 99th percentile of |d| over its compared pixels
/// (at least 1), as autoScale() for one image.
float diffAutoScale(const std::vector<float>& diff);

/// The knobs of the parameter table that differ between two structures, as
/// "max-level 24 -> 16, max-objects 4 -> 2"; "same parameters" when none does.
std::string paramChanges(const BuildParams& a, const BuildParams& b);

/// How an A/B stands this frame.
struct AbStatus {
    bool comparable = false;  ///< A exists and is of the current render's key
    int rows = 0;             ///< rows of B compared (its full-resolution rows done)
    int height = 0;
    /// Why there is nothing (or only part) to compare; empty when the whole image compares.
    std::string note;
};

/// The A/B state across rebuilds: keeps A, says whether the current render compares with it.
class RebuildDiff {
  public:
    /// A new structure of the same scene replaces the one that rendered `shown`. `shown` becomes
    /// A when `complete` (every row rendered at full resolution, by `params` at `key`); else
    /// the A kept so far stays (an older complete image, compared while its key holds), and if
    /// there is none the next comparison says "no complete old image to compare".
    void rebuilt(const Image& shown, bool complete, const RenderKey& key, const BuildParams& params,
                 const std::vector<PassRecord>& passes);
    /// Another scene is opened: nothing compares with what came before.
    void clear();
    /// The A kept (null: none).
    const CounterImage* old() const { return old_ ? &*old_ : nullptr; }
    /// Incremented whenever A changes (to upload the heat map again).
    uint64_t generation() const { return generation_; }
    /// The status against the current render of `key`, whose rows [0, doneRows) are rendered
    /// at full resolution.
    AbStatus status(const RenderKey& key, int doneRows) const;

  private:
    std::optional<CounterImage> old_;
    bool rebuiltOnce_ = false;     ///< a rebuild happened since the scene was opened
    bool lastIncomplete_ = false;  ///< the last rebuild came before its image was complete
    uint64_t generation_ = 0;
};

}  // namespace lancer::viewer::compare
