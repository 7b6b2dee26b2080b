// The heat-map colour map, shared by the shader (as uniforms), the colour bar and the tests.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <optional>
#include <string>
#include <vector>

#include "engine/render/image.h"

namespace lancer::viewer {

/// What the image area shows: the colour image or one per-pixel counter (those of --stats).
enum class ViewMode : uint8_t { Color, PrimTests, RegionVisits, TimeUs };
inline constexpr int kViewModeCount = 4;
const char* viewModeName(ViewMode m);
/// The word naming a mode in the ini and on the command line (`--view`): color, prim_tests,
/// region_visits, time; and back (nullopt for another word).
const char* viewModeWord(ViewMode m);
std::optional<ViewMode> viewModeOf(const std::string& word);

/// Evenly spaced stops of the colour map (black through purple and orange to pale yellow,
/// like matplotlib's "inferno": monotonic in lightness, so the order of values reads at a glance).
const std::array<glm::vec3, 8>& colormapStops();
/// The colour of `v` in [0, 1] (clamped), interpolated linearly between stops as the shader does.
glm::vec3 colormap(float v);
/// The per-pixel counter `mode` shows, as floats, of rows [rowBegin, rowEnd) (-1: to the last);
/// empty for ViewMode::Color.
std::vector<float> heatChannel(const Image& img, ViewMode mode, int rowBegin = 0, int rowEnd = -1);
/// A scale that fits the counter: its 99th percentile (at least 1), so a few outliers (a pixel
/// whose thread was preempted, in the time map) do not leave the rest of the map dark; pixels
/// above it show at the top of the map.
float autoScale(const std::vector<float>& heat);
/// Where `count` falls on the colour map of `scale`, in [0, 1]: count / scale, or on a log
/// scale log(1 + count) / log(1 + scale) (the shader computes the same).
float heatValue(float count, float scale, bool logScale);

/// Levels coloured the same in every build: BSP levels, screen-BSP cut depths, slab order in
/// depth, sub-table depth. Level k < kLevelRamp has hue from red (0) to violet
/// (kLevelRamp - 1) in even steps; deeper levels are all white. Never relative to the deepest
/// level a build has, so a colour names one level across rebuilds.
inline constexpr int kLevelRamp = 24;
glm::vec3 levelColor(int level);
/// Counts (primitives per leaf or zone, slabs per zone) on a fixed log scale: 1 to
/// 10^kCountDecades spread evenly by decade over the colour map from its purple to its pale
/// yellow; 0 and 1 share the bottom, more than 10^kCountDecades the top.
inline constexpr int kCountDecades = 3;
/// Where `count` falls on that scale, in [0, 1].
float countPosition(double count);
/// Its colour: colormap(0.3 + 0.7 * countPosition(count)) (the map's dark third does not read
/// as a line on a dark image).
glm::vec3 countColor(double count);
/// Costs on the structure (region visits, primitive tests of the last complete image, per
/// region, leaf, zone or slab) on a fixed log scale: 1 to 10^kCostDecades by decade over the
/// same stretch of the colour map as counts, so a key read before a rebuild reads after it; a
/// region no ray reached is kNoCostColor, apart from the map.
inline constexpr int kCostDecades = 6;
inline const glm::vec3 kNoCostColor{0.42f, 0.45f, 0.5f};
/// Where `count` falls on that scale, in [0, 1] (1 and below at 0, 10^kCostDecades and above
/// at 1).
float costPosition(double count);
/// Its colour: colormap(0.3 + 0.7 * costPosition(count)), kNoCostColor for 0.
glm::vec3 costColor(double count);
/// The heat maps' automatic scale: the power of ten at or above `p99` (at least 1), so the
/// key's ends are whole decades and a rebuild whose 99th percentile stays within the decade
/// keeps the scale.
float decadeScale(float p99);

/// A difference channel's value for a pixel with nothing to compare (the new image has not
/// reached it): drawn as grey stripes, unlike any value of the map. Counters differ by far less.
inline constexpr float kNoDiff = 1e30f;
/// Stops of the diverging map of a rebuild's difference (ColorBrewer's RdBu), evenly spaced over
/// [-1, 1]: red where the new structure does more work, near-white (the middle stop) where
/// nothing changed, blue where it does less. Red against blue stays apart for the common colour
/// blindnesses, and both ends are dark so the size of a change reads as the distance from white.
const std::array<glm::vec3, 9>& divergingStops();
/// The colour of `v` in [-1, 1] (clamped) on the diverging map, interpolated linearly between
/// stops as the shader does: -1 the "worse" end (red), 0 the neutral colour, 1 "better" (blue).
glm::vec3 divergingColor(float v);
/// Where a difference `d` = old - new falls on the diverging map, in [-1, 1]: d / scale, or on a
/// log scale sign(d) log(1 + |d|) / log(1 + scale) (the shader computes the same); clamped.
float diffValue(float d, float scale, bool logScale);

}  // namespace lancer::viewer
