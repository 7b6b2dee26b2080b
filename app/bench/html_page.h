// `lancer bench --report DIR`: DIR/index.html, one page that needs no other file (the plots are
// inline SVG): the run (machine, commit, date, command), the comparison table, the plots and
// every row of report.csv.
#pragma once

#include <deque>
#include <string>
#include <vector>

#include "app/bench/bench_rows.h"
#include "app/bench/machine.h"
#include "app/bench/plots.h"

namespace lancer::bench {

struct PageSettings {
    int width = 0, height = 0, threads = 0, bounces = 0, repeats = 1;
    bool quick = false, schemesOnly = false;
    double seconds = 0.0;  ///< the run's wall time
    /// The peers of the run, each "name: what was found" ("POV-Ray: not installed").
    std::vector<std::string> peers;
};

/// Write the page to `path` (atomically). False when it cannot be written.
bool writeHtmlPage(const std::string& path, const RunInfo& run, const PageSettings& settings,
                   const std::deque<BenchRow>& rows, const std::vector<Figure>& figures);

/// An SVG file's text made fit to sit inline in a page beside others: the XML prolog dropped,
/// its ids (and the references to them) prefixed with `prefix`, its title `title`.
std::string inlineSvg(const std::string& svg, const std::string& prefix, const std::string& title);

/// `s` with &, <, > and " escaped.
std::string htmlEscape(const std::string& s);

}  // namespace lancer::bench
