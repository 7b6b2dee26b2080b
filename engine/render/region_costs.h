// The cost of an image on its structure: for each region, how many times the image's rays
// entered it and how many primitive tests they made there. Counted by an observer of the
// render's own walk (Tracer::pixel with the render's eye buffer and trace context), so the
// counts add up to the render's counters (RayCounters::regionVisits, primTests) for the same
// image; the viewer colours the structure and its tree browser by them.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

#include "engine/render/renderer.h"

namespace lancer {

/// Which rays of each pixel's tree are counted.
enum class CostRays : uint8_t {
    All,      ///< the primary ray, its shadow rays and every reflected and refracted ray
    Primary,  ///< the primary ray alone
};
/// "all rays", "primary rays".
const char* costRaysName(CostRays r);

/// Region visits and primitive tests per region of one image, as prefix sums so that the
/// total over a range of region ids (a subtree whose regions are numbered together) is O(1).
struct RegionCosts {
    int width = 0, height = 0;
    CostRays rays = CostRays::All;
    /// visitsBefore[i]: visits of regions [0, i); size regions + 1. Likewise testsBefore.
    std::vector<uint64_t> visitsBefore, testsBefore;
    /// Tests made outside any region entered (none in today's schemes; counted, not lost).
    uint64_t unplacedTests = 0;

    size_t regions() const { return visitsBefore.empty() ? 0 : visitsBefore.size() - 1; }
    uint64_t visits(uint32_t region) const {
        return visitsBefore[region + 1] - visitsBefore[region];
    }
    uint64_t tests(uint32_t region) const { return testsBefore[region + 1] - testsBefore[region]; }
    /// Over regions [lo, hi).
    uint64_t visits(uint32_t lo, uint32_t hi) const { return visitsBefore[hi] - visitsBefore[lo]; }
    uint64_t tests(uint32_t lo, uint32_t hi) const { return testsBefore[hi] - testsBefore[lo]; }
    uint64_t totalVisits() const { return visitsBefore.empty() ? 0 : visitsBefore.back(); }
    uint64_t totalTests() const {
        return (testsBefore.empty() ? 0 : testsBefore.back()) + unplacedTests;
    }
};

/// Trace every pixel of the opt.width x opt.height image as render() does, with an observer
/// counting each region entered and each primitive test by the region it was made in, for the
/// rays `rays` selects. `regions`: the structure's region count (StructureView::regionCount);
/// a region id the walk reports beyond it is a bug (std::logic_error). Returns false, with
/// `out` unchanged, when `*cancel` becomes true (checked per row of a tile).
bool countRegionCosts(const Scene& scene, const Accelerator& accel, const RenderOptions& opt,
                      size_t regions, CostRays rays, RegionCosts& out,
                      const std::atomic<bool>* cancel = nullptr);

}  // namespace lancer
