#include "app/bench/plots.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>

#include "app/bench/machine.h"
#include "engine/accel/build_params.h"

namespace lancer::bench {

namespace {

namespace fs = std::filesystem;

/// The scheme's place among SchemeKind (peers after), for colours that stay with a scheme.
int schemeIndex(const std::string& scheme) {
    for (int k = 0; k < kSchemeCount; ++k)
        if (scheme == schemeName(SchemeKind(k))) return k;
    return kSchemeCount;
}

const char* const kColors[] = {"#555555", "#1f77b4", "#2ca02c", "#9467bd",
                               "#ff7f0e", "#8c564b", "#e377c2", "#17becf"};
const char* color(int i) { return kColors[size_t(i) % (sizeof kColors / sizeof *kColors)]; }

/// A gnuplot single-quoted string.
std::string q(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
    return out + "'";
}

/// A label or name in a tab-separated data file: no tabs, no newlines.
std::string cell(std::string s) {
    for (char& c : s)
        if (c == '\t' || c == '\n') c = ' ';
    return s;
}

/// A log axis whose zero (and infinity, for depth errors) are drawn at chosen values: zero at
/// `floor`, below every positive value, infinity at `ceiling`, above every finite one.
struct LogAxis {
    double floor = 0.5, ceiling = 0.0, lo = 0.1, hi = 10.0;
    bool hasInf = false;
    bool hasFinite = false;  ///< some value is positive and finite (else no decade tics)
    std::string infLabel = "inf";

