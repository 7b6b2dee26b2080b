#include "app/bench/html_page.h"

#include <fstream>
#include <sstream>

#include "engine/render/image.h"
#include "engine/util/format.h"

namespace lancer::bench {

namespace {

void replaceAll(std::string& s, const std::string& from, const std::string& to) {
    for (size_t p = 0; (p = s.find(from, p)) != std::string::npos; p += to.size())
        s.replace(p, from.size(), to);
}

const char* kStyle = R"css(
body { font: 15px/1.45 -apple-system, "Segoe UI", Helvetica, Arial, sans-serif; color: #222;
       margin: 0 auto; padding: 1.5em 2em 4em; max-width: 1180px; }
h1 { font-size: 1.7em; margin: 0 0 .2em; }
h2 { font-size: 1.3em; margin: 2em 0 .5em; border-bottom: 1px solid #ddd; padding-bottom: .2em; }
h3 { font-size: 1.05em; margin: 1.5em 0 .3em; }
p.lead { color: #555; margin-top: 0; }
table { border-collapse: collapse; font-size: 13px; margin: .5em 0 1em; }
th, td { border: 1px solid #d8d8d8; padding: 3px 7px; vertical-align: top; }
th { background: #f3f3f3; text-align: left; }
td.n { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
td.note { color: #8a5a00; font-style: italic; }
table.schemes td:nth-child(-n+2) { white-space: nowrap; }
tr.scene-start td { border-top: 2px solid #999; }
table.run th { width: 11em; }
table.run td { max-width: 60em; }
code, pre { font: 12.5px/1.4 "DejaVu Sans Mono", Menlo, Consolas, monospace; }
pre.cmd { background: #f6f8fa; border: 1px solid #e1e4e8; padding: .5em .8em; white-space: pre-wrap;
          word-break: break-all; margin: 0; }
figure { margin: 1.5em 0 2.5em; }
figure svg { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { color: #444; font-size: 13.5px; max-width: 62em; margin-top: .4em; }
p.missing { background: #fff4e5; border: 1px solid #f0c36d; padding: .5em .8em; }
details summary { cursor: pointer; font-weight: 600; }
table.all { font-size: 12px; }
)css";

std::string cls(const std::string& header) {
    return header == "scene" || header == "scheme" || header == "knob" || header == "value"
               ? ""
               : " class=\"n\"";
}

}  // namespace

std::string htmlEscape(const std::string& s) {
    std::string out;
    out.reserve(s.size());
    for (char c : s) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string inlineSvg(const std::string& svg, const std::string& prefix, const std::string& title) {
    const size_t start = svg.find("<svg");
    std::string s = start == std::string::npos ? svg : svg.substr(start);
    for (const char* q : {"'", "\""}) {
        replaceAll(s, std::string("id=") + q, std::string("id=") + q + prefix);
        replaceAll(s, std::string("href=") + q + "#", std::string("href=") + q + "#" + prefix);
    }
    replaceAll(s, "url(#", "url(#" + prefix);
    replaceAll(s, "<title>Gnuplot</title>", "<title>" + htmlEscape(title) + "</title>");
    return s;
}

bool writeHtmlPage(const std::string& path, const RunInfo& run, const PageSettings& st,
                   const std::deque<BenchRow>& rows, const std::vector<Figure>& figures) {
    const std::string dir = path.substr(0, path.find_last_of('/') + 1);
    std::ostringstream h;
    h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
      << "<title>Lancer: speed against error</title>\n<style>" << kStyle << "</style>\n"
      << "</head>\n<body>\n<h1>Lancer: speed against error</h1>\n"
      << "<p class=\"lead\">Every configuration rendered and compared with the brute-force image "
         "of the same run (<a href=\"report.csv\">report.csv</a> beside this page holds every "
         "figure).</p>\n";

    // The run.
    auto item = [&](const std::string& k, const std::string& v, bool code = false) {
        h << "<tr><th>" << htmlEscape(k) << "</th><td>"
          << (code ? "<pre class=\"cmd\">" + htmlEscape(v) + "</pre>" : htmlEscape(v))
          << "</td></tr>\n";
    };
    h << "<table class=\"run\" id=\"run\">\n";
    item("Date", run.date);
    item("Commit", run.commit);
    item("Command", run.command.empty() ? "(not known)" : run.command, true);
    item("CPU", run.cpu);
    item("Cores", std::to_string(run.logicalCpus) + " logical CPUs, " +
                      std::to_string(run.availableCpus) + " available to the run; " +
                      std::to_string(st.threads) + " render threads");
    item("Memory", run.memory);
    item("Load average", run.loadAverage + " (1, 5, 15 min, at the start of the run)");
    item("System", run.system);
    item("Build", run.compiler);
    item("Settings", std::to_string(st.width) + "x" + std::to_string(st.height) + ", " +
                         std::to_string(st.bounces) + " bounces, " + std::to_string(st.repeats) +
                         (st.repeats == 1 ? " repeat" : " repeats (round-robin)") +
                         (st.quick ? ", --quick (fewer knob values)" : "") +
                         (st.schemesOnly ? ", --schemes-only (each scheme at its defaults)" : ""));
    for (const std::string& p : st.peers) item("Peer", p);
    item("Run time", fixed(st.seconds, 1) + " s");
    h << "</table>\n";

    // The comparison table.
    h << "<h2 id=\"schemes\">The schemes compared</h2>\n"
      << "<p>Each scheme at its defaults, and the peers. Times are the median of " << st.repeats
      << (st.repeats == 1 ? " run" : " runs")
      << (st.repeats > 1 ? ", the range of the runs in brackets; the configurations of a "
                           "scene were run in turn, each once a round, so that the machine's "
                           "load falls on all of them alike"
                         : "")
      << ". Speedup: brute force's render time over the row's, in the same round, at the same "
         "bounces. Hits differing: pixels whose primary hit (primitive or distance) differs from "
         "brute force's; for POV-Ray (depth image), pixels where it hits and brute force misses "
         "or the reverse, or where their distances differ by more than a step of its 16-bit "
         "depth image (the depth range over 65535). Embree and the schemes marked (bounces 0) "
         "trace primary and shadow rays only, against brute force at --bounces 0.</p>\n"
         "<table class=\"schemes\" id=\"schemes-table\">\n<tr>";
    for (const std::string& c : comparisonHeader()) h << "<th>" << htmlEscape(c) << "</th>";
    h << "</tr>\n";
    std::string last;
    for (const BenchRow& r : rows) {
        if (!r.inTable) continue;
        const std::vector<std::string> cells = comparisonCells(r);
        const std::vector<std::string> head = comparisonHeader();
        h << "<tr data-scheme=\"" << htmlEscape(r.tableName()) << "\""
          << (r.scene != last ? " class=\"scene-start\"" : "") << ">";
        last = r.scene;
        for (size_t i = 0; i < cells.size(); ++i) {
            if (!r.measured() && i == 2) {
                h << "<td class=\"note\" colspan=\"" << cells.size() - 2 << "\">"
                  << htmlEscape(cells[i]) << "</td>";
                break;
            }
            h << "<td" << cls(head[i]) << ">" << htmlEscape(cells[i]) << "</td>";
        }
        h << "</tr>\n";
    }
    h << "</table>\n";

    // The plots.
    h << "<h2 id=\"plots\">Plots</h2>\n";
    if (figures.empty()) h << "<p class=\"missing\">No plots: the run drew none.</p>\n";
    int n = 0;
    for (const Figure& f : figures) {
        h << "<figure id=\"" << htmlEscape(f.name) << "\">\n<h3>" << htmlEscape(f.title)
          << "</h3>\n";
        std::string svg;
        if (f.drawn) {
            std::ifstream in(dir + f.file, std::ios::binary);
            std::stringstream ss;
            ss << in.rdbuf();
            svg = ss.str();
        }
        if (svg.find("<svg") != std::string::npos)
            h << inlineSvg(svg, std::string("f").append(std::to_string(++n)).append("-"), f.title)
              << "\n";
        else
            h << "<p class=\"missing\">" << htmlEscape(f.drawn ? "not an SVG: " + f.file : f.why)
              << "</p>\n";
        h << "<figcaption>" << htmlEscape(f.caption) << "</figcaption>\n</figure>\n";
    }

    // Every row.
    h << "<h2 id=\"rows\">Every configuration</h2>\n<details>\n<summary>Every row of "
         "report.csv ("
      << rows.size() << ")</summary>\n<table class=\"all\" id=\"all-rows\">\n<tr>";
    const std::vector<std::string> head = {"scene",
                                           "scheme",
                                           "knob",
                                           "value",
                                           "build ms",
                                           "memory",
                                           "regions",
                                           "render ms",
                                           "speedup",
                                           "rays",
                                           "prim tests/ray",
                                           "region visits/ray",
                                           "hits differing",
                                           "colours differing",
                                           "largest depth diff",
                                           "colour RMSE",
                                           "note"};
    for (const std::string& c : head) h << "<th>" << htmlEscape(c) << "</th>";
    h << "</tr>\n";
    int i = 0;
    for (const BenchRow& r : rows) {
        const Spread b = spreadOf(r.buildMs), t = spreadOf(r.renderMs), s = spreadOf(r.speedup);
        auto range = [](const Spread& x, int digits, const char* unit) {
            if (!x.count) return std::string();
            std::string out = fixed(x.median, digits) + unit;
            const std::string lo = fixed(x.min, digits), hi = fixed(x.max, digits);
            if (x.count > 1 && lo != hi) out += " (" + lo + "–" + hi + ")";
            return out;
        };
        const double rays = std::max<double>(1.0, double(r.counters.rays));
        std::vector<std::string> cells = {r.scene, r.scheme, r.knob, r.value};
        if (r.measured()) {
            cells.insert(cells.end(),
                         {range(b, 1, ""), r.peer ? "" : formatBytes(r.info.memoryBytes),
                          r.peer ? "" : std::to_string(r.info.regions), range(t, 1, ""),
                          range(s, 1, "x"), std::to_string(r.counters.rays),
                          r.peer ? "" : fixed(double(r.counters.primTests) / rays, 2),
                          r.peer ? "" : fixed(double(r.counters.regionVisits) / rays, 2)});
            if (r.compared)
                cells.insert(
                    cells.end(),
                    {std::to_string(r.error.hitDiff),
                     r.colorCompared ? std::to_string(r.error.colorDiff) : "-",
                     num(r.error.maxDepthDiff), r.colorCompared ? num(r.error.colorRmse) : "-"});
            else
                cells.insert(cells.end(), {"-", "-", "-", "-"});
            cells.push_back(r.csvNote());
        } else {
            cells.resize(head.size() - 1);
            cells.push_back(r.note);
        }
        h << "<tr data-row=\"" << ++i << "\">";
        for (size_t c = 0; c < cells.size(); ++c)
            h << "<td"
              << (c + 1 == cells.size() ? (cells[c].empty() ? "" : " class=\"note\"")
                                        : cls(head[c]))
              << ">" << htmlEscape(cells[c]) << "</td>";
        h << "</tr>\n";
    }
    h << "</table>\n</details>\n"
      << "<p>Written by <code>lancer bench --report</code>; the plots' data and gnuplot scripts "
         "are in <code>plots/</code> beside this page.</p>\n</body>\n</html>\n";
    try {
        writeFileAtomic(path, h.str());
    } catch (const std::exception&) {
        return false;
    }
    return true;
}

}  // namespace lancer::bench
