#include "app/bench/report.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include "app/bench/bench_rows.h"
#include "app/bench/embree_peer.h"
#include "app/bench/html_page.h"
#include "app/bench/image_error.h"
#include "app/bench/machine.h"
#include "app/bench/mesh_peer.h"
#include "app/bench/plots.h"
#include "app/bench/pov_peer.h"
#include "app/cli/param_table.h"
#include "engine/render/progressive.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "engine/scene/openscad_reader.h"

namespace lancer::bench {

namespace {

/// One point of a sweep: a knob set to a value.
struct Config {
    std::string knob, value;
    BuildParams build;
    ShadingOptions shading;
};

/// The schemes other than brute force that `wanted` keeps, in the table's order (every
/// SchemeKind, so that a scheme added to the table is measured without a change here).
std::vector<SchemeKind> accelerated(const std::function<bool(SchemeKind)>& wanted) {
    std::vector<SchemeKind> out;
    for (int k = 0; k < kSchemeCount; ++k)
        if (SchemeKind(k) != SchemeKind::Brute && wanted(SchemeKind(k)))
            out.push_back(SchemeKind(k));
    return out;
}

std::vector<Config> sweep(bool quick, bool schemesOnly,
                          const std::function<bool(SchemeKind)>& wanted) {
    std::vector<Config> out;
    auto add = [&](const std::string& knob, const std::string& value, BuildParams b,
                   ShadingOptions s = {}) {
        out.push_back({knob, value, b, s});
    };
    for (SchemeKind k : accelerated(wanted)) {
        BuildParams b;
        b.scheme = k;
        add("scheme", schemeName(k), b);
    }
    if (schemesOnly) return out;
    BuildParams regular;
    regular.scheme = SchemeKind::Regular;
    BuildParams irregular;
    irregular.scheme = SchemeKind::Irregular;
    const bool regularOn = wanted(SchemeKind::Regular), irregularOn = wanted(SchemeKind::Irregular);
    std::vector<int> levels =
        quick ? std::vector<int>{6, 12} : std::vector<int>{3, 6, 9, 12, 15, 18, 21, 24};
    if (regularOn)
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
        if (regularOn) add("regular max-objects", std::to_string(m), b);
        BuildParams c = irregular;
        c.irregular.maxObjects = m;
        if (irregularOn) add("irregular max-objects", std::to_string(m), c);
    }
    std::vector<double> deltas =
        quick ? std::vector<double>{1e-12, 1e-2}
              : std::vector<double>{1e-15, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3, 1e-2, 5e-2};
    if (regularOn)
        for (double d : deltas) {
            BuildParams b = regular;
            b.regular.step = StepMethod::Push;
            b.regular.delta = d;
            add("push delta", num(d), b);
        }
    if (irregularOn)
        for (BspHeuristic h :
             {BspHeuristic::First, BspHeuristic::Balanced, BspHeuristic::FewestCuts}) {
            BuildParams b = irregular;
            b.irregular.heuristic = h;
            add("bsp-heuristic", heuristicName(h), b);
        }
    if (regularOn) {
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
    }
    // The primitives' tests in double against float, in the regular scheme and in brute force
    // (where the tests are all the time): the speed single precision buys, against its depth
    // error (docs/benchmarks.md, "Float against double").
    for (Precision p : {Precision::Double, Precision::Float}) {
        ShadingOptions s;
        s.precision = p;
        const char* name = p == Precision::Float ? "float" : "double";
        if (regularOn) add("precision", name, regular, s);
        if (p == Precision::Float && wanted(SchemeKind::Brute))
            add("precision", name, BuildParams{}, s);
    }
    return out;
}

const char* kHeader =
    "scene,scheme,knob,value,build_ms,memory_bytes,regions,render_ms,speedup,rays,prim_tests_per_"
    "ray,region_visits_per_ray,mailbox_hits,walk_errors,hit_diff_pixels,color_diff_pixels,max_"
    "depth_diff,repeats,build_ms_min,build_ms_max,render_ms_min,render_ms_max,speedup_min,speedup_"
    "max,color_rmse,silhouette_diff_pixels,depth_rms,depth_p99,model_error,note\n";

/// A CSV field: quoted when it holds a comma or a quote.
std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

void writeCsvRow(std::ostream& csv, const BenchRow& r) {
    csv << csvField(r.scene) << "," << r.scheme << "," << csvField(r.knob) << ","
        << csvField(r.value) << ",";
    if (!r.measured()) {
        // Every figure empty, the reason last.
        for (int i = 0; i < 25; ++i) csv << ",";
        csv << csvField(r.note) << "\n";
        return;
    }
    const Spread b = spreadOf(r.buildMs), t = spreadOf(r.renderMs), s = spreadOf(r.speedup);
    const RayCounters& c = r.counters;
    const double rays = c.rays ? double(c.rays) : 1.0;
    auto opt = [](bool have, double v) { return have ? num(v) : std::string(); };
    const std::string none;
    // A peer has no structure of ours and no counters but its rays; POV-Ray's colours are not
    // compared (its shading is only near ours).
    csv << num(b.median) << "," << (r.peer ? none : std::to_string(r.info.memoryBytes)) << ","
        << (r.peer ? none : std::to_string(r.info.regions)) << "," << num(t.median) << ","
        << opt(s.count > 0, s.median) << "," << c.rays << ","
        << (r.peer ? none : num(double(c.primTests) / rays)) << ","
        << (r.peer ? none : num(double(c.regionVisits) / rays)) << ","
        << (r.peer ? none : std::to_string(c.mailboxHits)) << ","
        << (r.peer ? none : std::to_string(c.walkErrors)) << ",";
    if (r.compared)
        csv << r.error.hitDiff << ","
            << (r.colorCompared ? std::to_string(r.error.colorDiff) : none) << ","
            << num(r.error.maxDepthDiff);
    else
        csv << ",,";
    csv << "," << t.count << "," << num(b.min) << "," << num(b.max) << "," << num(t.min) << ","
        << num(t.max) << "," << opt(s.count > 0, s.min) << "," << opt(s.count > 0, s.max) << ","
        << (r.compared && r.colorCompared ? num(r.error.colorRmse) : none) << ","
        << (r.compared ? std::to_string(r.error.silhouetteDiff) : none) << ","
        << (r.compared ? num(r.error.rmsDepthDiff) : none) << ","
        << (r.compared ? num(r.error.p99DepthDiff) : none) << ","
        << (r.modelError >= 0.0 ? num(r.modelError) : none) << "," << csvField(r.csvNote()) << "\n";
}

using Clock = std::chrono::steady_clock;

}  // namespace