    /// For values `v` (>= 0, maybe inf); `unit`: the smallest positive value that can occur
    /// (1 for pixel counts), `labelRoom`: the fraction of the height below the floor kept for
    /// labels hanging from it.
    static LogAxis fit(const std::vector<double>& v, double unit, double labelRoom) {
        LogAxis a;
        double minPos = kInf, maxFin = 0.0;
        for (double x : v) {
            if (std::isinf(x)) {
                a.hasInf = true;
            } else if (x > 0.0) {
                minPos = std::min(minPos, x);
                maxFin = std::max(maxFin, x);
                a.hasFinite = true;
            }
        }
        if (unit > 0.0) {
            a.floor = 0.5 * unit;
        } else {
            const double base = std::isfinite(minPos) ? minPos : 1e-9;
            a.floor = std::pow(10.0, std::floor(std::log10(base)) - 1.0);
        }
        double top = maxFin > 0.0 ? maxFin : a.floor * 10.0;
        if (a.hasInf) {
            a.ceiling = std::pow(10.0, std::ceil(std::log10(top)) + 1.0);
            top = a.ceiling;
        }
        a.hi = top * 3.0;
        const double decades = std::max(1.0, std::log10(a.hi / a.floor));
        a.lo = a.floor / std::pow(10.0, decades * labelRoom / (1.0 - labelRoom));
        return a;
    }
    double map(double v) const {
        if (std::isinf(v)) return ceiling;
        return v > 0.0 ? v : floor;
    }
    bool atFloor(double v) const { return !(v > 0.0) && !std::isinf(v); }
    /// gnuplot commands for the y axis (log, range, tics with "0" and "inf").
    std::string commands(const std::string& axis = "y") const {
        std::ostringstream os;
        os << "set logscale " << axis << "\nset " << axis << "range [" << num(lo) << ":" << num(hi)
           << "]\nset " << axis << "tics (\"0\" " << num(floor);
        const double first = std::ceil(std::log10(floor) + 1e-9);
        const double last = std::floor(std::log10(hasInf ? ceiling / 10.0 : hi) + 1e-9);
        const int step = std::max(1, int(std::ceil((last - first + 1) / 8.0)));
        for (double e = first; e <= last && hasFinite; e += step)
            os << ", \"1e" << int(e) << "\" 1e" << int(e);
        if (hasInf) os << ", " << q(infLabel) << " " << num(ceiling);
        os << ")\nset arrow from graph 0, first " << num(floor) << " to graph 1, first "
           << num(floor) << " nohead dt 3 lc rgb '#999999' back\n";
        if (hasInf)
            os << "set arrow from graph 0, first " << num(ceiling) << " to graph 1, first "
               << num(ceiling) << " nohead dt 3 lc rgb '#999999' back\n";
        return os.str();
    }
};

/// Tics of a log axis over [lo, hi] at 1, 2 and 5 times the powers of ten (the powers alone over
/// more than three decades), labelled plainly: "set xtics (...)".
std::string logTics(const std::string& axis, double lo, double hi) {
    const int e0 = int(std::floor(std::log10(lo))), e1 = int(std::ceil(std::log10(hi)));
    const bool all = e1 - e0 <= 3;
    std::ostringstream os;
    os << "set " << axis << "tics (";
    bool first = true;
    for (int e = e0; e <= e1; ++e)
        for (double m : {1.0, 2.0, 5.0}) {
            if (!all && m != 1.0) continue;
            const double v = m * std::pow(10.0, e);
            if (v < lo || v > hi) continue;
            os << (first ? "" : ", ") << "\"" << num(v) << "\" " << num(v);
            first = false;
        }
    os << ")\n";
    return first ? std::string() : os.str();
}

/// Points that no other point beats on both counts: more speed and no more error, or no less
/// speed and less error. Sorted by speed.
std::vector<size_t> paretoFront(const std::vector<double>& speed, const std::vector<double>& err) {
    std::vector<size_t> order(speed.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return speed[a] != speed[b] ? speed[a] > speed[b] : err[a] < err[b];
    });
    std::vector<size_t> front;
    double best = kInf;
    for (size_t i : order)
        if (err[i] < best) {
            front.push_back(i);
            best = err[i];
        }
    std::reverse(front.begin(), front.end());
    return front;
}

/// Labels hanging from the floor, spread along a log x axis so that neighbours do not overlap:
/// each at least `gap` (in decades) from the next, as near its point as that allows, and all
/// within [lo, hi] where they fit.
std::vector<double> spreadLabels(const std::vector<double>& x, double gap, double lo, double hi) {
    const size_t n = x.size();
    std::vector<size_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return x[a] < x[b]; });
    std::vector<double> pos(n);
    for (size_t k = 0; k < n; ++k) pos[k] = std::log10(x[order[k]]);
    // Push right where crowded, then centre each crowded run on its points.
    for (int pass = 0; pass < 50; ++pass) {
        bool moved = false;
        for (size_t k = 1; k < n; ++k)
            if (pos[k] < pos[k - 1] + gap) {
                // The run ending at k: shift it so that its centre stays on its points' centre.
                size_t b = k;
                while (b > 0 && pos[b] < pos[b - 1] + gap + 1e-12) --b;
                double want = 0.0;
                for (size_t j = b; j <= k; ++j) want += std::log10(x[order[j]]);
                want /= double(k - b + 1);
                const double start = want - gap * double(k - b) / 2.0;
                for (size_t j = b; j <= k; ++j) pos[j] = start + gap * double(j - b);
                moved = true;
            }
        if (!moved) break;
    }
    // Inside the axis: pushed in from the right end, then from the left one.
    const double l = std::log10(lo), h = std::log10(hi);
    if (n > 0) {
        pos[n - 1] = std::min(pos[n - 1], h);
        for (size_t k = n - 1; k-- > 0;) pos[k] = std::min(pos[k], pos[k + 1] - gap);
        pos[0] = std::max(pos[0], l);
        for (size_t k = 1; k < n; ++k) pos[k] = std::max(pos[k], pos[k - 1] + gap);
    }
    std::vector<double> out(n);
    for (size_t k = 0; k < n; ++k) out[order[k]] = std::pow(10.0, pos[k]);
    return out;
}

struct Writer {
    std::string plotDir, outDir;
    PlotFormat format;
    bool gnuplot = false;
    std::vector<Figure> figures;

