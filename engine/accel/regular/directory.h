// The regular scheme's directory (report, section 3, Fig. 7): the table that maps a cell of the
// finest grid to the number of the BSP leaf holding it, stored either as one full table or as
// Tamminen's sub-tables, where a block of the table that lies inside one leaf is one entry.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace lancer {

class BuildGuard;

/// The axis the regular BSP cuts at each level. Every node of a level is cut on the same axis,
/// at its middle, so the cells of a level are all alike, and a cell's level fixes how many times
/// each axis was cut: the directory's resolution per axis follows from the finest level. The
/// report cuts x, y, z in turn; other orders keep every property of the scheme.
class AxisSchedule {
  public:
    static constexpr int kLevels = 64;
    /// The report's order: x, y, z in turn (level 0 cuts x).
    AxisSchedule();
    /// Level l cuts axes[l] (0 x, 1 y, 2 z); levels beyond the list cut axis l % 3.
    explicit AxisSchedule(const std::vector<int>& axes);

    /// Axis the cut of a node at `level` runs across.
    int axis(int level) const { return axis_[level]; }
    /// Cuts on `axis` made by levels [0, level): a node at `level` is 1 / 2^cuts of the box.
    int cuts(int level, int axis) const { return cuts_[level][axis]; }
    /// The first `levels` axes as letters, e.g. "xyxyxyxyzxyz".
    std::string toString(int levels) const;

  private:
    uint8_t axis_[kLevels] = {};
    uint8_t cuts_[kLevels + 1][3] = {};
};

/// The BSP the directory is built from: nodes in a flat array; an inner node's children are
/// `first` and `first + 1` (low and high half), a leaf has first == -1 and its number in `leaf`.
struct BspNodes {
    struct Node {
        int32_t first = -1;
        uint32_t leaf = 0;
        uint8_t height = 0;  ///< levels below this node (0 for a leaf)
    };
    std::vector<Node> nodes;  ///< nodes[0] is the root, at level 0
};

/// The directory: full table or sub-tables, one lookup path for both.
class Directory {
  public:
    /// Levels a sub-table covers at most (6: 4x4x4 entries, 256 bytes). Fewer levels mean more
    /// hops per lookup, more mean larger tables for partly uniform blocks. Directory bytes
    /// measured on balls4 / drilled:20 at the defaults: 3 levels 149 / 442 KB, 6 levels
    /// 194 / 585 KB, 9 levels 226 / 813 KB; render times differed within noise.
    static constexpr int kSubTableLevels = 6;
    /// Levels the top table covers at most in sub-table mode (12: 16x16x16 entries, 16 KiB).
    static constexpr int kTopLevels = 12;

    Directory() = default;

    /// Bytes the table built by `build` would take, computed without allocating it.
    static size_t estimateBytes(const BspNodes& bsp, int finestLevel, bool full);
    /// Fill the directory of a BSP cut by `schedule` whose deepest leaf is at `finestLevel`,
    /// polling `guard` (when given) for a cancellation as it goes.
    void build(const BspNodes& bsp, const AxisSchedule& schedule, int finestLevel, bool full,
               const BuildGuard* guard = nullptr);

    /// Leaf number of the finest cell (i, j, k), each index in [0, 2^n) of its axis.
    uint32_t lookup(uint32_t i, uint32_t j, uint32_t k) const {
        const Table* t = &tables_[0];
        for (;;) {
            uint32_t e = entries_[t->offset + (((i >> t->shift[0]) & t->mask[0]) << t->lowBits) +
                                  (((j >> t->shift[1]) & t->mask[1]) << t->bits[2]) +
                                  ((k >> t->shift[2]) & t->mask[2])];
            if (!(e & kSubTable)) return e;
            t = &tables_[e & ~kSubTable];
        }
    }

    /// The sub-tables a lookup of cell (i, j, k) passes through, in order (empty: an entry of
    /// the top table names the leaf), as lookup() follows them.
    std::vector<uint32_t> subTablesOf(uint32_t i, uint32_t j, uint32_t k) const {
        std::vector<uint32_t> path;
        const Table* t = &tables_[0];
        for (;;) {
            uint32_t e = entries_[t->offset + (((i >> t->shift[0]) & t->mask[0]) << t->lowBits) +
                                  (((j >> t->shift[1]) & t->mask[1]) << t->bits[2]) +
                                  ((k >> t->shift[2]) & t->mask[2])];
            if (!(e & kSubTable)) return path;
            path.push_back(e & ~kSubTable);
            t = &tables_[e & ~kSubTable];
        }
    }

