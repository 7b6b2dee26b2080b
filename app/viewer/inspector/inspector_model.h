// What the inspector draws, as data (no GL): the regions kept by the level range, the slice
// slab, the zone choice and the view, up to a cap the user sets, and the coloured lines of
// everything shown (regions, zone columns, directory blocks, minimized boxes, the camera's
// frustum and image plane, the selection). The GL view (inspector_view.h) uploads it; tests
// and picking read it.
#pragma once

#include <cstdint>
#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "app/viewer/gl/batch.h"
#include "app/viewer/inspector/inspector_geometry.h"
#include "app/viewer/region_filter.h"
#include "engine/accel/structure_view.h"

namespace lancer::viewer::inspector {

/// The inspector's switches and filters (the View panel edits them; `--show` sets the first).
struct InspectorOptions {
    bool show = false;           ///< the inspector is on screen
    bool regions = true;         ///< regular leaves, irregular slabs
    bool zones = true;           ///< irregular: zone columns (orthographic) or frusta (perspective)
    bool grid = false;           ///< regular: the directory's blocks and sub-tables
    bool boxes = false;          ///< the primitives' minimized boxes
    bool frustum = true;         ///< the camera's frustum and image plane
    bool surfaces = true;        ///< the scene traced from the inspector's camera, under the lines
    bool zoneSlabsOnly = false;  ///< irregular: only the selected zone's slabs
    ColorBy colorBy = ColorBy::Prims;
    /// Regular: the BSP levels kept (leaves by their level, directory blocks by theirs).
    int levelLo = 0, levelHi = 64;
    Slab slab;        ///< the slice slab (world axis)
    int cap = 20000;  ///< regions (and blocks, and boxes) drawn at most
    /// Regions drawn: all, or only the played ray's (not saved).
    RegionFilter only;
    bool operator==(const InspectorOptions&) const = default;
};

/// Where the camera's image lies: the main view's camera and image size.
struct MainView {
    Camera camera;
    int width = 1, height = 1;
};

/// The inspector's view: its camera and viewport size.
struct InspectorView {
    Camera camera;
    int width = 1, height = 1;
};

struct InspectorModel {
    std::vector<RegionView> regions;  ///< the regions drawn, which a click can pick
    gl::Batch lines;                  ///< everything but the selection
    gl::Batch selection;              ///< the selected region's edges
    size_t kept = 0;    ///< regions the filters kept in view, counted up to one past the cap
    size_t total = 0;   ///< regions of the structure (or of the frame primary rays walk)
    size_t blocks = 0;  ///< directory blocks kept (drawn: min(blocks, cap))
    int maxLevel = 0;   ///< deepest level among the structure's regions (regular)
    double top = 1.0;   ///< the colour scale's top: the largest value drawn
};

/// Whether any part of the volume can be in view: false when all its corners lie beyond one
/// edge of the image (or behind a perspective eye).
bool maybeVisible(const Camera& cam, int w, int h, const Corners& c);

/// The main camera's frustum (from its eye to the far side of the structure) and image plane,
/// as lines: what buildModel() adds with InspectorOptions::frustum.
gl::Batch frustumLines(const StructureView& view, const MainView& main);

/// The model of `view`'s structure as the options ask, seen from `insp`, with region
/// `selected` (-1: none) highlighted.
InspectorModel buildModel(const StructureView& view, const InspectorOptions& opt,
                          const MainView& main, const InspectorView& insp, int64_t selected);

/// Colours of the fixed elements.
inline constexpr glm::vec3 kBoxColor{0.45f, 0.75f, 1.0f};
inline constexpr glm::vec3 kFrustumColor{0.95f, 0.95f, 0.95f};
inline constexpr glm::vec3 kImagePlaneColor{1.0f, 0.85f, 0.2f};
inline constexpr glm::vec3 kZoneColor{0.45f, 0.45f, 0.5f};
inline constexpr glm::vec3 kCellColor{0.4f, 0.4f, 0.4f};       ///< a single directory cell
inline constexpr glm::vec3 kBlockColor{0.2f, 0.85f, 0.75f};    ///< one entry, several cells
inline constexpr glm::vec3 kSubTableColor{1.0f, 0.5f, 0.15f};  ///< a sub-table's block
inline constexpr glm::vec3 kSelectionColor{0.2f, 1.0f, 0.3f};

}  // namespace lancer::viewer::inspector
