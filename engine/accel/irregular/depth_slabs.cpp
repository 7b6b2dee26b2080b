#include "engine/accel/irregular/depth_slabs.h"

#include <algorithm>

#include "engine/accel/build_guard.h"
#include "engine/model/restriction.h"

namespace lancer {

DepthSlabs buildDepthSlabs(const Scene& scene, const ScreenBsp& bsp, const std::vector<Box3>& box,
                           double zlo, double zhi, BuildGuard* guard, size_t maxBytes) {
    DepthSlabs out;
    TreeRestrictor restrictor(scene.tree);
    // One tree and one list per distinct primitive set; list 0 is the empty set.
    RestrictedTreePool pool;
    auto share = [&](std::vector<uint32_t>& prims, IrregularRegion& r) {
        std::sort(prims.begin(), prims.end());
        const RestrictedTreePool::Entry e =
            pool.share(prims, [&](CsgTree& dst) { return restrictor.restrict(prims, dst); });
        r.list = e.list;
        r.root = e.root;
    };

    // What the slabs hold so far: vectors by capacity, and the pool.
    auto bytes = [&] {
        return out.regions.capacity() * sizeof(IrregularRegion) +
               out.zoneFirstRegion.capacity() * sizeof(uint32_t) + pool.bytes();
    };
    // What the zones not cut yet cost at least (merged): kept free for them.
    size_t reserve = bsp.zoneCount() * kMergedZoneBytes + bsp.zonePrims.size() * kMergedRefBytes;
    std::vector<double> cuts;
    std::vector<uint32_t> inSlab;
    out.zoneFirstRegion.push_back(0);
    for (uint32_t z = 0; z < bsp.zoneCount(); ++z) {
        const uint32_t* first = bsp.zonePrims.data() + bsp.zoneFirst[z];
        const uint32_t* last = bsp.zonePrims.data() + bsp.zoneFirst[z + 1];
        const size_t now = guard || maxBytes ? bytes() : 0;
        reserve -= kMergedZoneBytes + size_t(last - first) * kMergedRefBytes;
        if (guard) guard->poll("depth slabs", now, out.regions.size());
        IrregularRegion r;
        r.zone = z;
        r.box.lo = Vec3(bsp.zoneLo[z], zlo);
        r.box.hi = Vec3(bsp.zoneHi[z], zhi);
        if (first == last) {  // an empty zone: one empty region through the whole depth
            ++out.emptyZones;
            out.regions.push_back(r);
            out.zoneFirstRegion.push_back(uint32_t(out.regions.size()));
            continue;
        }
        // Depth cuts: the structure's ends and every box's zmin and zmax, unless the zone's
        // slabs could pass the limit: up to 2k + 1 regions, lists of k / 2 on average, and
        // their trees (a bound: lists shared between slabs and zones cost nothing more).
        const size_t k = size_t(last - first);
        const size_t worst = (2 * k + 1) * (kMergedZoneBytes + k * kMergedRefBytes / 2);
        cuts = {zlo, zhi};
        if (maxBytes && now + worst + reserve > maxBytes) {
            ++out.mergedZones;
        } else {
            for (const uint32_t* p = first; p != last; ++p) {
                cuts.push_back(std::clamp(box[*p].lo.z, zlo, zhi));
                cuts.push_back(std::clamp(box[*p].hi.z, zlo, zhi));
            }
        }
        std::sort(cuts.begin(), cuts.end());
        cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
        for (size_t i = 0; i + 1 < cuts.size(); ++i) {
            r.box.lo.z = cuts[i];
            r.box.hi.z = cuts[i + 1];
            inSlab.clear();
            for (const uint32_t* p = first; p != last; ++p)
                if (box[*p].lo.z < cuts[i + 1] && box[*p].hi.z > cuts[i]) inSlab.push_back(*p);
            if (inSlab.empty()) ++out.emptySlabs;
            share(inSlab, r);
            out.regions.push_back(r);
            ++out.slabs;
        }
        out.zoneFirstRegion.push_back(uint32_t(out.regions.size()));
    }
    out.pool = std::move(pool.trees);
    out.listFirst = std::move(pool.listFirst);
    out.listPrims = std::move(pool.lists);
    return out;
}

}  // namespace lancer
