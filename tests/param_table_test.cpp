// The parameter table (app/cli/param_table.h): every command-line option reaches the viewer or
// is marked batch-only, a knob of one scheme never rebuilds another, the ranges are the table's
// on the command line and in the ini, README's option section is the table's, and --camera
// reads what the viewer's Copy JSON writes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "app/cli/options.h"
#include "engine/render/renderer.h"
#include "engine/scene/loader.h"
#include "engine/scene/scene.h"

namespace lancer::cli {
namespace {

/// A value of `d` other than the one in `k`, inside its range.
void changeValue(const ParamDesc& d, Knobs& k) {
    switch (d.kind) {
        case ParamKind::Int:
        case ParamKind::Real: {
            double v = d.get(k);
            d.set(k, v == d.lo ? d.hi : d.lo);
            break;
        }
        case ParamKind::Enum:
            d.set(k, double((size_t(d.get(k)) + 1) % d.names.size()));
            break;
        case ParamKind::Switch:
            d.set(k, d.get(k) != 0.0 ? 0.0 : 1.0);
            break;
        case ParamKind::Size:
            d.set(k, d.get(k) != 0.0 ? 0.0 : double(size_t(1) << 30));
            break;
        case ParamKind::Path:
            (k.*d.path) += "x";
            break;
    }
}

/// A subcommand as main.cpp makes one, parsed from `args`.
struct Parsed {
    CLI::App app{"lancer"};
    CommonOptions o;
    std::string error;
    explicit Parsed(std::vector<std::string> args) {
        CLI::App* render = app.add_subcommand("render", "");
        render->add_option("scene", o.scene);
        addCommonOptions(*render, o);
        std::vector<std::string> reversed(args.rbegin(), args.rend());
        try {
            app.parse(reversed);
        } catch (const CLI::ParseError& e) {
            error = parseErrorMessage(app, e, args);
        }
    }
};

TEST(ParamTable, EveryOptionHasAnIniKeyAndAControlOrIsBatchOnly) {
    std::set<std::string> flags, keys;
    for (const ParamDesc& d : paramTable()) {
        SCOPED_TRACE(d.flag);
        EXPECT_TRUE(flags.insert(d.flag).second) << "flag twice";
        switch (d.reach) {
            case ViewerReach::Panel:
                ASSERT_NE(d.iniKey, nullptr);
                EXPECT_TRUE(d.label && *d.label);
                EXPECT_NE(d.kind, ParamKind::Path) << "a panel control edits a value";
                EXPECT_NE(d.effect, ChangeEffect::None) << "a panel change must do something";
                break;
            case ViewerReach::Window:
                ASSERT_NE(d.iniKey, nullptr);
                break;
            case ViewerReach::Startup:
            case ViewerReach::BatchOnly:
                EXPECT_EQ(d.iniKey, nullptr) << "a file is not a setting to remember";
                break;
        }
        if (d.iniKey) {
            EXPECT_TRUE(keys.insert(d.iniKey).second) << "ini key twice";
        }
        if (d.kind != ParamKind::Path) {
            EXPECT_TRUE(d.get && d.set);
        } else {
            EXPECT_NE(d.path, nullptr);
        }
        if (d.kind == ParamKind::Enum) {
            EXPECT_GE(d.names.size(), 2u);
        }
    }
    // Every option the command line registers is an entry of the table.
    Parsed p({"render", "builtin:default"});
    const CLI::App* render = p.app.get_subcommand("render");
    size_t options = 0;
    for (const CLI::Option* opt : render->get_options()) {
        for (const std::string& n : opt->get_lnames()) {
            if (n == "help") continue;
            ++options;
            EXPECT_NE(findParam("--" + n), nullptr) << "--" << n << " is not in the table";
        }
    }
    EXPECT_EQ(options, paramTable().size());
}

TEST(ParamTable, AKnobOfOneSchemeNeverRebuildsAnother) {
    size_t checked = 0;
    for (const ParamDesc& d : paramTable()) {
        if (d.reach != ViewerReach::Panel || d.effect != ChangeEffect::Rebuild) continue;
        for (int s = 0; s < kSchemeCount; ++s) {
            SCOPED_TRACE(std::string(d.flag) + " under " + schemeName(SchemeKind(s)));
            Knobs before;
            before.build.scheme = SchemeKind(s);
            before.build.regular.step = StepMethod::Push;  // so that --delta is read
            Knobs after = before;
            changeValue(d, after);
            ASSERT_NE(d.get(before), d.get(after));
            const bool reads = (d.schemes & schemeBit(SchemeKind(s))) != 0;
            EXPECT_EQ(changeEffect(before, after),
                      reads ? ChangeEffect::Rebuild : ChangeEffect::None);
            EXPECT_EQ(applies(d, after), reads);
            ++checked;
        }
    }
    EXPECT_GE(checked, 3u * 10u);
    // The cases a user met: the irregular scheme rebuilt on a change of step, and showed a
    // max-level it ignores; delta is read only with --step push.
    Knobs irregular;
    irregular.build.scheme = SchemeKind::Irregular;
    Knobs changed = irregular;
    changed.build.regular.step = StepMethod::Push;
    changed.build.regular.maxLevel = 3;
    EXPECT_EQ(changeEffect(irregular, changed), ChangeEffect::None);
    EXPECT_FALSE(applies(*findParam("--max-level"), irregular));
    Knobs exact;
    changed = exact;
    changed.build.regular.delta = 1e-3;
    EXPECT_EQ(changeEffect(exact, changed), ChangeEffect::None);
    EXPECT_FALSE(applies(*findParam("--delta"), exact));
    // A rendering knob re-renders under every scheme; the scheme itself always rebuilds.
    changed = irregular;
    changed.shading.bounces = 1;
    EXPECT_EQ(changeEffect(irregular, changed), ChangeEffect::Rerender);
    changed = irregular;
    changed.build.scheme = SchemeKind::Brute;
    EXPECT_EQ(changeEffect(irregular, changed), ChangeEffect::Rebuild);
}

TEST(ParamTable, RangesAreTheSameOnTheCommandLineAndInTheIni) {
    for (const ParamDesc& d : paramTable()) {
        if (d.kind != ParamKind::Int && d.kind != ParamKind::Real) continue;
        SCOPED_TRACE(d.flag);
        auto text = [&](double v) {
            std::ostringstream s;
            s.precision(17);
            s << (d.kind == ParamKind::Int ? double((long long)v) : v);
            return s.str();
        };
        const double below = d.kind == ParamKind::Int ? d.lo - 1 : d.lo - (d.hi - d.lo) * 0.5 - 1;
        const double above = d.kind == ParamKind::Int ? d.hi + 1 : d.hi * 2 + 1;
        for (double v : {d.lo, d.hi}) {
            Parsed p({"render", "x", d.flag, text(v)});
            EXPECT_EQ(p.error, "") << v;
            EXPECT_EQ(d.get(p.o.knobs), v);
            Knobs k;
            EXPECT_TRUE(parseValue(d, text(v), k));
            EXPECT_EQ(d.get(k), v);
        }
        for (double v : {below, above}) {
            Parsed p({"render", "x", d.flag, text(v)});
            EXPECT_NE(p.error.find(d.flag), std::string::npos) << p.error;
            EXPECT_EQ(p.error.rfind("error: ", 0), 0u) << p.error;
            Knobs k;
            EXPECT_FALSE(parseValue(d, text(v), k));
        }
    }
    // The irregular scheme's max-objects 0 (split until no segment is left) can be chosen.
    Parsed p({"render", "x", "--scheme", "irregular", "--max-objects", "0"});
    EXPECT_EQ(p.error, "");
    EXPECT_EQ(p.o.knobs.build.irregular.maxObjects, 0);
}

// --scheme takes every name of the scheme table, and only those.
TEST(ParamTable, SchemeTakesTheTablesNames) {
    for (const SchemeInfo& info : kSchemeTable) {
        Parsed p({"render", "x", "--scheme", info.name});
        EXPECT_EQ(p.error, "") << info.name;
        EXPECT_EQ(p.o.knobs.build.scheme, info.kind) << info.name;
    }
    Parsed bad({"render", "x", "--scheme", "kd-tree"});
    EXPECT_NE(bad.error.find("--scheme"), std::string::npos) << bad.error;
}

// max-objects' automatic value is written "auto" and read back from the command line, the ini
// and --change; an explicit number replaces it for both schemes.
TEST(ParamTable, MaxObjectsTakesAutoOrANumber) {
    const ParamDesc& d = *findParam("--max-objects");
    const Knobs defaults;
    EXPECT_EQ(defaults.build.regular.maxObjects, kAutoObjects);
    EXPECT_EQ(defaults.build.irregular.maxObjects, kAutoObjects);
    EXPECT_EQ(formatValue(d, defaults), "auto");
    Parsed one({"render", "x", "--max-objects", "1"});
    ASSERT_EQ(one.error, "");
    EXPECT_EQ(one.o.knobs.build.regular.maxObjects, 1);
    EXPECT_EQ(one.o.knobs.build.irregular.maxObjects, 1);
    Parsed back({"render", "x", "--max-objects", "auto"});
    ASSERT_EQ(back.error, "");
    EXPECT_EQ(back.o.knobs.build.regular.maxObjects, kAutoObjects);
    Knobs k = one.o.knobs;
    EXPECT_TRUE(parseValue(d, "auto", k));
    EXPECT_EQ(k.build.irregular.maxObjects, kAutoObjects);
    applyAssignments("max-objects=7", k);
    EXPECT_EQ(k.build.regular.maxObjects, 7);
    applyAssignments("max_objects=auto", k);
    EXPECT_EQ(k.build.regular.maxObjects, kAutoObjects);
    for (const char* bad : {"-1", "Auto", "4x", ""}) {
        EXPECT_FALSE(parseValue(d, bad, k)) << bad;
        Parsed p({"render", "x", "--max-objects", bad});
        EXPECT_NE(p.error.find("--max-objects"), std::string::npos) << bad << ": " << p.error;
    }
    EXPECT_NE(optionsMarkdown().find("| 0 to 1000000, auto | auto |"), std::string::npos);
}

TEST(ParamTable, EveryValueRoundTripsThroughItsText) {
    Knobs k;
    for (const ParamDesc& d : paramTable()) changeValue(d, k);
    for (const ParamDesc& d : paramTable()) {
        SCOPED_TRACE(d.flag);
        Knobs r;
        ASSERT_TRUE(parseValue(d, formatValue(d, k), r));
        EXPECT_EQ(formatValue(d, r), formatValue(d, k));
    }
    EXPECT_FALSE(parseValue(*findParam("--scheme"), "octree", k));
    EXPECT_FALSE(parseValue(*findParam("--full-table"), "yes", k));
}

TEST(ParamTable, CommandLineSwitchesAndEnumsSetTheKnobs) {
    Parsed p({"render", "x", "--scheme", "IRREGULAR", "--no-mailbox", "--full-table",
              "--irregular-frame", "camera", "--no-reflections", "--bsp-heuristic", "fewest-cuts"});
    ASSERT_EQ(p.error, "");
    EXPECT_EQ(p.o.knobs.build.scheme, SchemeKind::Irregular);
    EXPECT_FALSE(p.o.knobs.build.mailboxes);
    EXPECT_TRUE(p.o.knobs.build.regular.fullTable);
    EXPECT_EQ(p.o.knobs.build.irregular.frame, IrregularFrame::Camera);
    EXPECT_EQ(p.o.knobs.build.irregular.heuristic, BspHeuristic::FewestCuts);
    EXPECT_FALSE(p.o.knobs.shading.reflections);
    EXPECT_TRUE(p.o.knobs.shading.refractions);
}

// BuildParams prints itself as the options that build it again: the knobs of the scheme in
// use, read back by the command line into the same values.
TEST(ParamTable, BuildParamsPrintAsTheOptionsThatBuildThemAgain) {
    BuildParams a;
    a.scheme = SchemeKind::Regular;
    a.regular.maxLevel = 17;
    a.regular.maxObjects = 3;
    a.regular.step = StepMethod::Push;
    a.regular.delta = 2.5e-7;
    a.regular.splitAxes = SplitAxes::Cycle;
    a.regular.fullTable = true;
    a.mailboxes = false;
    BuildParams b;
    b.scheme = SchemeKind::Irregular;
    b.irregular.maxObjects = 0;
    b.irregular.heuristic = BspHeuristic::First;
    b.irregular.frame = IrregularFrame::Camera;
    b.lightBuffer = false;
    for (const BuildParams& want : {a, b, BuildParams{}}) {
        std::vector<std::string> args = {"render", "x", "--scheme"};
        std::istringstream words(toString(want));
        for (std::string w; words >> w;) args.push_back(w);
        Parsed p(args);
        ASSERT_EQ(p.error, "") << toString(want);
        const BuildParams& got = p.o.knobs.build;
        EXPECT_EQ(got.scheme, want.scheme) << toString(want);
        EXPECT_EQ(got.mailboxes, want.mailboxes);
        EXPECT_EQ(got.lightBuffer, want.lightBuffer || want.scheme == SchemeKind::Brute);
        if (want.scheme == SchemeKind::Regular) {
            EXPECT_EQ(got.regular.maxLevel, want.regular.maxLevel);
            EXPECT_EQ(got.regular.maxObjects, want.regular.maxObjects);
            EXPECT_EQ(got.regular.step, want.regular.step);
            EXPECT_EQ(got.regular.delta, want.regular.delta);
            EXPECT_EQ(got.regular.splitAxes, want.regular.splitAxes);
            EXPECT_EQ(got.regular.fullTable, want.regular.fullTable);
        }
        if (want.scheme == SchemeKind::Irregular) {
            EXPECT_EQ(got.irregular.maxObjects, want.irregular.maxObjects);
            EXPECT_EQ(got.irregular.heuristic, want.irregular.heuristic);
            EXPECT_EQ(got.irregular.frame, want.irregular.frame);
        }
        std::ostringstream os;
        os << want;
        EXPECT_EQ(os.str(), toString(want));
    }
}

TEST(ParamTable, AMisspeltOptionGetsTheNearestOne) {
    Parsed p({"render", "x", "--max-levle", "3"});
    EXPECT_EQ(p.error.rfind("error: ", 0), 0u) << p.error;
    EXPECT_NE(p.error.find("did you mean --max-level?"), std::string::npos) << p.error;
    Parsed q({"rendr", "x"});
    EXPECT_NE(q.error.find("did you mean render?"), std::string::npos) << q.error;
    Parsed far({"render", "x", "--zzzzzzzz"});
    EXPECT_NE(far.error.find("error: "), std::string::npos);
    EXPECT_EQ(far.error.find("did you mean"), std::string::npos) << far.error;
}

// README's options section is the table's (`lancer help-options` prints it).
TEST(ParamTable, ReadmeOptionSectionMatchesTheTable) {
    std::ifstream in(std::string(LANCER_SOURCE_DIR) + "/README.md");
    ASSERT_TRUE(in) << "README.md not found";
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string readme = ss.str();
    const std::string begin = "<!-- options:begin -->\n", end = "<!-- options:end -->";
    size_t b = readme.find(begin), e = readme.find(end);
    ASSERT_NE(b, std::string::npos) << "README.md has no line " << begin;
    ASSERT_NE(e, std::string::npos) << "README.md has no line " << end;
    ASSERT_LT(b, e);
    EXPECT_EQ(readme.substr(b + begin.size(), e - b - begin.size()), optionsMarkdown())
        << "regenerate the section with `lancer help-options`";
}

// --camera with what the viewer's Copy JSON writes (Camera::toJson) gives the image the viewer
// renders with that camera: for the scene's own camera, the image without --camera.
TEST(CameraOption, CopyJsonRoundTripGivesTheSameImage) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("lancer_camera_" + std::to_string(getpid()));
    fs::create_directories(dir);
    auto renderWith = [](const Scene& scene, const RenderOptions& ro) {
        auto accel = buildAccelerator(scene, Knobs{}.build);
        Image img(ro.width, ro.height);
        render(scene, *accel, ro, img);
        return img;
    };
    const std::string src = LANCER_SOURCE_DIR;
    for (const std::string& spec : {std::string("builtin:default"), src + "/assets/spd/balls1.nff",
                                    src + "/assets/openscad/bracket.csg"}) {
        for (int moved = 0; moved < 3; ++moved) {
            SCOPED_TRACE(spec + " camera " + std::to_string(moved));
            CommonOptions o;
            o.scene = spec;
            o.knobs.width = 48;
            o.knobs.height = 36;
            o.knobs.threads = 2;
            Scene plain = loadScene(spec);
            Camera cam = plain.camera;  // the viewer's camera: the scene's, or moved
            if (moved == 1) cam.from = cam.at + (cam.from - cam.at) * 0.7 + Vec3(0.3, -0.2, 0.1);
            if (moved == 2) {
                cam.projection = Projection::Orthographic;
                cam.orthoHeight = 0.8 * glm::length(plain.bounds.extent());
            }
            o.knobs.cameraPath = (dir / "view.camera.json").string();
            std::ofstream(o.knobs.cameraPath) << cam.toJson();
            Scene viaFile = loadSceneWithCamera(o);
            RenderOptions viewer = renderOptions(o, plain);
            viewer.camera = cam;
            Image a = renderWith(plain, viewer);
            Image b = renderWith(viaFile, renderOptions(o, viaFile));
            ASSERT_EQ(a.color.size(), b.color.size());
            EXPECT_TRUE(a.color == b.color);
            EXPECT_TRUE(a.depth == b.depth);
            EXPECT_TRUE(a.hitPrim == b.hitPrim);
        }
    }
    // An error names the file, the line and the column.
    CommonOptions bad;
    bad.knobs.cameraPath = (dir / "bad.camera.json").string();
    std::ofstream(bad.knobs.cameraPath) << "{\"from\": [0, 0, 1],\n \"fov\": 200}\n";
    try {
        loadSceneWithCamera(bad);
        ADD_FAILURE() << "a fov of 200 degrees was accepted";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("bad.camera.json:2:2"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

}  // namespace
}  // namespace lancer::cli
