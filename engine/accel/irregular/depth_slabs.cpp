#include "engine/accel/irregular/depth_slabs.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "engine/accel/build_guard.h"
#include "engine/model/restriction.h"

namespace lancer {

std::vector<uint32_t> headedLists(const std::vector<uint32_t>& listFirst,
                                  const std::vector<uint32_t>& listPrims,
                                  std::span<const uint32_t> tail, std::vector<uint32_t>& heads) {
    const size_t lists = listFirst.empty() ? 0 : listFirst.size() - 1;
    std::vector<uint32_t> out;
    out.reserve(listPrims.size() + lists * (tail.size() + 1));
    heads.assign(lists + 1, 0);
    for (size_t l = 0; l < lists; ++l) {
        heads[l] = uint32_t(out.size());
        out.push_back(uint32_t(listFirst[l + 1] - listFirst[l] + tail.size()));
        out.insert(out.end(), listPrims.begin() + listFirst[l],
                   listPrims.begin() + listFirst[l + 1]);
        out.insert(out.end(), tail.begin(), tail.end());
    }
    heads[lists] = uint32_t(out.size());
    return out;
}

DepthSlabs buildDepthSlabs(const Scene& scene, const ScreenBsp& bsp,
                           const std::vector<glm::dvec2>& depth, double zlo, double zhi,
                           BuildGuard* guard, size_t maxBytes, size_t maxRegions) {
    DepthSlabs out;
    // Cuts closer than this are one (a thousandth of the padding of irregular.cpp).
    const double minGap = 1e-12 * std::max({std::abs(zlo), std::abs(zhi), 1e-300});
    // The depth range of the zone reference at p (a pointer into bsp.zonePrims).
    auto range = [&](const uint32_t* p) { return depth[size_t(p - bsp.zonePrims.data())]; };
    // A union-only scene's region is the union of its primitives: the walk merges their spans
    // (hitInLeaf), so no tree is made, and each reference costs its list entries alone.
    out.unionOnly = scene.tree.unionOnly();
    const size_t refBytes = mergedRefBytes(out.unionOnly);
    std::optional<TreeRestrictor> restrictor;
    if (!out.unionOnly) restrictor.emplace(scene.tree);
    // One tree and one list per distinct primitive set; list 0 is the empty set.
    RestrictedTreePool pool;
    auto share = [&](std::vector<uint32_t>& prims, IrregularRegion& r) {
        std::sort(prims.begin(), prims.end());
        const RestrictedTreePool::Entry e = pool.share(prims, [&](CsgTree& dst) {
            return restrictor ? restrictor->restrict(prims, dst) : -1;
        });
        r.list = e.list;
        r.root = e.root;
    };

    // What the slabs hold so far: vectors by capacity, and the pool.
    auto bytes = [&] {
        return out.regions.capacity() * sizeof(IrregularRegion) +
               out.zoneFirstRegion.capacity() * sizeof(uint32_t) + pool.bytes();
    };
    // What the zones not cut yet cost at least (merged): kept free for them.
    size_t reserve = bsp.zoneCount() * kMergedZoneBytes + bsp.zonePrims.size() * refBytes;
    // Slabs still to make at least: one per zone not cut yet.
    size_t regionsLeft = bsp.zoneCount();
    std::vector<double> cuts, allCuts;
    std::vector<uint32_t> inSlab, slabFirst, slabPrims, span, fill;
    // A zone's depth cuts: the structure's ends and every box's zmin and zmax, sorted, unique.
    auto zoneCuts = [&](const uint32_t* first, const uint32_t* last) {
        cuts = {zlo, zhi};
        for (const uint32_t* p = first; p != last; ++p) {
            cuts.push_back(std::clamp(range(p).x, zlo, zhi));
            cuts.push_back(std::clamp(range(p).y, zlo, zhi));
        }
        std::sort(cuts.begin(), cuts.end());
        cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
        // Depth ranges clipped per zone (narrowZones) round differently where two primitives'
        // boxes share a plane: cuts a few rounding errors apart would make slabs of no depth.
        // The first cut of such a run is kept, and the structure's far end; a coarser cut is
        // always safe (a slab lists every range overlapping it).
        size_t k = 1;
        for (size_t i = 1; i < cuts.size(); ++i) {
            if (cuts[i] - cuts[k - 1] >= minGap)
                cuts[k++] = cuts[i];
            else if (i + 1 == cuts.size())
                cuts[k > 1 ? k - 1 : k++] = cuts[i];
        }
        cuts.resize(k);
    };
    // Whether every zone's full slabs fit (bytes and regions): then no zone is held to its share.
    bool ample = true;
    // The zones' cuts as the check below makes them, kept for the slabs (zone z's are
    // keptCuts[keptFirst[z] ..]) while they take at most an eighth of the byte limit (as the
    // screen BSP's presorted orders, uncharged scratch): the zones past it sort theirs again.
    std::vector<double> keptCuts;
    std::vector<size_t> keptFirst{0};
    if (maxBytes || maxRegions) {
        size_t allBytes = 0, allSlabs = 0;
        for (uint32_t z = 0; z < bsp.zoneCount(); ++z) {
            if (guard) guard->poll();
            const uint32_t* first = bsp.zonePrims.data() + bsp.zoneFirst[z];
            const uint32_t* last = bsp.zonePrims.data() + bsp.zoneFirst[z + 1];
            zoneCuts(first, last);
            if (keptFirst.size() == z + 1 &&
                (!maxBytes || (keptCuts.size() + cuts.size()) * sizeof(double) <= maxBytes / 8)) {
                keptCuts.insert(keptCuts.end(), cuts.begin(), cuts.end());
                keptFirst.push_back(keptCuts.size());
            }
            size_t refs = 0;
            for (const uint32_t* p = first; p != last; ++p) {
                auto at = [&](double v) {
                    return std::lower_bound(cuts.begin(), cuts.end(), std::clamp(v, zlo, zhi));
                };
                refs += size_t(at(range(p).y) - at(range(p).x));
            }
            const size_t slabs = first == last ? 1 : cuts.size() - 1;
            allSlabs += slabs;
            allBytes += slabs * kMergedZoneBytes + refs * refBytes;
        }
        // The charge counts every reference's list entry and tree, which lists shared between
        // slabs make about half (balls:3, lattice:12): the per-zone check below holds each zone
        // to the limit whatever this says.
        ample = (!maxBytes || allBytes / 2 + bytes() <= maxBytes) &&
                (!maxRegions || allSlabs <= maxRegions);
    }
    out.zoneFirstRegion.push_back(0);
    for (uint32_t z = 0; z < bsp.zoneCount(); ++z) {
        const uint32_t* first = bsp.zonePrims.data() + bsp.zoneFirst[z];
        const uint32_t* last = bsp.zonePrims.data() + bsp.zoneFirst[z + 1];
        const size_t now = guard || maxBytes ? bytes() : 0;
        const size_t k = size_t(last - first);
        const size_t refsLeft = bsp.zonePrims.size() - bsp.zoneFirst[z];
        reserve -= kMergedZoneBytes + k * refBytes;
        --regionsLeft;
        if (guard) guard->poll("depth slabs", now, out.regions.size());
        IrregularRegion r;
        r.zone = z;
        r.zlo = zlo;
        r.zhi = zhi;
        if (first == last) {  // an empty zone: one empty region through the whole depth
            ++out.emptyZones;
            out.regions.push_back(r);
            out.zoneFirstRegion.push_back(uint32_t(out.regions.size()));
            continue;
        }
        if (z + 1 < keptFirst.size())
            cuts.assign(keptCuts.begin() + ptrdiff_t(keptFirst[z]),
                        keptCuts.begin() + ptrdiff_t(keptFirst[z + 1]));
        else
            zoneCuts(first, last);
        // Each box spans the slabs from the one holding its zmin to the one holding its zmax
        // (a box overlaps a slab's interior); the lists are filled by those spans (a sweep, not
        // a scan of the zone per slab).
        auto spans = [&] {
            const size_t n = cuts.size() - 1;
            slabFirst.assign(n + 1, 0);
            span.clear();
            for (const uint32_t* p = first; p != last; ++p) {
                const double lo = std::clamp(range(p).x, zlo, zhi);
                const double hi = std::clamp(range(p).y, zlo, zhi);
                size_t a = size_t(std::upper_bound(cuts.begin(), cuts.end(), lo) - cuts.begin());
                a = std::min(a == 0 ? 0 : a - 1, n - 1);
                const size_t b = std::min(
                    size_t(std::lower_bound(cuts.begin(), cuts.end(), hi) - cuts.begin()), n);
                span.push_back(uint32_t(a));
                span.push_back(uint32_t(std::max(a, b)));
                for (size_t i = a; i < b; ++i) ++slabFirst[i + 1];
            }
            for (size_t i = 0; i < n; ++i) slabFirst[i + 1] += slabFirst[i];
            return size_t(slabFirst[n]);
        };
        // The zone's slabs cost at most a region each and, per reference, a list entry and its
        // tree (lists shared with earlier slabs cost nothing more). Past the byte limit (what is
        // held, this zone, and the least the zones after it take) or the region limit, the zone
        // keeps every fourth cut, then every sixteenth, .., down to one slab (its slabs merge).
        allCuts = cuts;
        for (size_t step = 1;; step *= 4) {
            if (step > 1) {
                cuts.clear();
                for (size_t i = 0; i + 1 < allCuts.size(); i += step) cuts.push_back(allCuts[i]);
                cuts.push_back(allCuts.back());
            }
            const size_t slabs = cuts.size() - 1;
            const size_t refs = spans();
            const size_t cost = slabs * kMergedZoneBytes + refs * refBytes;
            // Within the limits, and within twice the zone's share of what is left beyond every
            // zone's least (its references over theirs), so the first zones do not take it all.
            const double share = ample ? 1e300 : 2.0 * double(k) / double(refsLeft);
            const size_t least = kMergedZoneBytes + k * refBytes;
            const bool fits =
                (!maxBytes ||
                 (now + cost + reserve <= maxBytes &&
                  double(cost - std::min(cost, least)) <=
                      share * double(maxBytes - std::min(maxBytes, now + reserve + least)))) &&
                (!maxRegions ||
                 (out.regions.size() + slabs + regionsLeft <= maxRegions &&
                  double(slabs - 1) <=
                      share * double(maxRegions - out.regions.size() - regionsLeft - 1)));
            if (fits || slabs == 1) {
                if (slabs == 1 && allCuts.size() > 2)
                    ++out.mergedZones;
                else if (step > 1)
                    ++out.coarseZones;
                break;
            }
        }
        slabPrims.resize(slabFirst.back());
        fill.assign(slabFirst.begin(), slabFirst.end() - 1);
        for (size_t j = 0; j < span.size(); j += 2)
            for (uint32_t i = span[j]; i < span[j + 1]; ++i) slabPrims[fill[i]++] = first[j / 2];
        for (size_t i = 0; i + 1 < cuts.size(); ++i) {
            // A zone of a thousand boxes makes two thousand slabs, each restricted and shared
            // (balls:5: half a second): a cancellation must not wait for the zone's end.
            if (guard && (i & 63) == 63) guard->poll();
            r.zlo = cuts[i];
            r.zhi = cuts[i + 1];
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
