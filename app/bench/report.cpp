#include "app/bench/report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <sstream>

#include "app/bench/embree_peer.h"
#include "app/bench/image_error.h"
#include "app/bench/speedup.h"
#include "engine/render/progressive.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "engine/util/format.h"

namespace lancer::bench {

namespace {

/// One point of a sweep: a knob set to a value.
struct Config {
    std::string knob, value;
    BuildParams build;
    ShadingOptions shading;
};

std::string num(double v) {
    if (std::isinf(v)) return "inf";
    std::ostringstream os;
    os.precision(6);
    os << v;
    return os.str();
}

std::vector<Config> sweep(bool quick, bool schemesOnly, bool regularOn, bool irregularOn) {
    std::vector<Config> out;
    auto add = [&](const std::string& knob, const std::string& value, BuildParams b,
                   ShadingOptions s = {}) {
        out.push_back({knob, value, b, s});
    };
    BuildParams regular;
    regular.scheme = SchemeKind::Regular;
    BuildParams irregular;
    irregular.scheme = SchemeKind::Irregular;
    if (regularOn) add("scheme", "regular", regular);
    if (irregularOn) add("scheme", "irregular", irregular);
    if (schemesOnly) return out;
    std::vector<int> levels =
        quick ? std::vector<int>{6, 12} : std::vector<int>{3, 6, 9, 12, 15, 18, 21, 24};
    for (int l : levels) {
        BuildParams b = regular;
        b.regular.maxLevel = l;
        add("regular max-level", std::to_string(l), b);
    }
    std::vector<int> objects =
        quick ? std::vector<int>{1, 8} : std::vector<int>{1, 2, 4, 8, 16, 32};
    for (int m : objects) {
        BuildParams b = regular;
        b.regular.maxObjects = m;
        add("regular max-objects", std::to_string(m), b);
        BuildParams c = irregular;
        c.irregular.maxObjects = m;
        add("irregular max-objects", std::to_string(m), c);
    }
    std::vector<double> deltas =
        quick ? std::vector<double>{1e-12, 1e-2}
              : std::vector<double>{1e-15, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 5e-2};
    for (double d : deltas) {
        BuildParams b = regular;
        b.regular.step = StepMethod::Push;
        b.regular.delta = d;
        add("push delta", num(d), b);
    }
    for (BspHeuristic h : {BspHeuristic::First, BspHeuristic::Balanced, BspHeuristic::FewestCuts}) {
        BuildParams b = irregular;
        b.irregular.heuristic = h;
        add("bsp-heuristic", heuristicName(h), b);
    }
    for (SplitAxes a : {SplitAxes::Cycle, SplitAxes::Cost}) {
        BuildParams b = regular;
        b.regular.splitAxes = a;
        add("split-axes", splitAxesName(a), b);
    }
    for (bool mail : {true, false}) {
        BuildParams b = regular;
        b.mailboxes = mail;
        add("regular mailboxes", mail ? "on" : "off", b);
    }
    std::vector<double> offsets =
        quick ? std::vector<double>{0.0, 1e-9}
              : std::vector<double>{0.0, 1e-14, 1e-12, 1e-9, 1e-6, 1e-4, 1e-2};
    for (double o : offsets) {
        ShadingOptions s;
        s.offsetScale = o;
        add("offset", num(o), regular, s);
    }
    return out;
}

const char* kHeader =
    "scene,scheme,knob,value,build_ms,memory_bytes,regions,render_ms,speedup,rays,prim_tests_per_"
    "ray,"
    "region_visits_per_ray,mailbox_hits,walk_errors,hit_diff_pixels,color_diff_pixels,max_depth_"
    "diff\n";

void writePlots(const std::string& dir, const std::vector<std::string>& scenes) {
    // One gnuplot script per figure; each reads report.csv with awk-filtered rows.
    auto script = [&](const std::string& name, const std::string& body) {
        std::ofstream f(dir + "/" + name + ".gp");
        f << "set datafile separator ','\nset terminal pngcairo size 1000,620 font 'sans,10'\n"
          << "set output '" << name << ".png'\nset key outside right\nset grid\n"
          << body;
    };
    auto rows = [](const std::string& scene, const std::string& knob) {
        return "'< awk -F, \"\\$1==\\\"" + scene + "\\\" && \\$3==\\\"" + knob +
               "\\\"\" report.csv'";
    };
    std::string speedErr =
        "set title 'Speed against error (every configuration)'\nset xlabel 'speedup over brute "
        "force'\n"
        "set ylabel 'pixels whose primary hit differs from brute force'\nset logscale x\nset "
        "yrange [-1:*]\nplot ";
    std::string level =
        "set title 'Regular scheme: max-level'\nset xlabel 'max-level'\nset ylabel 'speedup'\nset "
        "y2label 'memory (KiB)'\nset y2tics\nplot ";
    std::string delta =
        "set title 'Push step: delta against error'\nset xlabel 'delta (relative to the scene "
        "size)'\nset logscale x\n"
        "set ylabel 'pixels whose hit differs'\nset yrange [-1:*]\nplot ";
    std::string offset =
        "set title 'Secondary-ray offset against error'\nset xlabel 'offset (relative to the scene "
        "scale; 0 plotted at 1e-16)'\nset logscale x\n"
        "set ylabel 'pixels whose colour differs'\nset yrange [-1:*]\nplot ";
    std::string prog =
        "set title 'Progressive passes: error and time'\nset xlabel 'pass stride'\nset logscale x "
        "2\nset xrange [*:*] reverse\n"
        "set ylabel 'pixels differing from the final image'\nset y2label 'time since the start "
        "(ms)'\nset y2tics\nplot ";
    for (size_t i = 0; i < scenes.size(); ++i) {
        const std::string& s = scenes[i];
        std::string sep = i + 1 < scenes.size() ? ", \\\n  " : "\n";
        speedErr += "'< awk -F, \"\\$1==\\\"" + s +
                    "\\\"\" report.csv' using 9:15 with points pt 7 title '" + s + "'" + sep;
        level += rows(s, "regular max-level") + " using 4:9 with linespoints title '" + s +
                 " speedup', " + rows(s, "regular max-level") +
                 " using 4:($6/1024) axes x1y2 with linespoints dt 2 title '" + s + " memory'" +
                 sep;
        delta += rows(s, "push delta") + " using 4:15 with linespoints title '" + s + "'" + sep;
        offset += rows(s, "offset") + " using ($4==0?1e-16:$4):16 with linespoints title '" + s +
                  "'" + sep;
        prog += rows(s, "progressive pass") + " using 4:16 with linespoints title '" + s +
                " error', " + rows(s, "progressive pass") +
                " using 4:8 axes x1y2 with linespoints dt 2 title '" + s + " time'" + sep;
    }
    script("speed_vs_error", speedErr);
    script("regular_max_level", level);
    script("push_delta", delta);
    script("offset", offset);
    script("progressive", prog);
}

}  // namespace

bool createOutDir(const std::string& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) std::cerr << "error: --out " << dir << ": " << ec.message() << "\n";
    return !ec;
}