    std::string ext() const { return format == PlotFormat::Svg ? "svg" : "png"; }
    std::string terminal(int w, int h) const {
        std::ostringstream os;
        if (format == PlotFormat::Svg)
            os << "set terminal svg size " << w << "," << h
               << " font 'Helvetica,12' noenhanced background rgb 'white'\n";
        else
            os << "set terminal pngcairo size " << w << "," << h << " font 'sans,10' noenhanced\n";
        return os.str();
    }
    /// Write DATA NAME.BLOCK.dat (tab separated, one line a row) and return its quoted name.
    std::string data(const std::string& name, const std::string& block,
                     const std::vector<std::vector<std::string>>& lines) const {
        const std::string file = name + "." + block + ".dat";
        std::ofstream f(plotDir + "/" + file);
        for (const auto& l : lines) {
            for (size_t i = 0; i < l.size(); ++i) f << (i ? "\t" : "") << cell(l[i]);
            f << "\n";
        }
        return q(file);
    }
    void figure(const std::string& name, const std::string& title, const std::string& caption,
                int w, int h, const std::string& body) {
        Figure f;
        f.name = name;
        f.file = name + "." + ext();
        f.title = title;
        f.caption = caption;
        {
            std::ofstream gp(plotDir + "/" + name + ".gp");
            gp << terminal(w, h) << "set output " << q("../" + f.file) << "\n"
               << "set datafile separator '\\t'\nset grid lc rgb '#dddddd'\n"
               << body;
        }
        std::error_code ec;
        fs::remove(outDir + "/" + f.file, ec);
        if (!gnuplot) {
            f.why = "not drawn: gnuplot is not installed";
        } else {
            bool ok = false;
            captureCommand("cd " + shellQuote(plotDir) + " && gnuplot " + shellQuote(name + ".gp") +
                               " 2>" + shellQuote(name + ".log"),
                           ok, false);
            f.drawn = ok && fs::exists(outDir + "/" + f.file) &&
                      fs::file_size(outDir + "/" + f.file, ec) > 0;
            if (!f.drawn)
                f.why = "gnuplot failed on plots/" + name + ".gp (see plots/" + name + ".log)";
        }
        figures.push_back(f);
    }
};

/// The rows of the sweeps of one scene that were measured against brute force (no peers, no
/// progressive passes).
std::vector<const BenchRow*> sweepRows(const std::deque<BenchRow>& rows, const std::string& scene) {
    std::vector<const BenchRow*> out;
    for (const BenchRow& r : rows)
        if (r.scene == scene && r.measured() && r.compared && !r.speedup.empty() &&
            r.knob != "progressive pass" && r.knob.compare(0, 4, "peer") != 0 &&
            r.knob.compare(0, 4, "mesh") != 0 && r.scheme != "brute")
            out.push_back(&r);
    return out;
}

