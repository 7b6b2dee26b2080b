// The cost of the last complete image on the structure it was rendered with: region visits and
// primitive tests per region (engine/render/region_costs.h), which the overlays' cost colourings
// and the tree browser read. Counted once per complete image, off the UI thread, only while
// something on screen shows them (ViewerState::requestCosts).
#pragma once

#include <cstdint>
#include <memory>

#include "app/viewer/structure_builder.h"
#include "engine/render/region_costs.h"

namespace lancer::viewer {

struct ImageCosts {
    std::shared_ptr<const SceneBuild> build;  ///< the structure the region ids are of
    RegionCosts costs;
    uint64_t job = 0;  ///< the render job (ProgressiveRenderer::job()) of the image counted
    double ms = 0.0;   ///< how long the count took
};

/// `c` is of structure `build` and counts `rays`.
inline bool costsFit(const ImageCosts* c, const SceneBuild* build, CostRays rays) {
    return c && c->build.get() == build && c->costs.rays == rays;
}

}  // namespace lancer::viewer