int runBench(const BenchOptions& opt) {
    namespace fs = std::filesystem;
    if (!createOutDir(opt.outDir)) return 2;
    auto wanted = [&](SchemeKind k) {
        return std::find(opt.schemes.begin(), opt.schemes.end(), schemeName(k)) !=
               opt.schemes.end();
    };
    const bool withBrute = wanted(SchemeKind::Brute);
    if (!withBrute && !opt.schemesOnly) {
        std::cerr << "error: --schemes without brute: the sweeps measure error against brute "
                     "force; add --schemes-only\n";
        return 2;
    }
    std::ostringstream csv, table;
    csv << kHeader;
    table << "| scene | scheme | build ms | regions | memory | render ms | us/ray | prim tests/ray "
             "| region visits/ray | speedup | hits differing |\n"
          << "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    std::vector<std::string> done;
    for (const std::string& spec : opt.scenes) {
        Scene scene;
        try {
            scene = loadScene(spec);
        } catch (const std::exception& e) {
            std::cerr << "error: " << e.what() << "\n";
            return 2;
        }
        RenderOptions ro;
        ro.width = opt.width;
        ro.height = opt.height;
        ro.threads = opt.threads;
        ro.shading.bounces = opt.bounces;

        // The reference of this run (after a small warm-up render that starts the thread pool).
        // Without brute force, renders are timed alone, with no speedup and no error.
        BuildParams bruteParams;
        auto brute = buildAccelerator(scene, bruteParams);
        Image ref(ro.width, ro.height);
        std::optional<SpeedupBaseline> baseline;
        if (withBrute) {
            render(scene, *brute, ro, ref, PassLattice{16, 0});
            baseline.emplace(scene, *brute, ro, PassLattice{}, ref);
        }
        auto alone = [&](const RenderStats& s) {
            Speedup sp;
            sp.scheme = s;
            sp.pixels = size_t(ro.width) * size_t(ro.height);
            return sp;
        };
        auto row = [&](const char* scheme, const std::string& knob, const std::string& value,
                       const AccelInfo& info, const Speedup& sp, const ImageError& e) {
            const RenderStats& s = sp.scheme;
            const RayCounters& c = s.counters;
            double rays = c.rays ? double(c.rays) : 1.0;
            if (knob == "scheme" || knob == "peer (bounces 0)") {
                char speedup[32] = "-", differing[32] = "-";
                if (withBrute) {
                    std::snprintf(speedup, sizeof speedup, "%.1fx", sp.ratio());
                    std::snprintf(differing, sizeof differing, "%zu", e.hitDiff);
                }
                char line[512];
                std::snprintf(line, sizeof line,
                              "| %s | %s%s | %.0f | %zu | %s | %.0f | %.2f | %.1f | %.1f | "
                              "%s | %s |\n",
                              spec.c_str(), scheme, knob == "scheme" ? "" : " (bounces 0)",
                              info.buildMs, info.regions,
                              formatBytes(info.memoryBytes, ByteUnit::MiB).c_str(), s.renderMs,
                              1000.0 * s.renderMs / rays, double(c.primTests) / rays,
                              double(c.regionVisits) / rays, speedup, differing);
                table << line;
            }
            csv << spec << "," << scheme << "," << knob << "," << value << "," << num(info.buildMs)
                << "," << info.memoryBytes << "," << info.regions << "," << num(s.renderMs) << ","
                << num(sp.ratio()) << "," << c.rays << "," << num(double(c.primTests) / rays) << ","
                << num(double(c.regionVisits) / rays) << "," << c.mailboxHits << "," << c.walkErrors
                << "," << e.hitDiff << "," << e.colorDiff << "," << num(e.maxDepthDiff) << "\n";
        };
        if (baseline) {
            row("brute", "scheme", "brute", brute->info(), baseline->against(baseline->brute()),
                {});
            std::cerr << spec << ": brute force " << int(baseline->brute().renderMs) << " ms\n";
        }

        for (const Config& c : sweep(opt.quick, opt.schemesOnly, wanted(SchemeKind::Regular),
                                     wanted(SchemeKind::Irregular))) {
            std::unique_ptr<Accelerator> accel;
            try {
                accel = buildAccelerator(scene, c.build);
            } catch (const std::invalid_argument& e) {
                std::cerr << spec << ": " << c.knob << " = " << c.value << ": skipped: " << e.what()
                          << "\n";
                continue;
            }
            RenderOptions r = ro;
            r.shading.offsetScale = c.shading.offsetScale;
            Image img(ro.width, ro.height);
            // The offset sweep changes the options: timed against the same brute-force render.
            const Speedup s = !baseline ? alone(render(scene, *accel, r, img))
                              : r.shading.offsetScale == ro.shading.offsetScale
                                  ? baseline->measure(*accel, img)
                                  : baseline->against(render(scene, *accel, r, img));
            row(schemeName(c.build.scheme), c.knob, c.value, accel->info(), s,
                baseline ? compareImages(ref, img) : ImageError{});
            std::cerr << spec << ": " << c.knob << " = " << c.value << ": "
                      << int(s.scheme.renderMs) << " ms\n";
        }

        // Against a peer: Embree on union-only scenes, on primary and shadow rays
        // (--bounces 0), with every scheme of ours on the same workload.
        if (EmbreePeer::available() && EmbreePeer::supports(scene)) {
            RenderOptions r0 = ro;
            r0.shading.bounces = 0;
            Image ref0(ro.width, ro.height);
            // Speedups of these rows are over brute force at --bounces 0.
            std::optional<SpeedupBaseline> base0;
            if (withBrute) {
                base0.emplace(scene, *brute, r0, PassLattice{}, ref0);
                row("brute", "peer (bounces 0)", "brute", brute->info(),
                    base0->against(base0->brute()), {});
            }
            auto against0 = [&](const RenderStats& s) {
                return base0 ? base0->against(s) : alone(s);
            };
            for (SchemeKind k : {SchemeKind::Regular, SchemeKind::Irregular}) {
                if (!wanted(k)) continue;
                BuildParams b;
                b.scheme = k;
                try {
                    auto a = buildAccelerator(scene, b);
                    Image img(ro.width, ro.height);
                    // Rendered before it is compared: a function's arguments have no order.
                    const Speedup sp = against0(render(scene, *a, r0, img));
                    row(schemeName(k), "peer (bounces 0)", schemeName(k), a->info(), sp,
                        base0 ? compareImages(ref0, img) : ImageError{});
                } catch (const std::invalid_argument&) {
                }
            }
            EmbreePeer peer(scene);
            Image img(ro.width, ro.height);
            const Speedup s = against0(peer.render(r0, img));
            AccelInfo info;
            info.buildMs = peer.buildMs();
            info.regions = 0;
            row("embree", "peer (bounces 0)", "embree", info, s,
                base0 ? compareImages(ref0, img) : ImageError{});
            std::cerr << spec << ": embree " << int(s.scheme.renderMs) << " ms";
            if (base0)
                std::cerr << " (brute force at --bounces 0: " << int(base0->brute().renderMs)
                          << " ms)";
            std::cerr << "\n";
        }

        if (opt.schemesOnly) {
            done.push_back(spec);
            continue;
        }
        // Progressive passes of the fastest default scheme available: error of each pass
        // against the final image, and the time since the first pass started.
        std::unique_ptr<Accelerator> best;
        for (SchemeKind k : {SchemeKind::Irregular, SchemeKind::Regular, SchemeKind::Brute}) {
            BuildParams b;
            b.scheme = k;
            try {
                best = buildAccelerator(scene, b);
                break;
            } catch (const std::invalid_argument&) {
            }
        }
        Image prog(ro.width, ro.height);
        double elapsed = 0.0;
        int prev = 0;
        for (int stride : ProgressiveRenderer::kDefaultStrides) {  // the viewer's passes
            RenderStats s = render(scene, *best, ro, prog, PassLattice{stride, prev});
            elapsed += s.renderMs;
            s.renderMs = elapsed;
            Image shown;  // what the viewer shows after this pass
            fillBlocks(prog, stride, shown);
            ImageError e = compareImages(ref, shown);
            // Speedup of the time to this pass, over brute force on the whole image.
            row(schemeName(best->params().scheme), "progressive pass", std::to_string(stride),
                best->info(), baseline->against(s), e);
            prev = stride;
        }
        done.push_back(spec);
    }
    std::ofstream(opt.outDir + "/report.csv") << csv.str();
    std::ofstream(opt.outDir + "/schemes.md") << table.str();
    std::cout << table.str() << "wrote " << opt.outDir << "/report.csv and schemes.md\n";
    if (opt.plots) {
        writePlots(opt.outDir, done);
        // A plot is drawn when the CSV has rows for its knob.
        const std::pair<const char*, const char*> plots[] = {
            {"speed_vs_error", ",scheme,"},
            {"regular_max_level", ",regular max-level,"},
            {"push_delta", ",push delta,"},
            {"offset", ",offset,"},
            {"progressive", ",progressive pass,"}};
        for (const auto& [name, knob] : plots) {
            if (csv.str().find(knob) == std::string::npos) continue;
            std::string cmd = "cd '" + opt.outDir + "' && gnuplot " + name + ".gp 2>/dev/null";
            if (std::system(cmd.c_str()) != 0)
                std::cerr << "warning: gnuplot failed on " << name
                          << ".gp (is gnuplot installed?)\n";
            else
                std::cout << "wrote " << opt.outDir << "/" << name << ".png\n";
        }
    }
    return 0;
}

}  // namespace lancer::bench
