// The report's restriction for many small primitive sets over one large tree. restrictTree
// (engine/model/csg.h) visits the whole tree for each set; with thousands of regions over a
// scene of thousands of primitives that is quadratic. This does the same restriction, node for
// node, but visits only the ancestors of the kept primitives: the other subtrees restrict to
// the empty tree anyway.
#pragma once

#include <vector>

#include "engine/model/csg.h"

namespace lancer {

class TreeRestrictor {
  public:
    explicit TreeRestrictor(const CsgTree& tree);
    /// Same result as restrictTree(tree, tree.root, keep, dst) with keep = `prims`.
    int restrict(const std::vector<uint32_t>& prims, CsgTree& dst);

  private:
    int visit(int node, CsgTree& dst) const;
    void mark(const std::vector<uint32_t>& prims, char value);

    const CsgTree* tree_;
    std::vector<int> parent_;
    std::vector<std::vector<int>> leaves_;  ///< leaves of each primitive
    std::vector<char> live_;                ///< node is an ancestor of a kept primitive
};

}  // namespace lancer
