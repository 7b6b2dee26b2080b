// Whether two batches' segments cover the same points in the same colours, checked apart from
// gl::mergeCollinearLines' sweep: on each axis-parallel line, every endpoint of either batch
// and every point between two consecutive endpoints is covered by both batches or by neither.
// Segments along no axis (or of two colours) must appear in both, unchanged and in order.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <set>
#include <sstream>
#include <tuple>
#include <vector>

#include "app/viewer/gl/batch.h"

namespace lancer::viewer::testing {

/// A line along axis `axis` through the other two coordinates, in one colour.
using LineKey = std::tuple<int, float, float, gl::Rgba8>;
using Interval = std::pair<float, float>;

struct LineCover {
    std::map<LineKey, std::vector<Interval>> lines;
    std::vector<std::pair<gl::BatchVertex, gl::BatchVertex>> others;  ///< in batch order
};

inline LineCover lineCover(const gl::Batch& b) {
    LineCover c;
    for (size_t k = 0; k < b.lineCount(); ++k) {
        const gl::BatchVertex &p = b.lines[2 * k], &q = b.lines[2 * k + 1];
        std::vector<int> along;
        for (int a = 0; a < 3; ++a)
            if (p.position[a] != q.position[a]) along.push_back(a);
        if (along.size() != 1 || p.color != q.color) {
            c.others.push_back({p, q});
            continue;
        }
        const int a = along[0];
        const int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
        c.lines[{a, p.position[u], p.position[v], p.color}].push_back(
            {std::min(p.position[a], q.position[a]), std::max(p.position[a], q.position[a])});
    }
    return c;
}

inline bool covered(const std::vector<Interval>& ivs, double t) {
    for (const auto& [lo, hi] : ivs)
        if (lo <= t && t <= hi) return true;
    return false;
}

/// The same points of the same colours; `merged` holds no two segments of one line that
/// overlap or touch when `maximal`.
inline ::testing::AssertionResult sameLineCover(const gl::Batch& original, const gl::Batch& merged,
                                                bool maximal = true) {
    const LineCover a = lineCover(original), b = lineCover(merged);
    std::set<LineKey> keys;
    for (const auto& kv : a.lines) keys.insert(kv.first);
    for (const auto& kv : b.lines) keys.insert(kv.first);
    for (const LineKey& key : keys) {
        static const std::vector<Interval> none;
        const auto ia = a.lines.find(key), ib = b.lines.find(key);
        const std::vector<Interval>& x = ia == a.lines.end() ? none : ia->second;
        const std::vector<Interval>& y = ib == b.lines.end() ? none : ib->second;
        std::vector<double> ends;
        for (const auto* set : {&x, &y})
            for (const auto& [lo, hi] : *set) ends.insert(ends.end(), {lo, hi});
        std::sort(ends.begin(), ends.end());
        ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
        std::vector<double> probes = ends;
        for (size_t i = 0; i + 1 < ends.size(); ++i)
            probes.push_back(0.5 * (ends[i] + ends[i + 1]));
        for (double t : probes)
            if (covered(x, t) != covered(y, t)) {
                std::ostringstream m;
                m << "axis " << std::get<0>(key) << " line (" << std::get<1>(key) << ", "
                  << std::get<2>(key) << ") colour " << std::hex << std::get<3>(key) << std::dec
                  << ": point " << t << " covered " << (covered(x, t) ? "before" : "after")
                  << " only";
                return ::testing::AssertionFailure() << m.str();
            }
        if (maximal) {
            std::vector<Interval> s = y;
            std::sort(s.begin(), s.end());
            for (size_t i = 0; i + 1 < s.size(); ++i)
                if (s[i + 1].first <= s[i].second)
                    return ::testing::AssertionFailure()
                           << "two merged segments of one line overlap or touch at "
                           << s[i + 1].first;
        }
    }
    auto same = [](const auto& p, const auto& q) {
        return p.first.position == q.first.position && p.first.color == q.first.color &&
               p.second.position == q.second.position && p.second.color == q.second.color;
    };
    if (!std::equal(a.others.begin(), a.others.end(), b.others.begin(), b.others.end(), same))
        return ::testing::AssertionFailure()
               << "segments along no axis changed (" << a.others.size() << " before, "
               << b.others.size() << " after)";
    if (original.triangles.size() != merged.triangles.size())
        return ::testing::AssertionFailure() << "the triangles changed";
    return ::testing::AssertionSuccess();
}

/// Layers drawn over one another without overlap (gl::subtractCovered): every point of an axis
/// line that some layer covers is drawn, in the colour of the first layer of `layers` (the
/// highest precedence) that covers it, and in no other colour; no other point is drawn. Lines
/// are told apart by position only; each layer's segments must lie along an axis.
inline ::testing::AssertionResult drawnByPrecedence(const std::vector<gl::Batch>& layers,
                                                    const gl::Batch& drawn) {
    using Line = std::tuple<int, float, float>;
    auto byLine = [](const LineCover& c, auto&& add) {
        for (const auto& [key, ivs] : c.lines)
            add(Line{std::get<0>(key), std::get<1>(key), std::get<2>(key)}, std::get<3>(key), ivs);
    };
    // Per line: each layer's intervals with its rank and colour; the drawing's by colour.
    std::map<Line, std::vector<std::tuple<size_t, gl::Rgba8, Interval>>> ranked;
    std::map<Line, std::map<gl::Rgba8, std::vector<Interval>>> drawnCover;
    for (size_t l = 0; l < layers.size(); ++l) {
        const LineCover c = lineCover(layers[l]);
        if (!c.others.empty())
            return ::testing::AssertionFailure() << "layer " << l << ": a segment along no axis";
        byLine(c, [&](const Line& line, gl::Rgba8 col, const std::vector<Interval>& ivs) {
            for (const Interval& iv : ivs) ranked[line].push_back({l, col, iv});
        });
    }
    const LineCover d = lineCover(drawn);
    if (!d.others.empty()) return ::testing::AssertionFailure() << "a drawn segment along no axis";
    byLine(d, [&](const Line& line, gl::Rgba8 col, const std::vector<Interval>& ivs) {
        auto& v = drawnCover[line][col];
        v.insert(v.end(), ivs.begin(), ivs.end());
    });
    std::set<Line> lines;
    for (const auto& kv : ranked) lines.insert(kv.first);
    for (const auto& kv : drawnCover) lines.insert(kv.first);
    for (const Line& line : lines) {
        std::vector<double> ends;
        for (const auto& [rank, col, iv] : ranked[line])
            ends.insert(ends.end(), {iv.first, iv.second});
        for (const auto& [col, ivs] : drawnCover[line])
            for (const auto& [lo, hi] : ivs) ends.insert(ends.end(), {lo, hi});
        std::sort(ends.begin(), ends.end());
        ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
        // Midpoints only: at an end two layers may meet, either colour is right there.
        for (size_t i = 0; i + 1 < ends.size(); ++i) {
            const double t = 0.5 * (ends[i] + ends[i + 1]);
            size_t best = SIZE_MAX;
            for (const auto& [rank, col, iv] : ranked[line])
                if (iv.first <= t && t <= iv.second) best = std::min(best, rank);
            // The colours of the first layer covering t (neighbouring boxes of one layer may
            // draw one edge in two colours).
            std::set<gl::Rgba8> want;
            for (const auto& [rank, col, iv] : ranked[line])
                if (rank == best && iv.first <= t && t <= iv.second) want.insert(col);
            for (const auto& [col, ivs] : drawnCover[line]) {
                const bool on = covered(ivs, t);
                if (on != (want.count(col) > 0))
                    return ::testing::AssertionFailure()
                           << "axis " << std::get<0>(line) << " line (" << std::get<1>(line) << ", "
                           << std::get<2>(line) << ") point " << t << ": colour " << std::hex << col
                           << std::dec << (on ? " drawn" : " missing");
            }
            for (gl::Rgba8 col : want)
                if (!drawnCover[line].count(col))
                    return ::testing::AssertionFailure()
                           << "a point of a layer is not drawn at " << t;
        }
    }
    return ::testing::AssertionSuccess();
}

}  // namespace lancer::viewer::testing
