#include "engine/accel/irregular/depth_slabs.h"

#include <algorithm>

#include "engine/accel/build_guard.h"
#include "engine/model/restriction.h"

namespace lancer {

DepthSlabs buildDepthSlabs(const Scene& scene, const ScreenBsp& bsp, const std::vector<Box3>& box,
                           double zlo, double zhi, BuildGuard* guard, size_t maxBytes,
                           size_t maxRegions) {
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
    // Slabs still to make at least: one per zone not cut yet.
    size_t regionsLeft = bsp.zoneCount();
    std::vector<double> cuts;
    std::vector<uint32_t> inSlab, slabFirst, slabPrims, span;
    out.zoneFirstRegion.push_back(0);
    for (uint32_t z = 0; z < bsp.zoneCount(); ++z) {
        const uint32_t* first = bsp.zonePrims.data() + bsp.zoneFirst[z];
        const uint32_t* last = bsp.zonePrims.data() + bsp.zoneFirst[z + 1];
        const size_t now = guard || maxBytes ? bytes() : 0;
        reserve -= kMergedZoneBytes + size_t(last - first) * kMergedRefBytes;
        --regionsLeft;
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
        // Depth cuts: the structure's ends and every box's zmin and zmax. Each box spans the
        // slabs between its own two cuts; the slabs' lists are made by those spans (a sweep, not
        // a scan of the zone per slab).
        const size_t k = size_t(last - first);
        cuts = {zlo, zhi};
        for (const uint32_t* p = first; p != last; ++p) {
            cuts.push_back(std::clamp(box[*p].lo.z, zlo, zhi));
            cuts.push_back(std::clamp(box[*p].hi.z, zlo, zhi));
        }
        std::sort(cuts.begin(), cuts.end());
        cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
        const size_t slabs = cuts.size() - 1;
        auto at = [&](double v) {
            return size_t(std::lower_bound(cuts.begin(), cuts.end(), std::clamp(v, zlo, zhi)) -
                          cuts.begin());
        };
        slabFirst.assign(slabs + 1, 0);
        span.clear();
        for (const uint32_t* p = first; p != last; ++p) {
            const size_t a = at(box[*p].lo.z), b = at(box[*p].hi.z);
            span.push_back(uint32_t(a));
            span.push_back(uint32_t(b));
            for (size_t i = a; i < b; ++i) ++slabFirst[i + 1];
        }
        for (size_t i = 0; i < slabs; ++i) slabFirst[i + 1] += slabFirst[i];
        // The zone's slabs cost at most a region each and, per reference, a list entry and its
        // tree (lists shared with earlier slabs cost nothing more). Past the byte limit (what is
        // held, this zone, and the least the zones after it take) or the region limit, the zone
        // stays one slab: its slabs merge.
        const size_t refs = slabFirst[slabs];
        const size_t cost = slabs * kMergedZoneBytes + refs * kMergedRefBytes;
        if ((maxBytes && now + cost + reserve > maxBytes) ||
            (maxRegions && out.regions.size() + slabs + regionsLeft > maxRegions)) {
            ++out.mergedZones;
            cuts = {zlo, zhi};
            slabFirst = {0, uint32_t(k)};
            slabPrims.assign(first, last);
        } else {
            slabPrims.resize(refs);
            std::vector<uint32_t> fill(slabFirst.begin(), slabFirst.end() - 1);
            size_t j = 0;
            for (const uint32_t* p = first; p != last; ++p, j += 2)
                for (uint32_t i = span[j]; i < span[j + 1]; ++i) slabPrims[fill[i]++] = *p;
        }
        for (size_t i = 0; i + 1 < cuts.size(); ++i) {
            r.box.lo.z = cuts[i];
            r.box.hi.z = cuts[i + 1];
            inSlab.assign(slabPrims.begin() + slabFirst[i], slabPrims.begin() + slabFirst[i + 1]);
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
