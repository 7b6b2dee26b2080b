#include "engine/accel/irregular/tree_restrictor.h"

namespace lancer {

TreeRestrictor::TreeRestrictor(const CsgTree& tree)
    : tree_(&tree), parent_(tree.nodes.size(), -1), live_(tree.nodes.size(), 0) {
    for (size_t n = 0; n < tree.nodes.size(); ++n) {
        const CsgNode& x = tree.nodes[n];
        if (x.op == Op::Primitive) {
            if (leaves_.size() <= x.prim) leaves_.resize(x.prim + 1);
            leaves_[x.prim].push_back(int(n));
        } else {
            parent_[x.left] = int(n);
            parent_[x.right] = int(n);
        }
    }
}

void TreeRestrictor::mark(const std::vector<uint32_t>& prims, char value) {
    for (uint32_t p : prims) {
        if (p >= leaves_.size()) continue;
        for (int n : leaves_[p])
            for (; n >= 0 && live_[n] != value; n = parent_[n]) live_[n] = value;
    }
}

int TreeRestrictor::visit(int node, CsgTree& dst) const {
    if (node < 0 || !live_[node]) return -1;
    const CsgNode& x = tree_->nodes[node];
    if (x.op == Op::Primitive) return dst.leaf(x.prim);
    // The rules of restrictTree, in the same order, so both build the same nodes.
    int a = visit(x.left, dst);
    if (a < 0 && x.op != Op::Union) return -1;
    int b = visit(x.right, dst);
    if (a >= 0 && b >= 0) return dst.combine(x.op, a, b);
    if (a < 0 && b < 0) return -1;
    if (a < 0) return b;
    return x.op == Op::Intersection ? -1 : a;
}

int TreeRestrictor::restrict(const std::vector<uint32_t>& prims, CsgTree& dst) {
    mark(prims, 1);
    int root = visit(tree_->root, dst);
    mark(prims, 0);
    return root;
}

}  // namespace lancer
