#include "engine/accel/irregular/corner_pointers.h"

#include <algorithm>

#include "engine/accel/build_guard.h"

namespace lancer {

uint32_t slabAt(const std::vector<IrregularRegion>& regions,
                const std::vector<uint32_t>& zoneFirstRegion, uint32_t zone, double z, int s) {
    uint32_t first = zoneFirstRegion[zone], last = zoneFirstRegion[zone + 1];
    // The first slab whose top is above z (s > 0) or at or above z (s <= 0).
    auto it = std::partition_point(
        regions.begin() + first, regions.begin() + last,
        [&](const IrregularRegion& r) { return s > 0 ? r.zhi <= z : r.zhi < z; });
    uint32_t i = uint32_t(it - regions.begin());
    return std::min(i, last - 1);
}

void linkCorners(const ScreenBsp& bsp, const Box3& bounds, DepthSlabs& slabs,
                 const BuildGuard* guard) {
    for (uint32_t zone = 0; zone < bsp.zoneCount(); ++zone) {
        // A million regions take a quarter of a second here (balls:6), several under the
        // sanitizers: a cancellation must not wait for them.
        if (guard && (zone & 1023) == 0) guard->poll();
        glm::dvec2 lo = bsp.zoneLo[zone], hi = bsp.zoneHi[zone];
        // The zones beyond this zone's corners, across each screen face (-1: the border).
        int64_t hx = hi.x < bounds.hi.x ? int64_t(bsp.locate(hi.x, hi.y, +1, -1)) : -1;
        int64_t hy = hi.y < bounds.hi.y ? int64_t(bsp.locate(hi.x, hi.y, -1, +1)) : -1;
        int64_t lx = lo.x > bounds.lo.x ? int64_t(bsp.locate(lo.x, lo.y, -1, +1)) : -1;
        int64_t ly = lo.y > bounds.lo.y ? int64_t(bsp.locate(lo.x, lo.y, +1, -1)) : -1;
        uint32_t first = slabs.zoneFirstRegion[zone], last = slabs.zoneFirstRegion[zone + 1];
        for (uint32_t i = first; i < last; ++i) {
            IrregularRegion& r = slabs.regions[i];
            // High corner: just below its zhi in the neighbour; low corner: just above its zlo.
            r.hi[0] = hx < 0 ? -1
                             : int32_t(slabAt(slabs.regions, slabs.zoneFirstRegion, uint32_t(hx),
                                              r.zhi, -1));
            r.hi[1] = hy < 0 ? -1
                             : int32_t(slabAt(slabs.regions, slabs.zoneFirstRegion, uint32_t(hy),
                                              r.zhi, -1));
            r.lo[0] = lx < 0 ? -1
                             : int32_t(slabAt(slabs.regions, slabs.zoneFirstRegion, uint32_t(lx),
                                              r.zlo, +1));
            r.lo[1] = ly < 0 ? -1
                             : int32_t(slabAt(slabs.regions, slabs.zoneFirstRegion, uint32_t(ly),
                                              r.zlo, +1));
        }
    }
}

}  // namespace lancer
