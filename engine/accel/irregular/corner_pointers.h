// Corner pointers of the irregular scheme (report, Fig. 4): see region.h for which corners
// carry them and irregular.h for why they suffice.
#pragma once

#include "engine/accel/irregular/depth_slabs.h"

namespace lancer {

class BuildGuard;  // build_guard.h

/// Fill lo[] and hi[] of every region. Built with the screen BSP (a point location per zone
/// corner) and a binary search over the neighbour zone's slabs; the walk never uses either.
/// `guard` (may be null) is polled for cancellation.
void linkCorners(const ScreenBsp& bsp, const Box3& bounds, DepthSlabs& slabs,
                 const BuildGuard* guard = nullptr);

/// The slab of zone `zone` holding depth z, on the side `s` of a cut (+1 above, -1 below).
uint32_t slabAt(const std::vector<IrregularRegion>& regions,
                const std::vector<uint32_t>& zoneFirstRegion, uint32_t zone, double z, int s);

}  // namespace lancer