/// One panel of the speed-against-error plot: every configuration at (speedup, error), its
/// label beside it (or, at zero error, hanging below the zero line, spread apart), the front.
std::string speedErrorPanel(Writer& wr, const std::string& name, const std::string& panel,
                            const std::vector<const BenchRow*>& pts,
                            const std::function<double(const BenchRow&)>& error, double unit,
                            const std::string& ylabel, const std::string& infLabel, double xlo,
                            double xhi, const std::string& title) {
    std::vector<double> errs, speed;
    for (const BenchRow* r : pts) {
        errs.push_back(error(*r));
        speed.push_back(spreadOf(r->speedup).median);
    }
    LogAxis ax = LogAxis::fit(errs, unit, 0.42);
    ax.infLabel = infLabel;
    std::vector<double> y(errs.size());
    for (size_t i = 0; i < errs.size(); ++i) y[i] = ax.map(errs[i]);

    std::vector<std::vector<std::string>> points, above, aboveLeft, hanging, leaders, front;
    std::vector<size_t> floorIdx;
    std::vector<double> floorX;
    // Labels beside their points: one a line below the other where points crowd (within 0.08
    // of the x axis's width and a line of the y axis's height).
    const double xDecades = std::log10(xhi / xlo), yLine = std::log10(ax.hi / ax.lo) * 14.0 / 420.0;
    std::vector<std::pair<double, double>> placed;  // log x, log y of the labels written
    auto labelY = [&](double x, double yv) {
        double ly = std::log10(yv);
        for (bool moved = true; moved;) {
            moved = false;
            for (const auto& [px, py] : placed)
                if (std::abs(px - std::log10(x)) < 0.08 * xDecades && std::abs(py - ly) < yLine) {
                    ly = py - yLine;
                    moved = true;
                }
        }
        placed.push_back({std::log10(x), ly});
        return num(std::pow(10.0, ly));
    };
    for (size_t i = 0; i < pts.size(); ++i) {
        const Spread s = spreadOf(pts[i]->speedup);
        points.push_back({num(s.median), num(y[i]), num(s.min), num(s.max),
                          std::to_string(schemeIndex(pts[i]->scheme))});
        if (ax.atFloor(errs[i])) {
            floorIdx.push_back(i);
            floorX.push_back(s.median);
        } else if (std::log10(s.median / xlo) < 0.7 * std::log10(xhi / xlo)) {
            above.push_back({num(s.median), labelY(s.median, y[i]), pts[i]->label()});
        } else {  // near the right edge: written to the left of the point
            aboveLeft.push_back({num(s.median), labelY(s.median, y[i]), pts[i]->label()});
        }
    }
    // About 13 px between hanging labels on a plot area of about 860 px.
    const double gap = std::log10(xhi / xlo) * 13.0 / 860.0;
    const double margin = std::pow(10.0, gap);
    const std::vector<double> lx = spreadLabels(floorX, gap, xlo * margin, xhi / margin);
    const double hangY = ax.floor / std::pow(ax.floor / ax.lo, 0.06);
    for (size_t k = 0; k < floorIdx.size(); ++k) {
        const size_t i = floorIdx[k];
        hanging.push_back({num(lx[k]), num(hangY), pts[i]->label()});
        leaders.push_back(
            {num(floorX[k]), num(ax.floor), num(lx[k] - floorX[k]), num(hangY - ax.floor)});
    }
    for (size_t i : paretoFront(speed, y)) front.push_back({num(speed[i]), num(y[i])});

    std::ostringstream os;
    os << "unset arrow\nunset label\nset logscale x\nset xrange [" << num(xlo) << ":" << num(xhi)
       << "]\n"
       << logTics("x", xlo, xhi) << ax.commands() << "set ylabel " << q(ylabel)
       << "\nset key outside top center horizontal\nset title " << q(title) << "\n";
    std::vector<std::string> clauses;
    const std::string base = name + "." + panel;
    clauses.push_back(wr.data(base, "front", front) +
                      " using 1:2 with linespoints lw 2 pt 6 ps 2.2 lc rgb '#d62728' title 'Pareto "
                      "front'");
    const std::string pf = wr.data(base, "points", points);
    std::map<int, std::string> present;
    for (const BenchRow* r : pts) present[schemeIndex(r->scheme)] = r->scheme;
    for (const auto& [k, scheme] : present)
        clauses.push_back(pf + " using ($5==" + std::to_string(k) +
                          "?$1:NaN):2:3:4 with xerrorbars pt 7 ps 0.9 lc rgb '" + color(k) +
                          "' title " + q(scheme));
    if (!leaders.empty())
        clauses.push_back(wr.data(base, "leaders", leaders) +
                          " using 1:2:3:4 with vectors nohead lc rgb '#bbbbbb' notitle");
    if (!hanging.empty())
        clauses.push_back(wr.data(base, "hanging", hanging) +
                          " using 1:2:3 with labels left rotate by -90 font ',9' notitle");
    if (!above.empty())
        clauses.push_back(wr.data(base, "above", above) +
                          " using 1:2:3 with labels left offset char 0.7,0.35 font ',9' notitle");
    if (!aboveLeft.empty())
        clauses.push_back(wr.data(base, "above-left", aboveLeft) +
                          " using 1:2:3 with labels right offset char -0.7,0.35 font ',9' "
                          "notitle");
    os << "plot ";
    for (size_t i = 0; i < clauses.size(); ++i) os << (i ? ", \\\n     " : "") << clauses[i];
    os << "\n";
    return os.str();
}

}  // namespace

std::string sceneSlug(const std::string& spec) {
    std::string s = spec;
    if (s.compare(0, 8, "builtin:") == 0)
        s = s.substr(8);
    else
        s = fs::path(s).stem().string();
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '-';
    return s.empty() ? "scene" : s;
}