bool createOutDir(const std::string& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) std::cerr << "error: --out " << dir << ": " << ec.message() << "\n";
    return !ec;
}

int runBench(const BenchOptions& opt) {
    namespace fs = std::filesystem;
    if (opt.repeats < 1) {
        std::cerr << "error: --repeats " << opt.repeats << ": at least 1\n";
        return 2;
    }
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
    if (!createOutDir(opt.outDir)) return 2;
    // Before anything runs: the load average is the machine's, not ours.
    const RunInfo run = collectRunInfo(opt.commandLine);
    const auto runStart = Clock::now();
    const bool povray = PovPeer::available();
    int sceneIndex = 0;

    const bool openscad = MeshPeer::available();
    std::vector<int> meshFn = opt.meshFn;
    if (meshFn.empty())
        meshFn = opt.quick ? std::vector<int>{8, 16} : std::vector<int>{8, 16, 32, 64};
    auto listed = [](const std::vector<std::string>& v, const std::string& s) {
        return std::find(v.begin(), v.end(), s) != v.end();
    };
    std::vector<std::string> allScenes = opt.scenes;
    if (!opt.schemesOnly)
        for (const std::string& s : opt.meshScenes)
            if (!listed(allScenes, s)) allScenes.push_back(s);

    std::deque<BenchRow> rows;  // every row of every scene, in the order made (stable addresses)
    std::vector<std::string> done;
    for (const std::string& spec : allScenes) {
        ++sceneIndex;
        // A scene of --mesh-scenes only gets the mesh axis; one of --scenes every measure.
        const bool full = listed(opt.scenes, spec);
        const bool meshAxis = !opt.schemesOnly && withBrute && listed(opt.meshScenes, spec);
        Scene scene;
        try {
            scene = loadScene(spec, opt.read);
        } catch (const std::exception& e) {
            std::cerr << "error: " << e.what() << "\n";
            return 2;
        }
        RenderOptions ro;
        ro.width = opt.width;
        ro.height = opt.height;
        ro.threads = opt.threads;
        ro.shading.bounces = opt.bounces;
        const int w = ro.width, h = ro.height;

        // The jobs of this scene, each run once a round, every job in turn each round.
        std::vector<std::function<void(int)>> jobs;
        // Rows whose speedup is over a brute-force row's render of the same round.
        std::vector<std::pair<BenchRow*, const BenchRow*>> against;
        auto newRow = [&](const std::string& scheme, const std::string& knob,
                          const std::string& value) -> BenchRow& {
            rows.emplace_back();
            BenchRow& r = rows.back();
            r.scene = spec;
            r.scheme = scheme;
            r.knob = knob;
            r.value = value;
            return r;
        };
        auto record = [](BenchRow& row, const AccelInfo& info, const RenderStats& s, int round) {
            row.buildMs.push_back(info.buildMs);
            row.renderMs.push_back(s.renderMs);
            if (round == 0) {
                row.info = info;
                row.counters = s.counters;
            }
        };
        // Build `params` and render with `r`; the first round's image is compared with `ref`.
        auto schemeJob = [&](BenchRow& row, BuildParams params, RenderOptions r, const Image* ref) {
            jobs.push_back([&scene, &row, params, r, ref, w, h, record](int round) {
                if (!row.note.empty()) return;
                std::unique_ptr<Accelerator> accel;
                try {
                    accel = buildAccelerator(scene, params);
                } catch (const std::invalid_argument& e) {
                    row.note = std::string("skipped: ") + e.what();
                    return;
                }
                Image img(w, h);
                const RenderStats s = render(scene, *accel, r, img);
                record(row, accel->info(), s, round);
                if (round == 0 && ref) {
                    row.error = compareImages(*ref, img);
                    row.compared = true;
                }
            });
        };

        // The reference of this run. Without brute force, renders are timed alone, with no
        // speedup and no error.
        Image ref(w, h);
        BenchRow* bruteRow = nullptr;
        // Brute force's row under `knob` at `opts`: the reference, its first round's image into
        // `image`.
        auto bruteReference = [&](const std::string& knob, const RenderOptions& opts,
                                  Image& image) -> BenchRow* {
            BenchRow& row = newRow("brute", knob, "brute");
            row.inTable = true;
            row.compared = true;  // it is the reference: nothing differs
            against.push_back({&row, &row});
            jobs.push_back([&scene, &row, &image, opts, w, h, record](int round) {
                auto brute = buildAccelerator(scene, BuildParams{});
                Image scratch(round ? w : 0, round ? h : 0);
                const RenderStats s = render(scene, *brute, opts, round ? scratch : image);
                record(row, brute->info(), s, round);
            });
            return &row;
        };
        if (withBrute && full) bruteRow = bruteReference("scheme", ro, ref);
        for (const Config& c :
             full ? sweep(opt.quick, opt.schemesOnly, wanted) : std::vector<Config>{}) {
            BenchRow& row = newRow(schemeName(c.build.scheme), c.knob, c.value);
            row.inTable = c.knob == "scheme";
            if (bruteRow) against.push_back({&row, bruteRow});
            RenderOptions r = ro;
            r.shading.offsetScale = c.shading.offsetScale;
            r.shading.precision = c.shading.precision;
            schemeJob(row, c.build, r, bruteRow ? &ref : nullptr);
        }

        // A twisted extrusion's slices as a knob: the scene read again with each slice of
        // OpenSCAD's cut into 1 to 16 parts, rendered by the regular scheme against brute force
        // on the scene as read by default; model_error is each reading's stated bound.
        OpenScadCounts counts;
        if (full && !opt.schemesOnly && bruteRow && wanted(SchemeKind::Regular) &&
            spec.size() > 4 && spec.compare(spec.size() - 4, 4, ".csg") == 0) {
            readOpenScadFile(spec, &counts, opt.read);  // read above: it reads again
        }
        if (counts.twistedExtrudes > 0)
            for (int parts :
                 opt.quick ? std::vector<int>{1, 4} : std::vector<int>{1, 2, 4, 8, 16}) {
                BenchRow& row = newRow("regular", "twist parts", std::to_string(parts));
                against.push_back({&row, bruteRow});
                ReadOptions o = opt.read;
                o.twistParts = parts;
                auto variant = std::make_shared<Scene>(loadScene(spec, o));
                row.modelError = variant->modelError;
                BuildParams b;
                b.scheme = SchemeKind::Regular;
                jobs.push_back([variant, &row, b, r = ro, &ref, w, h, record](int round) {
                    auto accel = buildAccelerator(*variant, b);
                    Image img(w, h);
                    const RenderStats s = render(*variant, *accel, r, img);
                    record(row, accel->info(), s, round);
                    if (round == 0) {
                        row.error = compareImages(ref, img);
                        row.compared = true;
                    }
                });
            }

        // Against Embree, on union-only scenes, on primary and shadow rays (--bounces 0), with
        // every scheme of ours on the same workload.
        RenderOptions r0 = ro;
        r0.shading.bounces = 0;
        Image ref0(w, h);
        const std::string peer0 = "peer (bounces 0)";
        if (!full) {  // a scene of the mesh axis alone: no Embree row
        } else if (!EmbreePeer::available() || !EmbreePeer::supports(scene)) {
            BenchRow& row = newRow("embree", peer0, "embree");
            row.inTable = true;
            row.note = !EmbreePeer::available()
                           ? "not installed (this build has no Embree)"
                           : "not run: the scene has intersections or differences (Embree "
                             "traces unions of primitives)";
        } else {
            BenchRow* const brute0 = withBrute ? bruteReference(peer0, r0, ref0) : nullptr;
            for (SchemeKind k : accelerated(wanted)) {
                BenchRow& row = newRow(schemeName(k), peer0, schemeName(k));
                row.inTable = true;
                if (brute0) against.push_back({&row, brute0});
                BuildParams b;
                b.scheme = k;
                schemeJob(row, b, r0, brute0 ? &ref0 : nullptr);
            }
            BenchRow& row = newRow("embree", peer0, "embree");
            row.inTable = true;
            row.peer = true;
            if (brute0) against.push_back({&row, brute0});
            const bool compare = brute0 != nullptr;
            jobs.push_back([&scene, &row, &ref0, r0, w, h, compare, record](int round) {
                EmbreePeer peer(scene);
                Image img(w, h);
                const RenderStats s = peer.render(r0, img);
                AccelInfo info;
                info.buildMs = peer.buildMs();
                info.regions = 0;
                record(row, info, s, round);
                if (round == 0 && compare) {
                    row.error = compareImages(ref0, img);
                    row.compared = true;
                }
            });
        }

        // POV-Ray on the same scene, camera and bounces: its own trace time against our renders.
        const std::string peerN = "peer (bounces " + std::to_string(opt.bounces) + ")";
        if (full) {
            BenchRow& row = newRow("povray", peerN, "povray");
            row.inTable = true;
            row.peer = true;
            if (!povray) {
                row.note = "not installed (no povray on the PATH)";
            } else {
                if (bruteRow) against.push_back({&row, bruteRow});
                std::shared_ptr<PovPeer> pov;
                try {
                    pov = std::make_shared<PovPeer>(
                        scene, ro, opt.outDir, std::to_string(sceneIndex) + "-" + sceneSlug(spec));
                } catch (const std::exception& e) {
                    row.note = std::string("failed: ") + e.what();
                }
                if (pov)
                    jobs.push_back(
                        [pov, &row, &ref, compare = bruteRow != nullptr, record](int round) {
                            if (!row.note.empty()) return;
                            PovRun p = pov->render(round == 0 && compare ? &ref : nullptr);
                            if (!p.failure.empty()) {
                                row.note = "failed: " + p.failure;
                                return;
                            }
                            AccelInfo info;
                            info.buildMs = p.parseMs;
                            info.regions = 0;
                            RenderStats s;
                            s.renderMs = p.traceMs;
                            s.counters.rays = p.rays;
                            record(row, info, s, round);
                            row.wallMs.push_back(p.wallMs);
                            if (round == 0 && p.compared) {
                                row.error = p.error;
                                row.compared = true;
                                row.errorNote = p.errorNote;
                                row.colorCompared = false;
                            }
                        });
            }
        }

        // Exact CSG against the mesh an OpenSCAD user would trace: OpenSCAD's CGAL render of the
        // same model at each $fn, traced by Embree, against every scheme's exact image, all at
        // --bounces 0 and compared with brute force by their surfaces.
        Image refMesh(meshAxis ? w : 0, meshAxis ? h : 0);
        if (meshAxis) {
            const std::string knob = "mesh (bounces 0)";
            BenchRow* const base = bruteReference(knob, r0, refMesh);
            base->inTable = false;  // the table's brute force is the scene's own
            for (SchemeKind k : accelerated(wanted)) {
                BenchRow& row = newRow(schemeName(k), knob, "exact");
                against.push_back({&row, base});
                BuildParams b;
                b.scheme = k;
                schemeJob(row, b, r0, &refMesh);
            }
            std::shared_ptr<MeshPeer> model;
            std::string why = !openscad ? "not installed (no openscad on the PATH)"
                              : !EmbreePeer::available()
                                  ? "not run: this build has no Embree to trace the mesh"
                                  : "";
            if (why.empty()) try {
                    model = std::make_shared<MeshPeer>(
                        scene, opt.outDir, std::to_string(sceneIndex) + "-" + sceneSlug(spec));
                } catch (const std::invalid_argument& e) {
                    why = std::string("not run: ") + e.what();
                }
            for (int fn : meshFn) {
                BenchRow& row = newRow("openscad", knob, "$fn " + std::to_string(fn));
                row.peer = true;
                row.note = why;
                if (!model) continue;
                against.push_back({&row, base});
                auto mesh = std::make_shared<Scene>();
                auto meshMs = std::make_shared<double>(0.0);
                jobs.push_back([model, mesh, meshMs, fn, &row, &refMesh, r0, w, h, record,
                                timeout = opt.meshTimeout](int round) {
                    if (!row.note.empty()) return;
                    if (round == 0) {
                        // Meshed once: CGAL takes seconds to minutes, the same each time.
                        const MeshRun m = model->mesh(fn, timeout);
                        if (!m.failure.empty()) {
                            row.note = "failed: " + m.failure;
                            return;
                        }
                        const auto t0 = Clock::now();
                        *mesh = readStl(m.stl, *model->scene());
                        *meshMs =
                            m.meshMs +
                            std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
                        row.errorNote =
                            "OpenSCAD's mesh, " + std::to_string(mesh->prims.size()) +
                            " triangles (its CGAL render and reading: " + fixed(*meshMs, 0) +
                            " ms, in build_ms with Embree's build); hits compared by "
                            "surface: silhouette and distance";
                    }
                    EmbreePeer peer(*mesh);
                    Image img(w, h);
                    const RenderStats s = peer.render(r0, img);
                    AccelInfo info;
                    info.buildMs = *meshMs + peer.buildMs();
                    info.regions = 0;
                    record(row, info, s, round);
                    if (round == 0) {
                        row.error = compareSurfaces(refMesh, img);
                        row.compared = true;
                        row.colorCompared = false;  // flat facets shade otherwise, as meant
                    }
                });
            }
        }

        // Progressive passes of the command line's default scheme: error of each pass against
        // the brute-force image, and the time since the first pass started.
        if (!opt.schemesOnly && bruteRow && full) {
            std::vector<BenchRow*> passes;
            BuildParams b;
            b.scheme = cli::Knobs{}.build.scheme;
            for (int stride : ProgressiveRenderer::kDefaultStrides) {  // the viewer's passes
                BenchRow& row =
                    newRow(schemeName(b.scheme), "progressive pass", std::to_string(stride));
                against.push_back({&row, bruteRow});
                passes.push_back(&row);
            }
            jobs.push_back([&scene, passes, b, ro, &ref, w, h, record](int round) {
                auto accel = buildAccelerator(scene, b);
                Image prog(w, h);
                double elapsed = 0.0;
                int prev = 0, i = 0;
                for (int stride : ProgressiveRenderer::kDefaultStrides) {
                    RenderStats s = render(scene, *accel, ro, prog, PassLattice{stride, prev});
                    elapsed += s.renderMs;
                    s.renderMs = elapsed;
                    record(*passes[size_t(i)], accel->info(), s, round);
                    if (round == 0) {
                        Image shown;  // what the viewer shows after this pass
                        fillBlocks(prog, stride, shown);
                        passes[size_t(i)]->error = compareImages(ref, shown);
                        passes[size_t(i)]->compared = true;
                    }
                    prev = stride;
                    ++i;
                }
            });
        }

        // A small warm-up render starts the thread pool; then the rounds.
        {
            auto brute = buildAccelerator(scene, BuildParams{});
            Image warm(w, h);
            render(scene, *brute, ro, warm, PassLattice{16, 0});
        }
        const auto sceneStart = Clock::now();
        for (int round = 0; round < opt.repeats; ++round) {
            for (auto& job : jobs) {
                try {
                    job(round);
                } catch (const std::exception& e) {
                    std::cerr << spec << ": error: " << e.what() << "\n";
                    return 1;
                }
            }
            std::cerr << spec << ": round " << round + 1 << " of " << opt.repeats << " done ("
                      << num(std::round(
                                 std::chrono::duration<double>(Clock::now() - sceneStart).count() *
                                 10.0) /
                             10.0)
                      << " s)\n";
        }
        for (auto& [row, base] : against) {
            if (!row->measured() || !base->measured()) continue;
            const size_t n = std::min(row->renderMs.size(), base->renderMs.size());
            for (size_t i = 0; i < n; ++i)
                if (row->renderMs[i] > 0.0)
                    row->speedup.push_back(base->renderMs[i] / row->renderMs[i]);
        }
        for (const BenchRow& r : rows) {
            if (r.scene != spec) continue;
            const Spread t = spreadOf(r.renderMs);
            std::cerr << spec << ": " << r.label() << ": "
                      << (r.measured()
                              ? num(std::round(t.median)) + " ms (" + num(std::round(t.min)) + "-" +
                                    num(std::round(t.max)) + ")"
                              : r.note)
                      << "\n";
        }
        done.push_back(spec);
    }

    std::ostringstream csv;
    csv << kHeader;
    for (const BenchRow& r : rows) writeCsvRow(csv, r);
    const std::string table = comparisonMarkdown(rows);
    std::ofstream(opt.outDir + "/report.csv") << csv.str();
    std::ofstream(opt.outDir + "/schemes.md") << table;
    std::cout << table << "wrote " << opt.outDir << "/report.csv and schemes.md\n";
    std::vector<Figure> figures;
    if (opt.plots) {
        figures = drawPlots(opt.outDir, rows, done, opt.html ? PlotFormat::Svg : PlotFormat::Png);
        for (const Figure& f : figures)
            if (f.drawn)
                std::cout << "wrote " << opt.outDir << "/" << f.file << "\n";
            else
                std::cerr << "warning: " << f.name << ": " << f.why << "\n";
    }
    if (opt.html) {
        PageSettings settings;
        settings.width = opt.width;
        settings.height = opt.height;
        settings.threads = effectiveThreads(opt.threads);
        settings.bounces = opt.bounces;
        settings.repeats = opt.repeats;
        settings.quick = opt.quick;
        settings.schemesOnly = opt.schemesOnly;
        settings.seconds = std::chrono::duration<double>(Clock::now() - runStart).count();
        settings.peers.push_back(EmbreePeer::available()
                                     ? "Embree 3 (in this build), on scenes that are a union of "
                                       "primitives, at --bounces 0"
                                     : "Embree: not installed (this build has no Embree)");
        settings.peers.push_back(povray ? PovPeer::version() + " (" + PovPeer::executable() +
                                              "), on every scene, at --bounces " +
                                              std::to_string(opt.bounces) +
                                              ": its parse and trace times"
                                        : "POV-Ray: not installed (no povray on the PATH)");
        if (!opt.schemesOnly)
            settings.peers.push_back(openscad
                                         ? MeshPeer::version() + " (" + MeshPeer::executable() +
                                               "), meshing the mesh axis' scenes, traced "
                                               "by Embree"
                                         : "OpenSCAD: not installed (no openscad on the "
                                           "PATH)");
        const std::string page = opt.outDir + "/index.html";
        if (!writeHtmlPage(page, run, settings, rows, figures)) {
            std::cerr << "error: could not write " << page << "\n";
            return 1;
        }
        std::cout << "wrote " << page << "\n";
    }
    return 0;
}

}  // namespace lancer::bench
