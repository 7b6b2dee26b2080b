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
struct IrregularRegion {
    Box3 box;  ///< camera frame
    int32_t lo[3] = {-1, -1, -1};
    int32_t hi[3] = {-1, -1, -1};
    int32_t root = -1;  ///< restricted tree in the shared pool; -1: an empty region
    uint32_t zone = 0;  ///< its screen zone
    uint32_t list = 0;  ///< its primitive list (IrregularSubdivision::primitives)
};

/// Corner numbers reported to the observer: bit 0 x, bit 1 y, bit 2 z set for the high side.
inline constexpr int kLowCorner = 0;
inline constexpr int kHighCorner = 7;

}  // namespace lancer
