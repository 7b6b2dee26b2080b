// A scene written for POV-Ray 3.7 (`lancer export SCENE --pov FILE.pov`, and the report's POV-Ray
// peer): the same camera, so that POV-Ray's pixel (x, y) is traced along the ray of Lancer's
// pixel (x, y) (docs/design.md section 6, "Pixels"), the primitives with their 4x4 transforms,
// the CSG tree, and the materials and lights roughly (Whitted's terms as POV-Ray's finish).
#pragma once

#include <iosfwd>
#include <string>

#include "engine/scene/scene.h"

namespace lancer::bench {

struct PovOptions {
    /// Reflection and refraction depth, as --bounces (POV-Ray's max_trace_level is one more).
    int bounces = 3;
    /// Instead of the materials and lights: every surface emits its primary hit's distance
    /// (perspective: from the eye; orthographic: along the view axis from the plane of `from`)
    /// as a grey level, 1 - distance / depthRange, the background black. With a 16-bit PNG of
    /// gamma 1 (+FN16 File_Gamma=1) it is POV-Ray's depth image, to the 1/65535 of depthRange.
    bool depth = false;
    double depthRange = 0.0;  ///< 0: depthRangeOf(scene, camera)
};

/// Write `scene` seen through `camera` as a POV-Ray 3.7 scene. The image's aspect ratio is read
/// from POV-Ray's image_width and image_height, so the file renders at any size (+W +H) with
/// square pixels, as Lancer does. Throws std::invalid_argument for a scene POV-Ray cannot take
/// (an empty tree).
void writePov(std::ostream& out, const Scene& scene, const Camera& camera,
              const PovOptions& options = {});

/// A depth range every primary hit of the scene lies within: a little more than the farthest
/// corner of the scene's bounds from the eye (along the view axis, orthographic).
double depthRangeOf(const Scene& scene, const Camera& camera);

}  // namespace lancer::bench
