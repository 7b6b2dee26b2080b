// NFF (Neutral File Format, Eric Haines' SPD): v b l f s p pp c and # comments.
#pragma once

#include "engine/scene/scene.h"
#include "engine/scene/source_text.h"

namespace lancer {

struct NffCounts {
    int spheres = 0, polygons = 0, patches = 0, cones = 0, lights = 0, materials = 0;
    int degenerate = 0;  ///< zero-area polygons skipped
};

/// Read an NFF scene. Spheres are solids; polygons, patches and cones are surfaces; all in one
/// top-level union. Throws SceneError naming file, line and column.
Scene readNff(const SourceText& src, NffCounts* counts = nullptr);

}  // namespace lancer
