// The heat-map colour map, shared by the shader (as uniforms), the colour bar and the tests.
#pragma once

#include <array>
#include <cstdint>
#include <glm/vec3.hpp>
#include <vector>

#include "engine/render/image.h"

namespace lancer::viewer {

/// What the image area shows: the colour image or one per-pixel counter (those of --stats).
enum class ViewMode : uint8_t { Color, PrimTests, RegionVisits, TimeUs };
inline constexpr int kViewModeCount = 4;
const char* viewModeName(ViewMode m);

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

}  // namespace lancer::viewer
