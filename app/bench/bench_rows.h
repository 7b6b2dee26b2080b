// The rows of `lancer bench`: one configuration (or peer, or progressive pass) of one scene, with
// a figure per repeat, from which the CSV, the markdown table, the plots and the page are made.
#pragma once

#include <string>
#include <vector>

#include "app/bench/image_error.h"
#include "engine/accel/accelerator.h"
#include "engine/accel/trace_context.h"

namespace lancer::bench {

/// The median of a set of repeats and its spread.
struct Spread {
    double median = 0.0, min = 0.0, max = 0.0;
    int count = 0;
};
/// The median (the mean of the middle two for an even count), minimum and maximum of `v`.
Spread spreadOf(std::vector<double> v);

struct BenchRow {
    std::string scene, scheme, knob, value;
    AccelInfo info;        ///< of the first repeat (memory and regions are the same each time)
    RayCounters counters;  ///< of the first repeat (the counters are the same each time)
    std::vector<double> buildMs, renderMs;  ///< one a repeat, in the order run
    std::vector<double> speedup;            ///< a repeat's brute-force time over its own
    std::vector<double> wallMs;  ///< a peer run as a process: its wall time, start to end
    bool compared = false;       ///< `error` measured against the brute-force image of the run
    ImageError error;
    bool colorCompared = true;  ///< `error`'s colour figures hold (not for POV-Ray's shading)
    double rmse = -1.0;         ///< progressive passes: colour RMSE against the final image (0..1)
    /// Why the row has no figures ("not installed", "not a union of primitives"); empty when
    /// it was measured.
    std::string note;
    /// What the error columns hold when they are not the usual ones (a peer's silhouette).
    std::string errorNote;
    /// The model's stated distance from the exact surface (`--stats` model_error) where a row
    /// reads the scene its own way (the twist parts axis); negative: the scene's own.
    double modelError = -1.0;
    bool inTable = false;  ///< a row of the comparison table (schemes.md)
    bool peer = false;     ///< another renderer (Embree, POV-Ray): no regions, tests or visits

    bool measured() const { return note.empty() && !renderMs.empty(); }
    /// The scheme as the table names it: "regular", "embree (bounces 0)".
    std::string tableName() const;
    /// "regular max-level 6", "irregular (defaults)", "push delta 1e-12": the configuration.
    std::string label() const;
    /// The CSV's note: why there are no figures, or what the error columns hold and a peer
    /// process's wall time.
    std::string csvNote() const;
};

/// `v` with up to 6 significant digits; "inf" for infinity.
std::string num(double v);
/// `v` with `digits` decimals.
std::string fixed(double v, int digits);

/// The comparison table's columns, and a row's cells (figures as medians, with the range of
/// the repeats in brackets): the markdown of schemes.md and the page's table alike.
std::vector<std::string> comparisonHeader();
std::vector<std::string> comparisonCells(const BenchRow& row);
/// The rows of `rows` in the comparison table, as a markdown table (what README includes).
template <class Rows>
std::string comparisonMarkdown(const Rows& rows) {
    std::string out = "|";
    std::string rule = "|";
    const std::vector<std::string> head = comparisonHeader();
    for (size_t i = 0; i < head.size(); ++i) {
        out += " " + head[i] + " |";
        rule += i < 2 ? "---|" : "---:|";
    }
    out += "\n" + rule + "\n";
    for (const BenchRow& r : rows) {
        if (!r.inTable) continue;
        out += "|";
        for (const std::string& c : comparisonCells(r)) out += " " + c + " |";
        out += "\n";
    }
    return out;
}

}  // namespace lancer::bench
