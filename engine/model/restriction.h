// The report's restriction of a CSG tree to a set of primitives (section 2), and the pool of
// restricted trees both subdivision schemes share between regions holding the same primitives.
// Two ways to restrict, with the same rules and the same nodes: restrictTree walks the whole
// tree (no set-up: for small trees, as the regular builder restricts each cell's tree for its
// children), TreeRestrictor walks only the ancestors of the kept primitives (for thousands of
// small sets over one large tree, where a walk of the whole tree per set is quadratic).
#pragma once

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

#include "engine/model/csg.h"

namespace lancer {

/// The restriction of `src` (from node `node`) to the primitives for which keep[p] is true,
/// appended to `dst`. Returns the new root in dst, or -1 for the empty tree.
int restrictTree(const CsgTree& src, int node, const std::vector<char>& keep, CsgTree& dst);

/// restrictTree of `src`'s root to the list `prims`; `marks` (one per primitive) is all 0 before
/// and after, set for `prims` meanwhile.
int restrictTreeTo(const CsgTree& src, const std::vector<uint32_t>& prims, std::vector<char>& marks,
                   CsgTree& dst);

/// Within a region that each primitive of `held` (sorted) fills (a convex solid holding the
/// whole region), the primitives of `tree` whose restriction (the rules above) equals `tree`
/// there, into `out` (sorted): by the rules union(full, x) = full, intersection(full, x) = x and
/// x - full = empty, a cell inside a subtrahend keeps nothing of the difference, and a tree that
/// is empty or full over the whole region keeps nothing at all (it has no boundary there).
/// False when the tree is left as it is: nothing held, a primitive with several leaves (one
/// rule could keep it and another drop it), or children stored after their parents.
bool restrictionWithin(const CsgTree& tree, std::span<const uint32_t> held,
                       std::vector<uint32_t>& out);

/// The restriction of one tree to many sets, visiting only the ancestors of each set's leaves.
class TreeRestrictor {
  public:
    explicit TreeRestrictor(const CsgTree& tree);
    /// Same result as restrictTree(tree, tree.root, keep, dst) with keep = `prims`.
    int restrict(const std::vector<uint32_t>& prims, CsgTree& dst) {
        if (live_.size() != parent_.size()) live_.assign(parent_.size(), 0);  // on first use
        return restrict(prims, dst, live_);
    }
    /// The same with the caller's marks (one per node of the tree, all 0 before and after):
    /// threads restricting at once each bring their own.
    int restrict(const std::vector<uint32_t>& prims, CsgTree& dst, std::vector<char>& live) const;
    /// The same nodes written to out[0..) instead of appended, numbered from `base` (as if
    /// appended to a tree of `base` nodes); returns the root. `out` has room for them: for a
    /// tree of unions, unionSize(prims).
    int restrict(std::span<const uint32_t> prims, CsgNode* out, int base,
                 std::vector<char>& live) const;
    /// Nodes of the restriction to `prims` when the tree has only unions: each kept leaf and
    /// each union over two kept subtrees, 2 m - 1 for the m leaves of `prims` (0 for none).
    /// Known before restricting, so restrictions can be written in parallel into one array.
    size_t unionSize(std::span<const uint32_t> prims) const {
        size_t m = 0;
        for (uint32_t p : prims)
            if (size_t(p) + 1 < leafFirst_.size()) m += leafFirst_[size_t(p) + 1] - leafFirst_[p];
        return m ? 2 * m - 1 : 0;
    }
    /// Nodes of the tree: the size of the marks.
    size_t nodeCount() const { return parent_.size(); }
    /// The tree has only unions (and primitives): restrictUnions() applies.
    bool unionOnly() const { return unionOnly_; }
    /// For a tree of unions only, the same nodes as restrict(prims, out, base, live), from the
    /// kept leaves alone: the restriction of a union keeps each kept leaf and each union whose
    /// two sides keep one, which is where two leaves next in depth-first order meet. No marks
    /// to set and clear, no walk down from the root (on a balanced union of 600,000 primitives
    /// each set of a few leaves climbed 20 levels three times). `scratch`: the caller's, reused.
    int restrictUnions(std::span<const uint32_t> prims, CsgNode* out, int base,
                       std::vector<int>& scratch) const;

  private:
    void mark(std::span<const uint32_t> prims, char value, std::vector<char>& live) const;

    const CsgTree* tree_;
    std::vector<int> parent_;
    bool unionOnly_ = false;
    /// A node's place in a depth-first walk from the root (left side first), -1 where the
    /// root does not reach it; its subtree takes places pre .. last - 1. With its parent:
    /// restrictUnions() climbs from node to parent reading both.
    struct Place {
        int pre = -1, last = -1, parent = -1;
    };
    std::vector<Place> places_;  ///< per node, with unionOnly_ (together: one cache line)
    /// Leaves of primitive p: leafNodes_[leafFirst_[p] .. leafFirst_[p + 1]) (one array rather
    /// than a list per primitive: 600,000 small allocations on the largest scenes).
    std::vector<uint32_t> leafFirst_;
    std::vector<int> leafNodes_;
    std::vector<char> live_;  ///< node is an ancestor of a kept primitive
};

/// Restricted trees keyed by sorted primitive set: each distinct set's tree (in `trees`) and
/// primitive list (in `lists`) are stored once, and regions with equal sets share them. List 0
/// is the empty set, with the empty tree.
class RestrictedTreePool {
  public:
    /// A set's tree and list.
    struct Entry {
        int root = -1;      ///< in trees; -1 for the empty tree
        uint32_t list = 0;  ///< lists[listFirst[list] .. listFirst[list + 1])
    };

    RestrictedTreePool();

    /// The entry of `prims` (sorted, distinct). A set not seen before gets the tree
    /// restrict(dst), which appends the restriction to `prims` to dst (= trees) and returns its
    /// root; lists and trees then grow in the order sets first arrive.
    template <class Restrict>
    Entry share(const std::vector<uint32_t>& prims, Restrict&& restrict) {
        auto it = index_.find(prims);
        if (it == index_.end()) it = index_.emplace(prims, add(prims, restrict(trees))).first;
        return it->second;
    }

    /// Bytes of one index entry beside its key's elements (see bytes()).
    static constexpr size_t kEntryBytes = 112;

    /// Distinct sets, the empty one included.
    size_t size() const { return index_.size(); }
    /// Heap bytes held: vectors by capacity; the index keeps each set again, in a node (64 bytes
    /// with malloc's rounding), a key allocation (32 at least) and a bucket.
    size_t bytes() const;

    CsgTree trees;                    ///< every set's restricted tree
    std::vector<uint32_t> listFirst;  ///< list l: lists[listFirst[l] .. [l + 1])
    std::vector<uint32_t> lists;      ///< every set's primitives, set after set

  private:
    struct Hash {
        size_t operator()(const std::vector<uint32_t>& v) const;
    };
    Entry add(const std::vector<uint32_t>& prims, int root);

    /// Only looked up, never iterated: the hash values cannot change what is built.
    std::unordered_map<std::vector<uint32_t>, Entry, Hash> index_;
};

}  // namespace lancer
