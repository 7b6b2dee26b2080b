// The regular builder's primitive lists and its pool of the leaves' distinct primitive sets, each
// with its restricted tree (docs/regular.md, "Build" and "Huge pages and one set index").
#pragma once

#include <algorithm>
#include <cstdint>
#include <memory>
#include <new>
#include <span>
#include <utility>
#include <vector>

#include "engine/model/restriction.h"
#include "engine/util/hash.h"

namespace lancer {

// The regular builder's own types and helpers, shared by its files (regular_builder.h): in a
// named namespace, since RegularBuilder, a friend of RegularGrid, holds them (a unity build would
// warn of a field of an internal type).
namespace regular_build {

/// An allocator whose resize() leaves the new elements uninitialised: a cell's pass sizes its
/// children's lists to hold every primitive and then writes them (zeroing them first took a
/// twentieth of the build's time on balls:6).
template <class T>
struct NoInit : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = NoInit<U>;
    };
    NoInit() = default;
    template <class U>
    NoInit(const NoInit<U>&) {}
    template <class U>
    void construct(U* p) {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... A>
    void construct(U* p, A&&... a) {
        ::new (static_cast<void*>(p)) U(std::forward<A>(a)...);
    }
};
/// The builder's lists of primitives.
using PrimList = std::vector<uint32_t, NoInit<uint32_t>>;

/// The leaves' distinct primitive sets, each with its restricted tree: RestrictedTreePool's
/// sets and numbering (list 0 the empty set, the others in the order they first arrive), looked
/// up by an open-addressing index of list numbers into `lists` itself. The pool's index keeps
/// each set again in a node of its own (two allocations a set, freed one by one): on balls:6,
/// 65,000 sets in the fragments and again in the layout.
class SetPool {
  public:
    SetPool() : listFirst{0, 0}, roots{-1}, hashes{hashOf({})} { grow(); }

    /// The entry of `prims` (sorted, distinct), whose hash is hashOf(prims). A set not seen
    /// before gets the tree restrict(trees), which appends the restriction to `prims` to trees
    /// and returns its root.
    template <class Restrict>
    RestrictedTreePool::Entry share(std::span<const uint32_t> prims, uint32_t hash,
                                    Restrict&& restrict) {
        const uint32_t mask = uint32_t(slots_.size() - 1);
        for (uint32_t i = hash & mask;; i = (i + 1) & mask) {
            const uint32_t l = slots_[i];
            if (l == kEmpty) {
                const uint32_t list = uint32_t(roots.size());
                roots.push_back(restrict(trees));  // before the list: restrict may read prims
                lists.insert(lists.end(), prims.begin(), prims.end());
                listFirst.push_back(uint32_t(lists.size()));
                hashes.push_back(hash);
                slots_[i] = list;
                if (2 * roots.size() > slots_.size()) grow();
                return {roots[list], list};
            }
            if (hashes[l] == hash && listFirst[l + 1] - listFirst[l] == prims.size() &&
                std::equal(prims.begin(), prims.end(), lists.begin() + listFirst[l]))
                return {roots[l], l};
        }
    }
    /// The hash share() takes.
    static uint32_t hashOf(std::span<const uint32_t> prims) {
        const uint64_t h = hashWords(prims);
        return uint32_t(h ^ (h >> 32));
    }
    /// Set `list`'s primitives.
    std::span<const uint32_t> set(uint32_t list) const {
        return {lists.data() + listFirst[list], listFirst[list + 1] - listFirst[list]};
    }
    /// Distinct sets, the empty one included.
    size_t size() const { return roots.size(); }
    /// Heap bytes held, vectors by capacity, with each set charged as RestrictedTreePool
    /// charges it (its index's node and key, RestrictedTreePool::kEntryBytes, and the key's
    /// elements again): more than this pool holds, but the budget's refusals stay where they
    /// were (--memory-budget's tests refuse the sponge at 256 KiB).
    size_t bytes() const {
        return trees.nodes.capacity() * sizeof(CsgNode) +
               (listFirst.capacity() + 2 * lists.capacity() + roots.capacity() + hashes.capacity() +
                slots_.capacity()) *
                   sizeof(uint32_t) +
               roots.size() * RestrictedTreePool::kEntryBytes;
    }

    CsgTree trees;                    ///< every set's restricted tree
    std::vector<uint32_t> listFirst;  ///< list l: lists[listFirst[l] .. [l + 1])
    std::vector<uint32_t> lists;      ///< every set's primitives, set after set
    std::vector<int> roots;           ///< set l's tree's root in trees; -1: empty
    std::vector<uint32_t> hashes;     ///< set l's hashOf()

  private:
    static constexpr uint32_t kEmpty = 0xffffffffu;
    /// Twice the slots, the sets placed again by their hashes: at most half the slots are used.
    void grow() {
        slots_.assign(std::max<size_t>(16, 2 * slots_.size()), kEmpty);
        const uint32_t mask = uint32_t(slots_.size() - 1);
        for (uint32_t l = 0; l < roots.size(); ++l) {
            uint32_t i = hashes[l] & mask;
            while (slots_[i] != kEmpty) i = (i + 1) & mask;
            slots_[i] = l;
        }
    }
    std::vector<uint32_t> slots_;  ///< a list number or kEmpty
};

}  // namespace regular_build

}  // namespace lancer
