// The costliest pixels of a complete image, for the Ray panel's "Worst rays" list: each pixel's
// ray tree (its primary ray and every secondary and shadow ray it spawned) as the render
// counted it, ranked by primitive tests, region visits or time. A row picks its pixel, whose
// tree the playback then traces and plays.
#pragma once

#include <cstdint>
#include <vector>

#include "engine/render/image.h"

namespace lancer::viewer::playback {

/// What ranks a pixel.
enum class RayCost : uint8_t { Tests, Visits, Time };

/// One pixel and what its rays cost.
struct CostlyPixel {
    int x = 0, y = 0;
    uint32_t tests = 0, visits = 0;
    float us = 0.0f;  ///< wall time of the pixel's rays, microseconds
};

/// The `n` pixels of `img` that cost most by `by`, costliest first (ties: the first pixel in
/// reading order first). Empty for an image without counters.
std::vector<CostlyPixel> costliestPixels(const Image& img, RayCost by, size_t n);

}  // namespace lancer::viewer::playback
