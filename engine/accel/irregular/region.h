// One region of the irregular subdivision: a depth slab of a screen zone, a box in the camera
// frame, with its restricted CSG tree and its corner pointers.
#pragma once

#include <cstdint>

#include "engine/geometry/geometry.h"

namespace lancer {

/// Corner pointers (report, Fig. 4), two corners per region:
///  - at the low corner (xlo, ylo, zlo), lo[a] is the region holding the point just below that
///    corner across the face a = lo, just inside the region on the other two axes;
///  - at the high corner (xhi, yhi, zhi), hi[a] is the region just above that corner across the
///    face a = hi, just inside on the other two axes.
/// -1 where the face lies on the structure's border. This is Ousterhout's corner stitching
/// (1984) in 3D; see irregular.h for why these six pointers reach every neighbour.
///
/// The record keeps what its zone does not: the region's box is its zone's rectangle (the screen
/// BSP's zoneLo/zoneHi) times [zlo, zhi], and a zone's slabs are stored in depth order, so the
/// depth pointers lo[2] and hi[2] are the slabs before and after it in the array (-1 at the
/// structure's near and far faces). The screen pointers lo[0..1] and hi[0..1] are stored. That
/// makes 48 bytes a region where a full box and six pointers took 88 (balls4's camera frame:
/// 86,359 regions, 3.5 MB less; docs/irregular.md, "A compact region record"). `first` takes
/// what was the record's padding: the camera-frame walk reads its list's length and entries
/// from there in one line, without the list table between (docs/irregular.md, "Region visits
/// in fewer cache lines").
struct IrregularRegion {
    double zlo = 0.0, zhi = 0.0;  ///< depth range in the camera frame
    int32_t lo[2] = {-1, -1};     ///< screen pointers at the low corner (x, y)
    int32_t hi[2] = {-1, -1};     ///< screen pointers at the high corner (x, y)
    int32_t root = -1;            ///< restricted tree in the shared pool; -1: an empty region
    uint32_t zone = 0;            ///< its screen zone
    uint32_t list = 0;            ///< its primitive list (IrregularSubdivision::primitives)
    /// Where its list's length, then its entries, lie in the owner's list array (set by
    /// IrregularSubdivision::build; 0 in other owners' records)
    uint32_t first = 0;
};
static_assert(sizeof(IrregularRegion) == 48);

/// A camera-frame zone's rectangle as the walk reads it: the screen BSP's zoneLo and zoneHi side
/// by side, 32 bytes aligned to 32, so one cache line holds it where the BSP's two arrays take
/// two (docs/irregular.md, "Region visits in fewer cache lines").
struct alignas(32) IrregularZoneRect {
    glm::dvec2 lo{0.0};  ///< low corner (x, y)
    glm::dvec2 hi{0.0};  ///< high corner (x, y)
};
static_assert(sizeof(IrregularZoneRect) == 32);

/// Corner numbers reported to the observer: bit 0 x, bit 1 y, bit 2 z set for the high side.
inline constexpr int kLowCorner = 0;
inline constexpr int kHighCorner = 7;

}  // namespace lancer
