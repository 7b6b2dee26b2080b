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
/// A slab as the depth step makes it (depth_slabs.h) and the corner pointers link it
/// (corner_pointers.h): its depth range, its screen pointers, its restricted tree, its zone and
/// its list. The camera frame keeps each as a 32-byte IrregularRegion; the projective frames as
/// their own 16-byte slab (projective_zones.h).
struct IrregularSlab {
    double zlo = 0.0, zhi = 0.0;  ///< depth range in the camera frame
    int32_t lo[2] = {-1, -1};     ///< screen pointers at the low corner (x, y)
    int32_t hi[2] = {-1, -1};     ///< screen pointers at the high corner (x, y)
    int32_t root = -1;            ///< restricted tree in the shared pool; -1: an empty region
    uint32_t zone = 0;            ///< its screen zone
    uint32_t list = 0;            ///< its primitive list (DepthSlabs::listFirst)
};
// The build charges a region this much (kMergedZoneBytes): the structures it makes, and so the
// camera-frame records' content, stay those of a 48-byte record.
static_assert(sizeof(IrregularSlab) == 48);

/// The camera frame's region record, what its zone and its neighbours do not give. The region's
/// box is its zone's rectangle (the screen BSP's zoneLo/zoneHi, IrregularZoneRect) times
/// [zlo, zhi], where zhi is the next record's zlo, or the structure's far face on its zone's
/// last slab (the slabs of a zone tile the depth range, so these are the same doubles the depth
/// step cut at). A zone's slabs are stored in depth order, so the depth pointers lo[2] and hi[2]
/// are the records before and after it (-1 at the structure's near and far faces). The screen
/// pointers lo[0..1] and hi[0..1] are stored. first() is where its list's header lies: its
/// length, its restricted tree, then its entries, so the walk reads the three from one line.
/// That makes 32 bytes aligned to 32, one cache line's half, where the record with its end
/// depth, tree and list number took 48 and half of them straddled two lines
/// (docs/irregular.md, "A 32-byte region record").
struct alignas(32) IrregularRegion {
    /// Set in `firstBits` on a zone's last slab, which ends at the structure's far face. It is
    /// kept beside the list's position, read once a visit, rather than beside the zone, which the
    /// corner walk reads at every face test.
    static constexpr uint32_t kLastSlab = 0x8000'0000u;

    double zlo = 0.0;          ///< start depth in the camera frame
    int32_t lo[2] = {-1, -1};  ///< screen pointers at the low corner (x, y)
    int32_t hi[2] = {-1, -1};  ///< screen pointers at the high corner (x, y)
    uint32_t zone = 0;         ///< its screen zone
    /// first(), with kLastSlab set on its column's last slab
    uint32_t firstBits = 0;

    /// Where its list's header (length, tree), then its entries, lie in the owner's list array.
    uint32_t first() const { return firstBits & ~kLastSlab; }
    /// It is its zone's last slab: its end is the structure's far face, no record's start.
    bool lastSlab() const { return (firstBits & kLastSlab) != 0; }
};
static_assert(sizeof(IrregularRegion) == 32 && alignof(IrregularRegion) == 32);

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
