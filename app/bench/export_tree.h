// What the exporters (POV-Ray, OpenSCAD) share: a CSG node's operands as a renderer with n-ary
// operators writes them, and numbers written to read back to the last bit.
#pragma once

#include <string>
#include <vector>

#include "engine/model/csg.h"

namespace lancer::bench {

/// The operands of operator node `node`, in order: for a union or an intersection, its chain of
/// the same operator flattened (a union of unions is one union), left to right; for a left-deep
/// chain of differences, the first solid and then every solid taken from it.
std::vector<int> operands(const CsgTree& tree, int node);

/// The shortest decimal form of `v` that reads back to the same double ("0" for 0 and -0).
std::string shortest(double v);

}  // namespace lancer::bench
