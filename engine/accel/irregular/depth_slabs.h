// The irregular scheme's 3D step: each zone of the screen BSP cut along depth at the zmin/zmax
// of the boxes over it (in a turned scene, the depths each primitive's boxes take over that zone:
// narrowZones, primitive_hulls.h). Each slab is a region with the primitives whose depth range
// overlaps its interior and their restricted tree; equal primitive sets share one tree in the
// pool. Ranges that only touch a slab are left out: with the padding of irregular.cpp their
// primitives have no hit there, and a closed overlap would add each box to the slabs on both
// sides of its own zmin and zmax.
#pragma once

#include <span>
#include <vector>

#include "engine/accel/irregular/region.h"
#include "engine/accel/irregular/screen_bsp.h"
#include "engine/model/restriction.h"
#include "engine/scene/scene.h"

namespace lancer {

struct DepthSlabs {
    std::vector<IrregularRegion> regions;   ///< zone by zone, slabs by increasing depth
    std::vector<uint32_t> zoneFirstRegion;  ///< zone z: regions [zoneFirstRegion[z], [z + 1])
    CsgTree pool;                           ///< the restricted trees (none when unionOnly)
    /// The scene is union-only: regions keep their primitive lists alone, no restricted tree
    /// (root -1 everywhere; a region is empty when its list is 0, the empty set).
    bool unionOnly = false;
    std::vector<uint32_t> listFirst;  ///< list l: listPrims[listFirst[l] .. [l + 1])
    std::vector<uint32_t> listPrims;
    size_t slabs = 0;        ///< regions cut in non-empty zones
    size_t emptyZones = 0;   ///< zones no rectangle touches (one region each)
    size_t emptySlabs = 0;   ///< slabs of non-empty zones that hold no primitive
    size_t mergedZones = 0;  ///< zones left as one slab to keep within the byte limit
    size_t coarseZones = 0;  ///< zones cut at a subset of their cuts to keep within the limits
};

class BuildGuard;  // build_guard.h

/// Bytes a zone's slabs cost at least, merged into one: a region, a pool entry, and per primitive
/// its list entry (kept twice: the list and the pool's index) and, unless the scene is union-only
/// (`unionOnly`: no tree is made), about two tree nodes.
inline constexpr size_t kMergedZoneBytes =
    sizeof(IrregularRegion) + RestrictedTreePool::kEntryBytes;
inline constexpr size_t kMergedRefBytes = 2 * sizeof(uint32_t) + 2 * sizeof(CsgNode);
inline constexpr size_t kUnionOnlyRefBytes = 2 * sizeof(uint32_t);
inline constexpr size_t mergedRefBytes(bool unionOnly) {
    return unionOnly ? kUnionOnlyRefBytes : kMergedRefBytes;
}

/// The lists (listFirst, listPrims) laid out for a walk that reads a list from one place: list
/// l becomes its length, its entries, then `tail`'s (the same for every list), from heads[l] of
/// the array returned (heads[lists]: its size). A region or slab keeps heads[l] and reads the
/// length from the line of the first entries, where a table of list starts cost a line of its
/// own a visit (docs/irregular.md, "Region visits in fewer cache lines").
std::vector<uint32_t> headedLists(const std::vector<uint32_t>& listFirst,
                                  const std::vector<uint32_t>& listPrims,
                                  std::span<const uint32_t> tail, std::vector<uint32_t>& heads);

/// Cut every zone of `bsp` along depth inside [zlo, zhi]; depth[i] is the depth range of the
/// zone reference bsp.zonePrims[i] (its primitive's camera box's, or narrower: narrowZones).
/// A zone whose slabs would take the structure past `maxBytes` bytes or `maxRegions` regions
/// (0: no limit) keeps every fourth cut (then every sixteenth, ..) until they fit, or is one slab
/// holding all its primitives: its slabs merge. `guard` (may be null)
/// is polled for cancellation.
DepthSlabs buildDepthSlabs(const Scene& scene, const ScreenBsp& bsp,
                           const std::vector<glm::dvec2>& depth, double zlo, double zhi,
                           BuildGuard* guard = nullptr, size_t maxBytes = 0, size_t maxRegions = 0);

}  // namespace lancer
