#include "engine/accel/regular/directory.h"

#include <algorithm>
#include <stdexcept>

#include "engine/accel/build_guard.h"

namespace lancer {

AxisSchedule::AxisSchedule() : AxisSchedule(std::vector<int>{}) {}

AxisSchedule::AxisSchedule(const std::vector<int>& axes) {
    for (int l = 0; l < kLevels; ++l) {
        const int a = l < int(axes.size()) ? axes[size_t(l)] : l % 3;
        if (a < 0 || a > 2) throw std::invalid_argument("AxisSchedule: axis must be 0, 1 or 2");
        axis_[l] = uint8_t(a);
        for (int b = 0; b < 3; ++b) cuts_[l + 1][b] = uint8_t(cuts_[l][b] + (b == a));
    }
}

std::string AxisSchedule::toString(int levels) const {
    std::string out;
    for (int l = 0; l < std::min(levels, kLevels); ++l) out += "xyz"[axis_[l]];
    return out;
}

int Directory::tableLevels(int level, int height, int finestLevel, bool full) {
    if (full) return finestLevel - level;
    return std::min(height, level == 0 ? kTopLevels : kSubTableLevels);
}

size_t Directory::estimateBytes(const BspNodes& bsp, int finestLevel, bool full) {
    // Walk the same recursion as build(), counting entries instead of writing them.
    size_t entries = 0, tables = 0;
    struct Counter {
        const BspNodes& bsp;
        int finest;
        bool full;
        size_t& entries;
        size_t& tables;
        void table(int node, int level) {
            int m = tableLevels(level, bsp.nodes[size_t(node)].height, finest, full);
            ++tables;
            entries += size_t(1) << m;
            below(node, level, level + m);
        }
        void below(int node, int level, int stop) {
            const BspNodes::Node& n = bsp.nodes[size_t(node)];
            if (n.first < 0) return;
            if (level == stop) return table(node, level);
            below(n.first, level + 1, stop);
            below(n.first + 1, level + 1, stop);
        }
    } c{bsp, finestLevel, full, entries, tables};
    if (full && finestLevel >= 62) return SIZE_MAX;
    if (full) return (size_t(1) << finestLevel) * sizeof(uint32_t) + sizeof(Table);
    c.table(0, 0);
    return entries * sizeof(uint32_t) + tables * sizeof(Table);
}

void Directory::build(const BspNodes& bsp, const AxisSchedule& schedule, int finestLevel, bool full,
                      const BuildGuard* guard) {
    schedule_ = schedule;
    entries_.clear();
    tables_.clear();
    guard_ = guard;
    unpolled_ = 0;
    struct Unset {
        const BuildGuard*& g;
        ~Unset() { g = nullptr; }
    } unset{guard_};
    addTable(bsp, 0, 0, finestLevel, full);
    entries_.shrink_to_fit();
    tables_.shrink_to_fit();
}

void Directory::written(size_t entries) {
    // Polled by the entries written, not by the leaves: a full table's leaf may own millions.
    unpolled_ += entries;
    if (unpolled_ < kPollEntries) return;
    unpolled_ = 0;
    if (guard_) guard_->poll();
}

uint32_t Directory::addTable(const BspNodes& bsp, int node, int level, int finestLevel, bool full) {
    int m = tableLevels(level, bsp.nodes[size_t(node)].height, finestLevel, full);
    if (tables_.size() >= kSubTable) throw std::length_error("directory: too many sub-tables");
    Table t;
    t.offset = uint32_t(entries_.size());
    for (int a = 0; a < 3; ++a) {
        t.bits[a] = uint8_t(schedule_.cuts(level + m, a) - schedule_.cuts(level, a));
        t.shift[a] = uint8_t(schedule_.cuts(finestLevel, a) - schedule_.cuts(level + m, a));
        t.mask[a] = (1u << t.bits[a]) - 1u;
    }
    t.lowBits = uint8_t(t.bits[1] + t.bits[2]);
    uint32_t id = uint32_t(tables_.size());
    tables_.push_back(t);
    entries_.resize(entries_.size() + (size_t(1) << m), 0);
    const uint32_t origin[3] = {0, 0, 0};
    fill(bsp, id, level, m, node, level, origin, finestLevel, full);
    return id;
}

void Directory::fill(const BspNodes& bsp, uint32_t table, int tableLevel, int levels, int node,
                     int level, const uint32_t pos[3], int finestLevel, bool full) {
    const BspNodes::Node& n = bsp.nodes[size_t(node)];
    int bottom = tableLevel + levels;
    if (n.first < 0 || level == bottom) {
        // A leaf owns every entry of its block; an inner node at the table's bottom level gets
        // one entry naming its own sub-table.
        uint32_t value =
            n.first < 0 ? n.leaf : kSubTable | addTable(bsp, node, level, finestLevel, full);
        const Table t = tables_[table];  // copy: addTable may have grown tables_
        uint32_t lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            int size = schedule_.cuts(bottom, a) - schedule_.cuts(level, a);
            lo[a] = pos[a] << size;
            hi[a] = (pos[a] + 1) << size;
        }
        for (uint32_t x = lo[0]; x < hi[0]; ++x) {
            for (uint32_t y = lo[1]; y < hi[1]; ++y)
                for (uint32_t z = lo[2]; z < hi[2]; ++z)
                    entries_[t.offset + (x << t.lowBits) + (y << t.bits[2]) + z] = value;
            written(size_t(hi[1] - lo[1]) * (hi[2] - lo[2]));
        }
        return;
    }
    const int axis = schedule_.axis(level);  // the cut at level + 1
    for (int side = 0; side < 2; ++side) {
        uint32_t child[3] = {pos[0], pos[1], pos[2]};
        child[axis] = 2 * pos[axis] + uint32_t(side);
        fill(bsp, table, tableLevel, levels, n.first + side, level + 1, child, finestLevel, full);
    }
}

}  // namespace lancer
