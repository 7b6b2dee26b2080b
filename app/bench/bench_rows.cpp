#include "app/bench/bench_rows.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>

#include "engine/scene/builtin_scenes.h"
#include "engine/util/format.h"

namespace lancer::bench {

Spread spreadOf(std::vector<double> v) {
    Spread s;
    s.count = int(v.size());
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    s.min = v.front();
    s.max = v.back();
    return s;
}

std::string num(double v) {
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    std::ostringstream os;
    os.precision(6);
    os << v;
    return os.str();
}

std::string BenchRow::tableName() const {
    const std::string peer = "peer (";
    if (knob.compare(0, peer.size(), peer) == 0) return scheme + " " + knob.substr(5);
    return scheme;
}

std::string BenchRow::csvNote() const {
    if (!measured()) return note;
    std::string out = errorNote;
    if (!wallMs.empty()) {
        if (!out.empty()) out += "; ";
        out += "process wall time " + fixed(spreadOf(wallMs).median, 0) + " ms (median)";
    }
    return out;
}

std::string BenchRow::label() const {
    if (knob == "scheme") return scheme + " (defaults)";
    if (knob.compare(0, 5, "peer ") == 0) return tableName();
    if (knob == "progressive pass") return scheme + " pass stride " + value;
    if (knob.compare(0, 5, "mesh ") == 0) return scheme == "openscad" ? "mesh " + value : scheme;
    // Knobs named after their scheme ("regular max-level") read as they are; the others
    // ("push delta", "offset", "bsp-heuristic") get the scheme in front.
    if (knob.compare(0, scheme.size(), scheme) == 0) return knob + " " + value;
    return scheme + " " + knob + " " + value;
}

}  // namespace lancer::bench

namespace lancer::bench {

namespace {

/// A time in ms: one decimal under 10, none above.
std::string ms(double v) { return fixed(v, std::abs(v) < 10.0 ? 1 : 0); }

/// "61 (58–66)": the median and, when the repeats differ, their range.
std::string withRange(const Spread& s, const std::function<std::string(double)>& f) {
    std::string out = f(s.median);
    const std::string lo = f(s.min), hi = f(s.max);
    if (s.count > 1 && lo != hi) out += " (" + lo + "–" + hi + ")";
    return out;
}

}  // namespace

std::string fixed(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

std::vector<std::string> comparisonHeader() {
    return {"scene",         "scheme", "build ms",       "regions",           "memory",
            "render ms",     "µs/ray", "prim tests/ray", "region visits/ray", "speedup",
            "hits differing"};
}

std::vector<std::string> comparisonCells(const BenchRow& r) {
    std::vector<std::string> c(comparisonHeader().size());
    c[0] = parseBuiltinSpec(r.scene) ? r.scene : std::filesystem::path(r.scene).filename().string();
    c[1] = r.tableName();
    if (!r.measured()) {
        c[2] = r.note;
        return c;
    }
    const double rays = double(r.counters.rays);
    const Spread t = spreadOf(r.renderMs);
    c[2] = withRange(spreadOf(r.buildMs), ms);
    c[5] = withRange(t, ms);
    if (rays > 0) c[6] = fixed(1000.0 * t.median / rays, 2);
    if (!r.peer) {
        c[3] = std::to_string(r.info.regions);
        c[4] = formatBytes(r.info.memoryBytes, ByteUnit::MiB);
        c[7] = fixed(double(r.counters.primTests) / std::max(1.0, rays), 1);
        c[8] = fixed(double(r.counters.regionVisits) / std::max(1.0, rays), 1);
    }
    const Spread s = spreadOf(r.speedup);
    c[9] = s.count ? withRange(s, [](double v) { return fixed(v, 1) + "x"; }) : "-";
    c[10] = r.compared ? std::to_string(r.error.hitDiff) : "-";
    if (r.compared && !r.errorNote.empty()) c[10] += " (depth image)";
    return c;
}

}  // namespace lancer::bench
