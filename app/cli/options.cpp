#include "app/cli/options.h"

#include <cstdio>
#include <map>

namespace lancer::cli {

void addCommonOptions(CLI::App& app, CommonOptions& o) {
    static const std::map<std::string, SchemeKind> schemes = {{"brute", SchemeKind::Brute},
                                                              {"regular", SchemeKind::Regular},
                                                              {"irregular", SchemeKind::Irregular}};
    static const std::map<std::string, StepMethod> steps = {{"exact", StepMethod::Exact},
                                                            {"push", StepMethod::Push}};
    static const std::map<std::string, BspHeuristic> heuristics = {
        {"first", BspHeuristic::First},
        {"balanced", BspHeuristic::Balanced},
        {"fewest-cuts", BspHeuristic::FewestCuts}};

    app.add_option("--width", o.width, "Image width in pixels (default: the scene's)")
        ->check(CLI::Range(1, 16384));
    app.add_option("--height", o.height, "Image height in pixels (default: the scene's)")
        ->check(CLI::Range(1, 16384));
    app.add_option("--scheme", o.build.scheme, "Acceleration scheme: brute, regular or irregular")
        ->transform(CLI::CheckedTransformer(schemes, CLI::ignore_case)
                        .description("{brute, regular, irregular}"))
        ->default_str(schemeName(o.build.scheme));
    app.add_option("--max-level", o.build.maxLevel, "Deepest subdivision level")
        ->check(CLI::Range(0, 48))
        ->default_val(o.build.maxLevel);
    app.add_option("--max-objects", o.build.maxObjects,
                   "Stop subdividing at this many primitives per cell")
        ->check(CLI::Range(1, 1000000))
        ->default_val(o.build.maxObjects);
    app.add_option("--step", o.build.step, "Regular scheme's next-cell method: exact or push")
        ->transform(CLI::CheckedTransformer(steps, CLI::ignore_case).description("{exact, push}"))
        ->default_str("exact");
    app.add_option("--delta", o.build.delta,
                   "Push distance of --step push, relative to the scene size")
        ->check(CLI::Range(1e-15, 0.5))
        ->default_val(o.build.delta);
    app.add_option("--bsp-heuristic", o.build.heuristic,
                   "Irregular scheme's choice of splitting segment: first, balanced, fewest-cuts")
        ->transform(CLI::CheckedTransformer(heuristics, CLI::ignore_case)
                        .description("{first, balanced, fewest-cuts}"))
        ->default_str("balanced");
    static const std::map<std::string, SplitAxes> splitAxes = {{"cycle", SplitAxes::Cycle},
                                                               {"cost", SplitAxes::Cost}};
    app.add_option("--split-axes", o.build.splitAxes,
                   "Regular scheme's axis per BSP level: cycle (x, y, z in turn, the report's) or "
                   "cost (per level, the axis of least estimated cost)")
        ->transform(
            CLI::CheckedTransformer(splitAxes, CLI::ignore_case).description("{cycle, cost}"))
        ->default_str(splitAxesName(o.build.splitAxes));
    app.add_flag("--full-table", o.build.fullTable,
                 "Regular scheme: one full directory table instead of sub-tables");
    static const std::map<std::string, IrregularFrame> frames = {
        {"camera", IrregularFrame::Camera}, {"projective", IrregularFrame::Projective}};
    app.add_option("--irregular-frame", o.build.irregularFrame,
                   "Irregular scheme's structure for primary rays: camera (the camera-frame walk) "
                   "or projective (zones in screen x/z, y/z)")
        ->transform(
            CLI::CheckedTransformer(frames, CLI::ignore_case).description("{camera, projective}"))
        ->default_str(irregularFrameName(o.build.irregularFrame));
    app.add_flag("--no-mailbox{false}", o.build.mailboxes,
                 "Turn the mailboxes off (to measure their effect)");
    app.add_flag(
        "--no-light-buffer{false}", o.build.lightBuffer,
        "Accelerated schemes: trace shadow rays without the light buffer (to measure its effect)");
    app.add_option_function<std::string>(
           "--memory-budget",
           [&o](const std::string& v) { o.build.memoryBudget = parseMemoryBudget(v); },
           "Bytes a structure may take while it is built (512M, 2G, ...); over it the irregular "
           "scheme stops subdividing, the regular one is refused (default: an eighth of physical "
           "memory, " +
               formatBytes(defaultMemoryBudget()) + ")")
        ->check(CLI::Validator(
            [](std::string& v) {
                try {
                    parseMemoryBudget(v);
                    return std::string();
                } catch (const std::invalid_argument& e) {
                    return std::string(e.what());
                }
            },
            "SIZE"));
    app.add_option("--threads", o.render.threads, "Worker threads (0: all cores)")
        ->check(CLI::Range(0, 1024))
        ->default_val(0);
    app.add_option("--bounces", o.render.shading.bounces,
                   "Reflection/refraction depth; 0 = primary and shadow rays only")
        ->check(CLI::Range(0, 64))
        ->default_val(o.render.shading.bounces);
    app.add_option("--offset", o.render.shading.offsetScale,
                   "Secondary-ray origin offset, relative to the scene scale")
        ->check(CLI::Range(0.0, 1e-2))
        ->default_val(o.render.shading.offsetScale);
    app.add_flag("--no-shadows{false}", o.render.shading.shadows, "Trace no shadow rays");
    app.add_option("--stats", o.statsPath, "Write statistics as JSON to this file");
    app.add_option("--depth", o.depthPath, "Write the primary hit distances as a PFM to this file");
}

BuildControl buildProgressOnStderr() {
    BuildControl c;
    c.progress = [](const BuildProgress& p) {
        std::fprintf(stderr, "building: %s, %.0f s, %s of the %s memory budget, %zu so far\n",
                     p.stage, p.seconds, formatBytes(p.bytes).c_str(),
                     formatBytes(p.budget).c_str(), p.items);
    };
    return c;
}

void resolveSize(const CommonOptions& o, const Scene& scene, int& w, int& h) {
    w = scene.width;
    h = scene.height;
    if (o.width && o.height) {
        w = o.width;
        h = o.height;
    } else if (o.width) {
        h = std::max(1, int(std::lround(double(o.width) * scene.height / scene.width)));
        w = o.width;
    } else if (o.height) {
        w = std::max(1, int(std::lround(double(o.height) * scene.width / scene.height)));
        h = o.height;
    }
}

}  // namespace lancer::cli