std::vector<Figure> drawPlots(const std::string& dir, const std::deque<BenchRow>& rows,
                              const std::vector<std::string>& scenes, PlotFormat format) {
    Writer wr;
    wr.outDir = dir;
    wr.plotDir = dir + "/plots";
    wr.format = format;
    std::error_code ec;
    fs::create_directories(wr.plotDir, ec);
    bool ok = false;
    captureCommand("command -v gnuplot", ok);
    wr.gnuplot = ok;

    // Speed against error, one figure a scene (two panels: pixels, depth).
    std::map<std::string, int> slugs;
    std::vector<std::string> slugOf;
    for (const std::string& spec : scenes) {
        std::string slug = sceneSlug(spec);
        if (slugs[slug]++) slug += "-" + std::to_string(slugs[slug]);
        slugOf.push_back(slug);
    }
    // The speedup axis over `pts`' ranges, with room at both ends, at least a factor 16 wide.
    auto speedRange = [](const std::vector<const BenchRow*>& pts, double& xlo, double& xhi) {
        xlo = kInf;
        xhi = 0.0;
        for (const BenchRow* r : pts) {
            const Spread s = spreadOf(r->speedup);
            xlo = std::min(xlo, s.min);
            xhi = std::max(xhi, s.max);
        }
        xlo /= 1.35;
        xhi *= 1.35;
        if (xhi / xlo < 4.0) {
            const double mid = std::sqrt(xlo * xhi);
            xlo = mid / 2.0;
            xhi = mid * 2.0;
        }
    };
    for (size_t si = 0; si < scenes.size(); ++si) {
        const std::string& spec = scenes[si];
        const auto pts = sweepRows(rows, spec);
        if (pts.empty()) continue;
        double xlo, xhi;
        speedRange(pts, xlo, xhi);
        const std::string name = "speed_vs_error-" + slugOf[si];
        std::ostringstream body;
        body << "set multiplot layout 2,1\n"
             << "set xlabel 'speedup over brute force (median of the repeats; bars: their range)'\n"
             << speedErrorPanel(
                    wr, name, "hits", pts,
                    [](const BenchRow& r) { return double(r.error.hitDiff); }, 1.0,
                    "pixels whose primary hit differs", "", xlo, xhi,
                    spec + ": pixels whose primary hit differs from brute force's")
             << speedErrorPanel(
                    wr, name, "depth", pts, [](const BenchRow& r) { return r.error.maxDepthDiff; },
                    0.0, "largest depth difference", "hit/miss", xlo, xhi,
                    spec + ": largest difference of primary hit distance")
             << "unset multiplot\n";
        wr.figure(name, "Speed against error: " + spec,
                  "Each point is a configuration (its scheme and knob value written beside it, or "
                  "below the zero line when it makes no error), at its speedup over brute force "
                  "(the median of the repeats, the bar their range). Top: pixels whose primary "
                  "hit differs from brute force's; bottom: the largest difference of primary hit "
                  "distance (hit/miss: a pixel hits in one image and misses in the other). Error "
                  "is on a log scale, zero drawn on the dotted line. The red line joins the "
                  "Pareto front: the configurations no other beats on both speed and error.",
                  1100, 1250, body.str());
    }

    // Exact CSG against OpenSCAD's meshes of it, one figure a scene of the mesh axis.
    for (size_t si = 0; si < scenes.size(); ++si) {
        std::vector<const BenchRow*> pts;
        for (const BenchRow& r : rows)
            if (r.scene == scenes[si] && r.knob.compare(0, 5, "mesh ") == 0 && r.measured() &&
                r.compared && !r.speedup.empty() && r.scheme != "brute")
                pts.push_back(&r);
        // Without a measured mesh (no openscad, no Embree) there is nothing to set the schemes
        // against: the table's rows say why, and no figure is drawn.
        const bool meshes =
            std::any_of(pts.begin(), pts.end(), [](const BenchRow* r) { return r->peer; });
        if (!meshes) continue;
        double xlo, xhi;
        speedRange(pts, xlo, xhi);
        const std::string name = "exact_vs_mesh-" + slugOf[si];
        const std::string& spec = scenes[si];
        std::ostringstream body;
        body << "set multiplot layout 2,1\n"
             << "set xlabel 'speedup of the render over brute force, both at --bounces 0 "
                "(median of the repeats; bars: their range)'\n"
             << speedErrorPanel(
                    wr, name, "silhouette", pts,
                    [](const BenchRow& r) { return double(r.error.silhouetteDiff); }, 1.0,
                    "pixels hit in one image only", "", xlo, xhi,
                    spec + ": pixels whose silhouette differs from the exact solid's")
             << speedErrorPanel(
                    wr, name, "depth", pts, [](const BenchRow& r) { return r.error.p99DepthDiff; },
                    0.0, "depth difference, 99th percentile", "", xlo, xhi,
                    spec + ": difference of primary hit distance where both hit, 99th percentile")
             << "unset multiplot\n";
        wr.figure(name, "Exact CSG against OpenSCAD's mesh: " + spec,
                  "Each scheme traces the exact solid; each mesh point is OpenSCAD's CGAL render "
                  "of the same model with its circles cut into $fn segments, traced by Embree. "
                  "All at --bounces 0 (primary rays and a shadow ray a light), at their render's "
                  "speedup over brute force; the mesh's own making (OpenSCAD's time, in the "
                  "table's build column) is not in it. Top: pixels hit in one image and missed "
                  "in the other; bottom: the difference of hit distance over the pixels both hit, "
                  "the 99th percentile (the 1% above it are depth edges, where one sees past an "
                  "edge the other does not). Error on a log scale, zero on the dotted line; the "
                  "red line joins the Pareto front.",
                  1100, 1250, body.str());
    }

    // Progressive passes: time to each pass against its RMSE, a line a scene.
    {
        std::vector<const BenchRow*> passes;
        std::vector<double> rmse;
        for (const BenchRow& r : rows)
            if (r.knob == "progressive pass" && r.measured() && r.compared) {
                passes.push_back(&r);
                rmse.push_back(r.error.colorRmse);
            }
        if (!passes.empty()) {
            double tlo = kInf, thi = 0.0;
            for (const BenchRow* r : passes) {
                const Spread t = spreadOf(r->renderMs);
                tlo = std::min(tlo, t.min);
                thi = std::max(thi, t.max);
            }
            LogAxis ax = LogAxis::fit(rmse, 0.0, 0.12);
            ax.floor = std::min(ax.floor, 0.5 / 255.0 / 16.0);
            ax.lo = ax.floor / 3.0;
            std::ostringstream body;
            body << "set title 'Progressive passes: time against error'\nset logscale x\n"
                 << "set xrange [" << num(tlo / 1.5) << ":" << num(thi * 2.0) << "]\n"
                 << logTics("x", tlo / 1.5, thi * 2.0)
                 << "set xlabel 'time since the first pass started (ms; median of the repeats, "
                    "bars: their range)'\n"
                 << ax.commands() << "set ylabel 'colour RMSE against brute force (0..1)'\n"
                 << "set key outside top center horizontal\n";
            std::vector<std::string> clauses;
            for (size_t si = 0; si < scenes.size(); ++si) {
                std::vector<std::vector<std::string>> lines;
                for (const BenchRow* r : passes) {
                    if (r->scene != scenes[si]) continue;
                    const Spread t = spreadOf(r->renderMs);
                    lines.push_back({num(t.median), num(ax.map(r->error.colorRmse)), num(t.min),
                                     num(t.max),
                                     "stride " + r->value + (r->value == "1" ? " (final)" : "")});
                }
                if (lines.empty()) continue;
                const std::string f = wr.data("progressive", slugOf[si], lines);
                const std::string c = std::string("lc rgb '") + color(int(si) + 1) + "'";
                clauses.push_back(f + " using 1:2:3:4 with xerrorlines pt 7 " + c + " title " +
                                  q(scenes[si] + " (" + passes.front()->scheme + ")"));
                // Each scene's labels at a height of their own beside the points.
                const char* const dy[] = {"0.8", "-0.9", "-1.9", "1.8"};
                clauses.push_back(f + " using 1:2:5 with labels left offset char 0.8," +
                                  dy[si % 4] + " font ',9' tc rgb '" + color(int(si) + 1) +
                                  "' notitle");
            }
            body << "plot ";
            for (size_t i = 0; i < clauses.size(); ++i)
                body << (i ? ", \\\n     " : "") << clauses[i];
            body << "\n";
            wr.figure("progressive", "Progressive passes: time against error",
                      "The viewer's passes (one pixel in 16x16 drawn as a block, then one in "
                      "4x4, then every pixel) of the command line's default scheme: the time "
                      "since the first pass started against the colour RMSE of what is shown "
                      "against the brute-force image. The last pass is the image itself (zero "
                      "error, on the dotted line).",
                      1000, 600, body.str());
        }
    }

    // A knob swept per scene: `y` of each row with that knob, against its value.
    auto knobPlot = [&](const std::string& name, const std::string& knob, const std::string& title,
                        const std::string& caption, const std::string& settings,
                        const std::function<std::vector<std::string>(const BenchRow&)>& fields,
                        const std::vector<std::string>& using_) {
        std::vector<std::string> clauses;
        for (size_t si = 0; si < scenes.size(); ++si) {
            std::vector<std::vector<std::string>> lines;
            for (const BenchRow& r : rows)
                if (r.scene == scenes[si] && r.knob == knob && r.measured() && r.compared)
                    lines.push_back(fields(r));
            if (lines.empty()) continue;
            const std::string f = wr.data(name, slugOf[si], lines);
            for (const std::string& u : using_) {
                std::string c = u;
                const std::string col = std::string("lc rgb '") + color(int(si) + 1) + "'";
                for (size_t p; (p = c.find("@C")) != std::string::npos;) c.replace(p, 2, col);
                for (size_t p; (p = c.find("@T")) != std::string::npos;)
                    c.replace(p, 2, q(scenes[si]));
                clauses.push_back(f + " " + c);
            }
        }
        if (clauses.empty()) return;
        std::ostringstream body;
        body << "set title " << q(title) << "\nset key outside top center horizontal\n"
             << settings << "plot ";
        for (size_t i = 0; i < clauses.size(); ++i) body << (i ? ", \\\n     " : "") << clauses[i];
        body << "\n";
        wr.figure(name, title, caption, 1000, 560, body.str());
    };
    auto errorValues = [&](const std::string& knob, bool color) {
        std::vector<double> v;
        for (const BenchRow& r : rows)
            if (r.knob == knob && r.measured() && r.compared)
                v.push_back(double(color ? r.error.colorDiff : r.error.hitDiff));
        return LogAxis::fit(v, 1.0, 0.05);
    };

    knobPlot("regular_max_level", "regular max-level", "Regular scheme: max-level",
             "Speedup over brute force (median of the repeats, bars their range; left axis) and "
             "memory of the structure (dashed, right axis) at each max-level.",
             "set xlabel 'max-level'\nset ylabel 'speedup over brute force'\nset y2label "
             "'memory (KiB, dashed)'\nset y2tics\nset ytics nomirror\nset offsets 0.5, 0.5, 0, "
             "0\n",
             [](const BenchRow& r) {
                 const Spread s = spreadOf(r.speedup);
                 return std::vector<std::string>{r.value, num(s.median), num(s.min), num(s.max),
                                                 num(double(r.info.memoryBytes) / 1024.0)};
             },
             {"using 1:2:3:4 with yerrorlines pt 7 @C title @T",
              "using 1:5 axes x1y2 with linespoints dt 2 pt 6 @C title 'memory'"});
    {
        const LogAxis ax = errorValues("push delta", false);
        knobPlot("push_delta", "push delta", "Push step: delta against error",
                 "Pixels whose primary hit differs from brute force's at each push distance "
                 "(relative to the box's extent), the exact step giving none.",
                 "set logscale x\nset xlabel 'delta (relative to the box extent)'\nset ylabel "
                 "'pixels whose hit differs'\n" +
                     ax.commands(),
                 [ax](const BenchRow& r) {
                     return std::vector<std::string>{r.value, num(ax.map(double(r.error.hitDiff)))};
                 },
                 {"using 1:2 with linespoints pt 7 @C title @T"});
    }
    {
        const LogAxis ax = errorValues("offset", true);
        knobPlot("offset", "offset", "Secondary-ray offset against error",
                 "Pixels whose colour differs from brute force's (by more than 2/255) at each "
                 "offset of the secondary rays' origins (relative to the scene's scale; 0 "
                 "drawn at 1e-16).",
                 "set logscale x\nset xlabel 'offset (relative to the scene scale; 0 at "
                 "1e-16)'\nset ylabel 'pixels whose colour differs'\n" +
                     ax.commands(),
                 [ax](const BenchRow& r) {
                     const double o = std::atof(r.value.c_str());
                     return std::vector<std::string>{num(o > 0.0 ? o : 1e-16),
                                                     num(ax.map(double(r.error.colorDiff)))};
                 },
                 {"using 1:2 with linespoints pt 7 @C title @T"});
    }
    {
        // Float against double: each configuration's render time against its primary hits'
        // depth error (the 99th percentile filled, the largest open), the double rows on the
        // dotted zero line. Labels name the float rows' scheme, moved down where they crowd.
        std::vector<double> depths;
        double tLo = kInf, tHi = 0.0;
        for (const BenchRow& r : rows)
            if (r.knob == "precision" && r.measured() && r.compared) {
                for (double d : {r.error.p99DepthDiff, r.error.maxDepthDiff}) depths.push_back(d);
                tLo = std::min(tLo, spreadOf(r.renderMs).median);
                tHi = std::max(tHi, spreadOf(r.renderMs).median);
            }
        const LogAxis ax = LogAxis::fit(depths, 0.0, 0.05);
        auto placed = std::make_shared<std::vector<std::pair<double, double>>>();
        const double yStep = std::log10(ax.hi / ax.lo) / 24.0;
        const std::string xRange = tHi > 0.0
                                       ? "set xrange [" + num(tLo / 1.6) + ":" + num(tHi * 3.0) +
                                             "]\n" + logTics("x", tLo / 1.6, tHi * 3.0)
                                       : std::string();
        knobPlot("precision", "precision", "Float against double: render time against depth error",
                 "Each scene's primitive tests in double and in single precision (the walk, the "
                 "transforms and the CSG in double), in the regular scheme and in brute force: "
                 "render time (median of the repeats) against the primary hits' distance error "
                 "against brute force in double, its 99th percentile (filled) and its largest "
                 "(open; a pixel on an edge may see another surface, inf: a pixel hit in one "
                 "image and missed in the other). The regular scheme in double is on the dotted "
                 "zero line.",
                 "set logscale x\nset xlabel 'render time (ms)'\nset ylabel 'depth error "
                 "(scene units)'\n" +
                     xRange + ax.commands(),
                 [ax, placed, yStep](const BenchRow& r) {
                     const double t = spreadOf(r.renderMs).median, y = ax.map(r.error.p99DepthDiff);
                     double ly = std::log10(y);
                     for (bool moved = true; moved && r.value == "float";) {
                         moved = false;
                         for (const auto& [px, py] : *placed)
                             if (std::abs(px - std::log10(t)) < 0.25 &&
                                 std::abs(py - ly) < 0.99 * yStep) {
                                 ly = py - yStep;
                                 moved = true;
                             }
                     }
                     if (r.value == "float") placed->push_back({std::log10(t), ly});
                     return std::vector<std::string>{
                         num(t), num(y), num(ax.map(r.error.maxDepthDiff)),
                         r.value == "float" ? r.scheme : "", num(std::pow(10.0, ly))};
                 },
                 {"using 1:2 with points pt 7 ps 1.3 @C title @T",
                  "using 1:3 with points pt 6 ps 1.3 @C notitle",
                  "using 1:5:4 with labels left offset char 0.8,0 font ',9' notitle"});
    }
    return wr.figures;
}

}  // namespace lancer::bench
