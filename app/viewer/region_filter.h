// The regions a view is narrowed to: "only the regions the picked ray visits" (the Ray panel,
// `--show visited`) keeps, in the overlays and the inspector alike, the regions whose Region
// events the played ray's walk recorded, and hides the others.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace lancer::viewer {

struct RegionFilter {
    bool on = false;            ///< false: every region passes
    std::vector<uint32_t> ids;  ///< sorted, unique: the regions that pass when on
    /// Region `id` is drawn.
    bool keeps(uint32_t id) const { return !on || std::binary_search(ids.begin(), ids.end(), id); }
    bool operator==(const RegionFilter&) const = default;
};

}  // namespace lancer::viewer
