// lancer: CSG ray tracing with the space subdivisions of Arnaldi, Priol and Bouatouch (1986).
#include <CLI/CLI.hpp>
#include <cctype>
#include <iostream>

#include "app/bench/report.h"
#include "app/bench/scale.h"
#include "app/cli/commands.h"
#include "engine/accel/build_guard.h"
#include "engine/scene/builtin_scenes.h"
#include "engine/scene/loader.h"
#include "engine/util/kept_memory.h"
#ifdef LANCER_WITH_VIEWER
#include "app/viewer/compare/rebuild_diff.h"
#include "app/viewer/overlay/overlays.h"
#include "app/viewer/window.h"
#endif

using namespace lancer;

namespace {
constexpr const char* kSceneHelp =
    "Scene: a .json, .nff or .csg (OpenSCAD's CSG export) file, or builtin:NAME[:SIZE]";
}  // namespace

int main(int argc, char** argv) {
    // Freed blocks (a bench's repeated builds, the viewer's images and textures) reused, not
    // mapped afresh: each fresh page is a page fault (engine/util/kept_memory.h).
    keepFreedMemory();
    CLI::App app{
        "lancer: see and measure how space subdivision accelerates ray tracing of CSG solids"};
    app.require_subcommand(0, 1);
    std::string builtins = "Built-in scenes:";
    for (const BuiltinInfo& b : builtinScenes())
        builtins += std::string("\n  builtin:") + b.name +
                    (b.maxSize > b.minSize ? "[:SIZE]" : "") + "  " + b.description;
    app.footer(builtins);

    cli::CommonOptions viewOpt, renderOpt, traceOpt, structureOpt;
    std::string viewOut = "lancer-view.png";
    CLI::App* view = app.add_subcommand(
        "view", "Open the viewer (the default); without a display, render headless");
    view->add_option("scene", viewOpt.scene, kSceneHelp);
    view->add_option("--headless-output", viewOut,
                     "Where the headless render goes when there is no display");
    cli::addCommonOptions(*view, viewOpt);
#ifdef LANCER_WITH_VIEWER
    viewer::ViewOptions vopt;
    CLI::Option* frames =
        view->add_option("--frames", vopt.frames,
                         "Run this many frames, wait for the render to finish, then exit")
            ->check(CLI::Range(1, 1000000));
    CLI::Option* screenshot =
        view->add_option("--screenshot", vopt.screenshot,
                         "With --frames: save the window (PNG or JPEG) before exiting; without a "
                         "display, the headless render goes there")
            ->needs(frames);
    view->add_flag("--hide-panels", vopt.hidePanels,
                   "Start with the panels hidden (Tab shows and hides them)");
    view->add_flag("--log-timings", vopt.logTimings,
                   "Print the latency of each pass after a change to stderr, and at the end "
                   "the frame times (p50, p95, max) since the structure was ready");
    view->add_option("--orbit", vopt.orbit,
                     "With --frames: once the structure is ready, turn the camera DEG degrees "
                     "about its target in each of the first --frames frames, as a drag does")
        ->check(CLI::Range(-180.0, 180.0))
        ->needs(frames);
    view->add_flag("--replay-change", vopt.replayChange,
                   "After the first complete image, rebuild the structure once, as a parameter "
                   "change does (to time it)");
    view->add_flag("--continuous", vopt.continuous,
                   "Redraw every frame, as while the user interacts (to measure the UI's frame "
                   "rate under load)");
    view->add_option("--drop", vopt.drop,
                     "After the first complete image, hand FILE to the window's drop handler, as "
                     "the desktop does "
                     "when a file is dropped on the window")
        ->needs(frames);
    view->add_option("--show", vopt.show,
                     "Layers drawn, a comma list of bsp, zones, slabs, leaves, grid, visits, "
                     "tests, boxes, frustum, inspector, ray, visited, worst, tree, none")
        ->check([](const std::string& list) {
            viewer::overlay::OverlayOptions o;
            try {
                viewer::overlay::applyShowList(list, o);
            } catch (const std::invalid_argument& e) {
                return std::string(e.what());
            }
            return std::string();
        });
    view->add_option("--view", vopt.view,
                     "What the image shows: color, or the heat map of prim_tests, region_visits "
                     "or time per pixel")
        ->check([](const std::string& w) {
            return viewer::viewModeOf(w) ? std::string()
                                         : "expected color, prim_tests, region_visits or time";
        });
    view->add_option("--ab", vopt.ab,
                     "With a heat map, after a rebuild: new (the new structure's counter), old "
                     "(the old one's) or diff (old minus new, per pixel)")
        ->check([](const std::string& w) {
            return viewer::compare::abViewOf(w) ? std::string() : "expected new, old or diff";
        });
    view->add_option("--change", vopt.change,
                     "After the first complete image, change parameters as the Parameters panel "
                     "does: a comma list of NAME=VALUE (max-level=16,max-objects=2)")
        ->check([](const std::string& list) {
            cli::Knobs k;
            try {
                cli::applyAssignments(list, k);
            } catch (const std::invalid_argument& e) {
                return std::string(e.what());
            }
            return std::string();
        });
    view->add_option("--select", vopt.select,
                     "Select region ID once the structure is built (its Selection panel, its "
                     "highlight)")
        ->check(CLI::NonNegativeNumber);
    view->add_option("--ini", vopt.ini,
                     "Settings file (default: ~/.config/lancer/imgui.ini; \"none\": none)");
    // Ray playback (docs/design.md section 6, "Scripted views"). `--step` is the common option's
    // next-cell method (a word) or, with --pick, the playback step to stop at (a number).
    std::vector<int> pickXY;
    CLI::Option* pickOpt =
        view->add_option("--pick", pickXY, "Pick pixel X Y (y = 0 on the top row): its ray tree")
            ->expected(2);
    view->add_option("--ray", vopt.pickRay, "With --pick: the ray of the tree played (0: primary)")
        ->check(CLI::Range(0, 1000000))
        ->needs(pickOpt);
    view->remove_option(view->get_option("--step"));
    std::string stepArg;
    view->add_option("--step", stepArg,
                     "Two meanings. Without --pick: the regular scheme's next-cell method, exact "
                     "or push. With --pick: the playback step to stop at, first, last or N (from "
                     "0, the ray's first region)");
#endif

    std::string out;
    bool quiet = false;
    CLI::App* render = app.add_subcommand("render", "Render a scene to a PNG or JPEG");
    render->add_option("scene", renderOpt.scene, kSceneHelp)->required();
    render->add_option("-o,--output", out, "Output image: .png, .jpg or .jpeg")->required();
    render->add_flag("-q,--quiet", quiet, "Print nothing on success");
    cli::addCommonOptions(*render, renderOpt);

    cli::TraceOptions topt;
    CLI::App* trace = app.add_subcommand(
        "trace",
        "Trace one pixel's rays (primary, shadow, reflected, refracted) and print their walks");
    trace->add_option("scene", traceOpt.scene, kSceneHelp)->required();
    std::vector<int> pixel;
    trace->add_option("--pixel", pixel, "Pixel X Y (y = 0 on the top row)")
        ->expected(2)
        ->required();
    trace->add_flag("--json", topt.json, "Machine-readable output");
    cli::addCommonOptions(*trace, traceOpt);

    cli::StructureOptions sopt;
    CLI::App* structure = app.add_subcommand(
        "structure", "Write the built structure as JSON (regions, zones, slabs)");
    structure->add_option("scene", structureOpt.scene, kSceneHelp)->required();
    structure->add_option("-o,--output", sopt.output, "Output JSON")->required();
    structure->add_flag("--all", sopt.all, "List every region even beyond a million (else counts)");
    structure->add_flag("-q,--quiet", sopt.quiet, "Print nothing on success");
    cli::addCommonOptions(*structure, structureOpt);

    cli::CommonOptions exportOpt;
    cli::ExportOptions eopt;
    CLI::App* exportCmd = app.add_subcommand(
        "export", "Write the scene for another renderer (POV-Ray 3.7, OpenSCAD)");
    exportCmd->add_option("scene", exportOpt.scene, kSceneHelp)->required();
    exportCmd->add_option(
        "--pov", eopt.pov,
        "POV-Ray 3.7 scene: the same camera (each pixel's ray through its centre), "
        "primitives, CSG and, roughly, materials and lights");
    exportCmd->add_option("--scad", eopt.scad,
                          "OpenSCAD model: the primitives and CSG, curved ones faceted at --fn "
                          "segments a circle (OpenSCAD's render of it is the mesh it would trace)");
    exportCmd->add_option("--fn", eopt.fn, "$fn of the OpenSCAD model")
        ->check(CLI::Range(3, 100000))
        ->default_val(32);
    exportCmd->add_flag("--pov-depth", eopt.depth,
                        "Surfaces emit their primary hit distance as grey, 1 - distance / range "
                        "(render with +FN16 File_Gamma=1.0): POV-Ray's depth image");
    exportCmd->add_flag("-q,--quiet", eopt.quiet, "Print nothing on success");
    cli::addCommonOptions(*exportCmd, exportOpt);

    // A value given twice takes the last, so scripts' defaults can be overridden after them.
    bench::BenchOptions bopt;
    CLI::App* benchCmd =
        app.add_subcommand("bench", "Write the speed-against-error report (CSV and plots)");
    benchCmd->add_option("--scenes", bopt.scenes, "Scenes to measure")->capture_default_str();
    benchCmd->add_option("--width", bopt.width, "Image width")
        ->check(CLI::Range(1, 16384))
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd->add_option("--height", bopt.height, "Image height")
        ->check(CLI::Range(1, 16384))
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd->add_option("--threads", bopt.threads, "Worker threads (0: all cores)")
        ->check(CLI::Range(0, 1024))
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd->add_option("--bounces", bopt.bounces, "Reflection/refraction depth")
        ->check(CLI::Range(0, 64))
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd->add_option("--out", bopt.outDir, "Output directory")
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    std::string reportDir;
    bool noMesh = false;
    benchCmd->add_option("--report", reportDir,
                         "Write DIR/index.html, one self-contained page (plots inline as SVG), "
                         "beside the CSV in DIR (instead of --out)");
    benchCmd
        ->add_option("--repeats", bopt.repeats,
                     "Runs of each configuration, in turn (round-robin); figures are medians "
                     "with their range")
        ->check(CLI::Range(1, 1000))
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd
        ->add_option("--mesh-scenes", bopt.meshScenes,
                     "Scenes of the mesh axis: exact CSG against OpenSCAD's mesh of it traced by "
                     "Embree (none: --no-mesh)")
        ->capture_default_str();
    benchCmd->add_flag("--no-mesh", noMesh, "No mesh axis");
    benchCmd
        ->add_option("--mesh-fn", bopt.meshFn,
                     "The meshes' $fn (default 8 16 32 64; --quick: 8 16)")
        ->check(CLI::Range(3, 4096));
    benchCmd->add_option("--mesh-timeout", bopt.meshTimeout, "Seconds an openscad run may take")
        ->check(CLI::Range(1.0, 86400.0))
        ->capture_default_str();
    benchCmd->add_flag("--quick", bopt.quick, "Fewer knob values (a smoke run)");
    benchCmd
        ->add_option_function<std::string>(
            "--facets",
            [&bopt](const std::string& v) {
                bopt.read.facets = v == "openscad" ? Facets::OpenScad : Facets::Exact;
            },
            "Round shapes of .csg scenes: exact, or openscad (OpenSCAD's polygons and polyhedra "
            "by $fn, $fa, $fs)")
        ->transform(CLI::IsMember({"exact", "openscad"}));
    benchCmd->add_flag("--no-plots{false}", bopt.plots, "Write the CSV only");
    benchCmd->add_flag("--schemes-only", bopt.schemesOnly,
                       "Each scheme at its defaults, and the peer: the comparison table");
    benchCmd
        ->add_option("--schemes", bopt.schemes,
                     "Schemes measured; without brute (--schemes-only or --scale only) no speedup "
                     "or error")
        ->check(CLI::IsMember(schemeNames()))
        ->capture_default_str();
    bool scale = false;
    std::string memoryLimit = "4G", memoryBudget = "0";
    bench::ScaleOptions scaleOpt;
    benchCmd->add_flag("--scale", scale,
                       "The scale table: each scheme at its defaults in a child process (peak "
                       "memory, limits, hits against brute force); see docs/scale.md");
    benchCmd->add_flag("--scene-size", scaleOpt.sceneSize,
                       "--scale: each scene's own image size instead of --width x --height");
    benchCmd
        ->add_option("--time-limit", scaleOpt.timeLimitS,
                     "--scale: seconds a scheme may take to load, build and render")
        ->check(CLI::PositiveNumber)
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd
        ->add_option("--memory-limit", memoryLimit,
                     "--scale: peak resident memory a scheme may take (K, M, G, T)")
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd
        ->add_option("--brute-limit", scaleOpt.bruteLimitS,
                     "--scale: seconds over which brute force renders a lattice of pixels")
        ->check(CLI::PositiveNumber)
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd
        ->add_option("--kill-after", scaleOpt.killAfterS,
                     "--scale: seconds after which a child is killed (0: twice --time-limit, at "
                     "least --brute-limit + 60)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd
        ->add_option("--memory-budget", memoryBudget,
                     "--scale: the builds' --memory-budget (0: an eighth of physical memory)")
        ->capture_default_str()
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    benchCmd->add_flag("--no-peer{false}", scaleOpt.peer,
                       "--scale: without Embree (measured only at --bounces 0, on scenes that are "
                       "a union of primitives)");

    // The README's option section, generated from the parameter table.
    CLI::App* helpOptions = app.add_subcommand(
        "help-options", "Print the common options as a Markdown table (README's options section)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help prints and succeeds; every other parse error names the option and exits 2.
        if (e.get_exit_code() == 0) return app.exit(e);
        std::cerr << cli::parseErrorMessage(app, e, std::vector<std::string>(argv + 1, argv + argc))
                  << "\n";
        return 2;
    }

    if (*helpOptions) {
        std::cout << cli::optionsMarkdown();
        return 0;
    }

    if (*benchCmd && scale) {
        scaleOpt.scenes = bopt.scenes;
        scaleOpt.width = bopt.width;
        scaleOpt.height = bopt.height;
        scaleOpt.threads = bopt.threads;
        scaleOpt.bounces = bopt.bounces;
        scaleOpt.outDir = bopt.outDir;
        scaleOpt.schemes = bopt.schemes;
        // Sizes as --memory-budget takes them, the error naming the option given.
        auto size = [](const char* option, const std::string& text, bool zero) -> size_t {
            if (zero && text == "0") return 0;
            try {
                return parseMemoryBudget(text);
            } catch (const std::invalid_argument&) {
                throw std::invalid_argument(std::string(option) + " " + text +
                                            ": expected a size such as 512M, 2G or 1.5GiB");
            }
        };
        try {
            scaleOpt.memoryLimit = size("--memory-limit", memoryLimit, false);
            scaleOpt.memoryBudget = size("--memory-budget", memoryBudget, true);
        } catch (const std::invalid_argument& e) {
            std::cerr << "error: " << e.what() << "\n";
            return 2;
        }
        return bench::runScale(scaleOpt);
    }
    if (*benchCmd) {
        if (!reportDir.empty()) {
            bopt.outDir = reportDir;
            bopt.html = true;
        }
        if (noMesh) bopt.meshScenes.clear();
        bopt.commandLine.assign(argv, argv + argc);
        return bench::runBench(bopt);
    }

    if (*render) return cli::runRender(renderOpt, out, quiet);
    if (*exportCmd) return cli::runExport(exportOpt, eopt);
    if (*structure) return cli::runStructure(structureOpt, sopt);
    if (*trace) {
        topt.x = pixel[0];
        topt.y = pixel[1];
        return cli::runTrace(traceOpt, topt);
    }
    // view (explicit or default): the window when there is a display, else a headless render.
    std::string why = "the interactive viewer is not available in this build";
    // A missing file or a directory is refused before any window opens.
    if (view->count("scene")) {
        try {
            checkSceneFile(viewOpt.scene);
        } catch (const SceneError& e) {
            std::cerr << "error: " << e.what() << "\n";
            return 2;
        }
    }
#ifdef LANCER_WITH_VIEWER
    bool stepIsMethod = false;
    if (!stepArg.empty()) {
        std::string lower;
        for (char c : stepArg) lower += char(std::tolower(static_cast<unsigned char>(c)));
        const bool number =
            stepArg.find_first_not_of("0123456789") == std::string::npos && stepArg.size() < 10;
        if (lower == "exact" || lower == "push") {
            viewOpt.knobs.build.regular.step =
                lower == "exact" ? StepMethod::Exact : StepMethod::Push;
            stepIsMethod = true;
        } else if (number || lower == "first" || lower == "last") {
            if (pickXY.empty()) {
                std::cerr << "error: --step " << stepArg
                          << ": a playback step (first, last or N) needs --pick X Y; without "
                             "it --step is the next-cell method, exact or push\n";
                return 2;
            }
            vopt.pickStep = lower == "last" ? viewer::kLastStep : number ? std::stoi(stepArg) : 0;
        } else {
            std::cerr << "error: --step " << stepArg
                      << ": expected exact or push (the next-cell method), or with --pick a "
                         "playback step: first, last or N\n";
            return 2;
        }
    }
    if (view->count("--ab") && !view->count("--change")) {
        std::cerr << "error: --ab " << vopt.ab
                  << ": the A/B compares the images before and after a rebuild; it needs "
                     "--change NAME=VALUE\n";
        return 2;
    }
    // A layer of another scheme is refused here when --scheme is given (else the viewer checks
    // it against the saved scheme).
    if (view->count("--show") && view->count("--scheme")) {
        if (std::string why =
                viewer::overlay::showListMismatch(vopt.show, viewOpt.knobs.build.scheme);
            !why.empty()) {
            std::cerr << "error: " << why << "\n";
            return 2;
        }
    }
    if (!pickXY.empty()) {
        if (pickXY[0] < 0 || pickXY[1] < 0) {
            std::cerr << "error: --pick " << pickXY[0] << " " << pickXY[1]
                      << ": pixel coordinates are not negative\n";
            return 2;
        }
        vopt.pick = {pickXY[0], pickXY[1]};
    }
    auto given = [&](const std::string& name) {
        return name == "--step" ? stepIsMethod : view->count(name) > 0;
    };
    if (int status = viewer::runViewer(viewOpt, vopt, given, why); status != viewer::kNoDisplay)
        return status;
#endif
#ifdef LANCER_WITH_VIEWER
    // A screenshot asked of the window is what the headless render stands for.
    if (*screenshot && view->count("--headless-output") == 0) viewOut = vopt.screenshot;
#endif
    std::cout << "lancer: " << why << "; rendering " << viewOpt.scene << " headless.\n";
    return cli::runRender(viewOpt, viewOut, false);
}
