// The structure dump of docs/design.md section 6 (`lancer structure`): a StructureView as JSON.
#pragma once

#include <iosfwd>

#include "engine/accel/structure_view.h"

namespace lancer {

struct StructureDumpOptions {
    /// Structures of more regions than this are summarised (counts) unless `all`.
    static constexpr size_t kDefaultLimit = 1'000'000;
    int width = 0, height = 0;  ///< the image the pixel units refer to
    bool all = false;           ///< list every region whatever the count
    size_t limit = kDefaultLimit;
};

/// Whether the dump of `view` lists its regions or only counts them.
bool dumpIsSummary(const StructureView& view, const StructureDumpOptions& o);

/// Write the dump to `out`, streamed (a full irregular dump can reach hundreds of megabytes):
/// {"scheme", "width", "height", "camera", "regions", "summary", "primitives", and "regular",
/// "irregular", "projective" as the scheme has them}.
void writeStructureJson(const StructureView& view, const StructureDumpOptions& o,
                        std::ostream& out);

}  // namespace lancer
