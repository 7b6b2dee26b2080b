#include "engine/model/restriction.h"

#include <algorithm>
#include <span>

#include "engine/util/hash.h"
#include "engine/util/huge_pages.h"

namespace lancer {

namespace {

/// The report's rules from `node` down, the walk entering only nodes for which live(node) holds
/// (a primitive's leaf: it is kept; an operator: it may hold a kept primitive). Both
/// restrictions are this walk, so they build the same nodes in the same order.
/// Nodes written to an array of room enough, numbered from `base`: the same calls as a CsgTree's.
struct ArrayDst {
    CsgNode* out;
    int base;
    int n = 0;
    int leaf(uint32_t prim) {
        out[n] = {Op::Primitive, -1, -1, prim};
        return base + n++;
    }
    int combine(Op op, int a, int b) {
        out[n] = {op, a, b, kNoPrim};
        return base + n++;
    }
};

template <class Live, class Dst>
int restrictWalk(const CsgTree& src, int node, const Live& live, Dst& dst) {
    if (node < 0 || !live(node)) return -1;
    const CsgNode& x = src.nodes[size_t(node)];
    if (x.op == Op::Primitive) return dst.leaf(x.prim);
    int a = restrictWalk(src, x.left, live, dst);
    // Short cut: with A empty, intersection and difference are empty whatever B is.
    if (a < 0 && x.op != Op::Union) return -1;
    int b = restrictWalk(src, x.right, live, dst);
    if (a >= 0 && b >= 0) return dst.combine(x.op, a, b);
    if (a < 0 && b < 0) return -1;
    if (a < 0) return b;                       // only B: union gives B
    return x.op == Op::Intersection ? -1 : a;  // only A: union and difference give A
}

}  // namespace

int restrictTree(const CsgTree& src, int node, const std::vector<char>& keep, CsgTree& dst) {
    return restrictWalk(
        src, node,
        [&](int n) {
            const CsgNode& x = src.nodes[size_t(n)];
            return x.op != Op::Primitive || keep[x.prim];
        },
        dst);
}

int restrictTreeTo(const CsgTree& src, const std::vector<uint32_t>& prims, std::vector<char>& marks,
                   CsgTree& dst) {
    for (uint32_t p : prims) marks[p] = 1;
    const int root = restrictTree(src, src.root, marks, dst);
    for (uint32_t p : prims) marks[p] = 0;
    return root;
}

bool restrictionWithin(const CsgTree& tree, std::span<const uint32_t> held,
                       std::vector<uint32_t>& out) {
    out.clear();
    if (held.empty() || tree.root < 0) return false;
    // Each node's state over the region, children first (they are stored before their
    // parents, as combine() and the restrictions append them).
    constexpr uint8_t kEmpty = 0, kFull = 1, kMixed = 2;
    const size_t n = size_t(tree.root) + 1;
    std::vector<uint8_t> state(n, kEmpty);
    for (size_t i = 0; i < n; ++i) {
        const CsgNode& x = tree.nodes[i];
        if (x.op == Op::Primitive) {
            out.push_back(x.prim);
            state[i] = std::binary_search(held.begin(), held.end(), x.prim) ? kFull : kMixed;
            continue;
        }
        if (size_t(x.left) >= i || size_t(x.right) >= i) return false;
        const uint8_t a = state[size_t(x.left)], b = state[size_t(x.right)];
        switch (x.op) {
            case Op::Union:
                state[i] = a == kFull || b == kFull ? kFull
                           : a == kEmpty            ? b
                           : b == kEmpty            ? a
                                                    : kMixed;
                break;
            case Op::Intersection:
                state[i] = a == kEmpty || b == kEmpty ? kEmpty
                           : a == kFull && b == kFull ? kFull
                                                      : kMixed;
                break;
            default:  // difference
                state[i] = a == kEmpty || b == kFull ? kEmpty : b == kEmpty ? a : kMixed;
                break;
        }
    }
    // A primitive with two leaves: restricting to a list would keep both.
    std::sort(out.begin(), out.end());
    const bool shared = std::adjacent_find(out.begin(), out.end()) != out.end();
    out.clear();
    if (state[size_t(tree.root)] != kMixed) return true;  // no boundary in the region
    if (shared) return false;
    // The primitives of the subtrees the rules keep: of a full union one full side, of an
    // intersection both, of a difference its minuend alone when the subtrahend is empty.
    std::vector<int> stack = {tree.root};
    while (!stack.empty()) {
        const CsgNode& x = tree.nodes[size_t(stack.back())];
        stack.pop_back();
        if (x.op == Op::Primitive) {
            out.push_back(x.prim);
            continue;
        }
        const uint8_t a = state[size_t(x.left)], b = state[size_t(x.right)];
        const bool keepLeft = x.op == Op::Union ? a != kEmpty && !(b == kFull && a != kFull) : true;
        const bool keepRight = x.op == Op::Union          ? b != kEmpty && a != kFull
                               : x.op == Op::Intersection ? true
                                                          : b != kEmpty;
        if (keepLeft) stack.push_back(x.left);
        if (keepRight) stack.push_back(x.right);
    }
    std::sort(out.begin(), out.end());
    return true;
}

TreeRestrictor::TreeRestrictor(const CsgTree& tree) : tree_(&tree) {
    reserveHuge(parent_, tree.nodes.size());
    parent_.assign(tree.nodes.size(), -1);
    // Count each primitive's leaves, then place them: leaves in node order per primitive. The
    // arrays are sized once and placing moves each start to the next one's, shifted back after
    // (on a million nodes, growing them and a copy for the cursors were thousands of fresh
    // pages).
    uint32_t prims = 0;
    for (const CsgNode& x : tree.nodes)
        if (x.op == Op::Primitive) prims = std::max(prims, x.prim + 1);
    if (prims) {
        reserveHuge(leafFirst_, size_t(prims) + 1);
        leafFirst_.assign(size_t(prims) + 1, 0);
    }
    for (size_t n = 0; n < tree.nodes.size(); ++n) {
        const CsgNode& x = tree.nodes[n];
        if (x.op == Op::Primitive) {
            ++leafFirst_[size_t(x.prim) + 1];
        } else {
            parent_[size_t(x.left)] = int(n);
            parent_[size_t(x.right)] = int(n);
        }
    }
    for (size_t p = 1; p < leafFirst_.size(); ++p) leafFirst_[p] += leafFirst_[p - 1];
    reserveHuge(leafNodes_, leafFirst_.empty() ? 0 : leafFirst_.back());
    leafNodes_.resize(leafFirst_.empty() ? 0 : leafFirst_.back());
    for (size_t n = 0; n < tree.nodes.size(); ++n)
        if (tree.nodes[n].op == Op::Primitive)
            leafNodes_[leafFirst_[tree.nodes[n].prim]++] = int(n);
    for (size_t p = leafFirst_.size(); p-- > 1;) leafFirst_[p] = leafFirst_[p - 1];
    if (!leafFirst_.empty()) leafFirst_[0] = 0;
    // A union-only tree's depth-first places, for restrictUnions(), from a stack rather than a
    // recursion (a chain of unions may be deep): a node is placed when first met, and its
    // subtree's end set when ~node, pushed under its children, comes back up.
    unionOnly_ = tree.unionOnly();
    if (!unionOnly_ || tree.root < 0) return;
    reserveHuge(places_, tree.nodes.size());
    places_.assign(tree.nodes.size(), Place{});
    for (size_t n = 0; n < tree.nodes.size(); ++n) places_[n].parent = parent_[n];
    std::vector<int> stack{tree.root};
    int placed = 0;
    while (!stack.empty()) {
        const int n = stack.back();
        stack.pop_back();
        if (n < 0) {
            places_[size_t(~n)].last = placed;
            continue;
        }
        places_[size_t(n)].pre = placed++;
        stack.push_back(~n);
        const CsgNode& x = tree.nodes[size_t(n)];
        if (x.op != Op::Primitive) stack.push_back(x.right), stack.push_back(x.left);
    }
}

int TreeRestrictor::restrictUnions(std::span<const uint32_t> prims, CsgNode* out, int base,
                                   std::vector<int>& scratch) const {
    // The kept leaves the root reaches, in depth-first order (a balanced union of primitives
    // listed in order already has them so).
    scratch.clear();
    for (uint32_t p : prims) {
        if (size_t(p) + 1 >= leafFirst_.size()) continue;
        for (uint32_t l = leafFirst_[p]; l < leafFirst_[size_t(p) + 1]; ++l)
            if (places_[size_t(leafNodes_[l])].pre >= 0) scratch.push_back(leafNodes_[l]);
    }
    const auto before = [&](int a, int b) {
        return places_[size_t(a)].pre < places_[size_t(b)].pre;
    };
    if (!std::is_sorted(scratch.begin(), scratch.end(), before))
        std::sort(scratch.begin(), scratch.end(), before);
    const size_t leaves = scratch.size();
    if (leaves == 0) return -1;
    // restrictWalk writes a union once its right side is done, that is before the first kept
    // leaf past it: the unions met between two leaves wait on a stack (behind the leaves in
    // `scratch`), each with its left side's root, and those below the next meeting point are
    // written, deepest first, before the next leaf.
    ArrayDst dst{out, base};
    const std::vector<CsgNode>& nodes = tree_->nodes;
    int cur = dst.leaf(nodes[size_t(scratch[0])].prim);
    for (size_t i = 1; i < leaves; ++i) {
        const int next = places_[size_t(scratch[i])].pre;
        int meet = places_[size_t(scratch[i - 1])].parent;
        while (!(places_[size_t(meet)].pre <= next && next < places_[size_t(meet)].last))
            meet = places_[size_t(meet)].parent;
        while (scratch.size() > leaves &&
               places_[size_t(scratch[scratch.size() - 2])].pre > places_[size_t(meet)].pre) {
            cur = dst.combine(Op::Union, scratch.back(), cur);
            scratch.resize(scratch.size() - 2);
        }
        scratch.push_back(meet);
        scratch.push_back(cur);
        cur = dst.leaf(nodes[size_t(scratch[i])].prim);
    }
    for (; scratch.size() > leaves; scratch.resize(scratch.size() - 2))
        cur = dst.combine(Op::Union, scratch.back(), cur);
    return cur;
}

void TreeRestrictor::mark(std::span<const uint32_t> prims, char value,
                          std::vector<char>& live) const {
    for (uint32_t p : prims) {
        if (size_t(p) + 1 >= leafFirst_.size()) continue;
        for (uint32_t l = leafFirst_[p]; l < leafFirst_[size_t(p) + 1]; ++l)
            for (int n = leafNodes_[l]; n >= 0 && live[size_t(n)] != value; n = parent_[size_t(n)])
                live[size_t(n)] = value;
    }
}

int TreeRestrictor::restrict(const std::vector<uint32_t>& prims, CsgTree& dst,
                             std::vector<char>& live) const {
    mark(prims, 1, live);
    const int root = restrictWalk(
        *tree_, tree_->root, [&](int n) { return live[size_t(n)] != 0; }, dst);
    mark(prims, 0, live);
    return root;
}

int TreeRestrictor::restrict(std::span<const uint32_t> prims, CsgNode* out, int base,
                             std::vector<char>& live) const {
    mark(prims, 1, live);
    ArrayDst dst{out, base};
    const int root = restrictWalk(
        *tree_, tree_->root, [&](int n) { return live[size_t(n)] != 0; }, dst);
    mark(prims, 0, live);
    return root;
}

size_t RestrictedTreePool::Hash::operator()(const std::vector<uint32_t>& v) const {
    return size_t(hashWords(v));
}

RestrictedTreePool::RestrictedTreePool() : listFirst{0, 0} {
    index_.emplace(std::vector<uint32_t>{}, Entry{});
}

RestrictedTreePool::Entry RestrictedTreePool::add(const std::vector<uint32_t>& prims, int root) {
    const uint32_t list = uint32_t(listFirst.size() - 1);
    lists.insert(lists.end(), prims.begin(), prims.end());
    listFirst.push_back(uint32_t(lists.size()));
    return {root, list};
}

size_t RestrictedTreePool::bytes() const {
    return trees.nodes.capacity() * sizeof(CsgNode) +
           (listFirst.capacity() + 2 * lists.capacity()) * sizeof(uint32_t) +
           index_.size() * kEntryBytes + index_.bucket_count() * sizeof(void*);
}

}  // namespace lancer