    size_t memoryBytes() const {
        return entries_.size() * sizeof(uint32_t) + tables_.size() * sizeof(Table);
    }
    size_t tableCount() const { return tables_.size(); }
    /// Visit every entry of every table, depth first from the top table: f(lo, hi, subTable,
    /// value, table, depth) with [lo, hi) the entry's block of finest cells per axis, value the
    /// leaf (subTable false) or the sub-table the block is stored in, `table` the table holding
    /// the entry and `depth` that table's depth (0: the top table).
    template <class F>
    void forEachEntry(F&& f) const {
        if (!tables_.empty()) visitTable(0, 0, 0, 0, 0, f);
    }
    size_t entryCount() const { return entries_.size(); }
    /// Entries of table `t` (a block of 2^bits cells per axis of the table's own level).
    size_t tableSize(uint32_t t) const {
        const Table& T = tables_[t];
        return size_t(T.mask[0] + 1) * (T.mask[1] + 1) * (T.mask[2] + 1);
    }
    /// Entry `i` of table `t` (forEachEntry's order inside the table) whose block starts at
    /// finest cell `origin`: its block [lo, hi) of finest cells, whether it names a sub-table,
    /// and the leaf or sub-table it names.
    void tableEntry(uint32_t t, const uint32_t origin[3], size_t i, uint32_t lo[3], uint32_t hi[3],
                    bool& subTable, uint32_t& value) const {
        const Table& T = tables_[t];
        const uint32_t idx[3] = {uint32_t(i >> T.lowBits), uint32_t(i >> T.bits[2]) & T.mask[1],
                                 uint32_t(i) & T.mask[2]};
        for (int k = 0; k < 3; ++k) {
            lo[k] = origin[k] + (idx[k] << T.shift[k]);
            hi[k] = lo[k] + (1u << T.shift[k]);
        }
        const uint32_t e = entries_[T.offset + i];
        subTable = (e & kSubTable) != 0;
        value = subTable ? e & ~kSubTable : e;
    }
    /// The entry of table `t` (block at `origin`) holding finest cell `cell`.
    size_t tableEntryAt(uint32_t t, const uint32_t origin[3], const uint32_t cell[3]) const {
        const Table& T = tables_[t];
        const uint32_t a = (cell[0] - origin[0]) >> T.shift[0],
                       b = (cell[1] - origin[1]) >> T.shift[1],
                       c = (cell[2] - origin[2]) >> T.shift[2];
        return (size_t(a) << T.lowBits) + (size_t(b) << T.bits[2]) + c;
    }

  private:
    /// Tag of an entry that names a sub-table rather than a leaf.
    static constexpr uint32_t kSubTable = 0x80000000u;

    /// One table: a block of the grid at BSP level `level`, subdivided `levels` more levels.
    /// 24 bytes, the masks stored rather than computed on each lookup.
    struct Table {
        uint32_t offset = 0;    ///< first entry in entries_
        uint8_t shift[3] = {};  ///< finest index >> shift = index at the table's finest level
        uint8_t bits[3] = {};   ///< entries per axis = 2^bits
        uint8_t lowBits = 0;    ///< bits[1] + bits[2]
        /// Low bits of an index at the table's finest level, 2^bits - 1: the position inside
        /// the block.
        uint32_t mask[3] = {};
    };

    template <class F>
    void visitTable(uint32_t t, uint32_t x, uint32_t y, uint32_t z, int depth, F& f) const {
        const Table T = tables_[t];
        const uint32_t lo0[3] = {x, y, z};
        for (uint32_t a = 0; a <= T.mask[0]; ++a)
            for (uint32_t b = 0; b <= T.mask[1]; ++b)
                for (uint32_t c = 0; c <= T.mask[2]; ++c) {
                    const uint32_t e = entries_[T.offset + (a << T.lowBits) + (b << T.bits[2]) + c];
                    const uint32_t idx[3] = {a, b, c};
                    uint32_t lo[3], hi[3];
                    for (int k = 0; k < 3; ++k) {
                        lo[k] = lo0[k] + (idx[k] << T.shift[k]);
                        hi[k] = lo[k] + (1u << T.shift[k]);
                    }
                    const bool sub = (e & kSubTable) != 0;
                    f(lo, hi, sub, sub ? e & ~kSubTable : e, t, depth);
                    if (sub) visitTable(e & ~kSubTable, lo[0], lo[1], lo[2], depth + 1, f);
                }
    }
    /// Levels a table rooted at a node of `height` at `level` covers.
    static int tableLevels(int level, int height, int finestLevel, bool full);
    uint32_t addTable(const BspNodes& bsp, int node, int level, int finestLevel, bool full);
    void fill(const BspNodes& bsp, uint32_t table, int tableLevel, int levels, int node, int level,
              const uint32_t pos[3], int finestLevel, bool full);

    /// Polls guard_ once in kPollEntries entries written (a leaf's block counts its entries).
    void written(size_t entries);
    static constexpr size_t kPollEntries = size_t(1) << 16;

    std::vector<uint32_t> entries_;
    std::vector<Table> tables_;
    AxisSchedule schedule_;              ///< of the BSP being filled
    const BuildGuard* guard_ = nullptr;  ///< while build() runs
    size_t unpolled_ = 0;                ///< entries written since guard_ was last polled
};

}  // namespace lancer
