// What the ray playback draws, as a world-space line batch (no GL): the current region's edges
// from its 8 corners (StructureView), the played ray's stretch inside it, the rest of its walk
// and the pixel's other rays faint from their origins, the hit and its normal, and the step's
// scheme events: the corner pointer followed (irregular), the exit point and the directory cell
// looked up (regular). The image overlay and the inspector draw the same batch, each with its
// own camera.
#pragma once

#include <array>
#include <optional>

#include "app/viewer/gl/batch.h"
#include "app/viewer/playback/playback.h"
#include "engine/accel/structure_view.h"

namespace lancer::viewer::playback {

/// Colours of the drawing (tests look for them).
inline constexpr glm::vec3 kRegionColor{1.0f, 0.85f, 0.1f};    ///< the current region's edges
inline constexpr glm::vec3 kSegmentColor{1.0f, 0.2f, 0.9f};    ///< the ray inside the region
inline constexpr glm::vec3 kNormalColor{0.2f, 1.0f, 0.3f};     ///< the hit's normal
inline constexpr glm::vec3 kPointerColor{0.2f, 0.9f, 1.0f};    ///< the corner pointer used
inline constexpr glm::vec3 kCellColor{1.0f, 0.5f, 0.1f};       ///< the directory cell looked up
inline constexpr glm::vec3 kTestedColor{0.35f, 0.63f, 1.0f};   ///< a primitive tested in the step
inline constexpr glm::vec3 kMailboxColor{0.55f, 0.55f, 0.7f};  ///< one read from its mailbox

/// The current region's 8 corners (empty optional when the ray walks no region).
std::optional<std::array<Vec3, 8>> currentCorners(const RayPlayback& play,
                                                  const StructureView& view);

/// The minimized boxes of the primitives the current step read (testedBoxes): tested ones in
/// kTestedColor, those read from the mailbox in kMailboxColor.
gl::Batch testedBoxesBatch(const RayPlayback& play, const StructureView& view);

/// The batch for the playback's current state (the tested boxes included); markers are scaled by
/// the structure's extent.
gl::Batch rayBatch(const RayPlayback& play, const StructureView& view);

/// The world-to-clip matrix the image overlay draws rayBatch() with: the viewer's camera on a
/// width x height image (gl::worldToClip), its depth range holding the structure and the rays.
glm::mat4 imageClipMatrix(const Camera& camera, int width, int height, const RayPlayback& play,
                          const StructureView& view);

}  // namespace lancer::viewer::playback
