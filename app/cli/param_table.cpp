#include "app/cli/param_table.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "engine/accel/build_guard.h"

namespace lancer::cli {

namespace {

constexpr uint8_t kRegular = schemeBit(SchemeKind::Regular);
constexpr uint8_t kIrregular = schemeBit(SchemeKind::Irregular);
constexpr uint8_t kBvh = schemeBit(SchemeKind::Bvh);
constexpr uint8_t kAccelerated = kRegular | kIrregular | kBvh;

std::vector<ParamDesc> makeTable() {
    using K = Knobs;
    std::vector<ParamDesc> t;
    auto add = [&](ParamDesc d) { t.push_back(std::move(d)); };
    ParamDesc d{};

    d = {.flag = "--width",
         .metavar = "W",
         .iniKey = "width",
         .label = "width",
         .help = "Image width in pixels (default: the scene's)",
         .kind = ParamKind::Int,
         .lo = 1,
         .hi = 16384};
    d.reach = ViewerReach::Window;
    d.get = [](const K& k) { return double(k.width); };
    d.set = [](K& k, double v) { k.width = int(v); };
    add(d);
    d = {.flag = "--height",
         .metavar = "H",
         .iniKey = "height",
         .label = "height",
         .help = "Image height in pixels (default: the scene's)",
         .kind = ParamKind::Int,
         .lo = 1,
         .hi = 16384};
    d.reach = ViewerReach::Window;
    d.get = [](const K& k) { return double(k.height); };
    d.set = [](K& k, double v) { k.height = int(v); };
    add(d);

    d = {.flag = "--scheme",
         .metavar = "S",
         .iniKey = "scheme",
         .label = "scheme",
         .help = "Acceleration scheme",
         .kind = ParamKind::Enum};
    for (const SchemeInfo& s : kSchemeTable) d.names.push_back(s.name);
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.scheme); };
    d.set = [](K& k, double v) { k.build.scheme = SchemeKind(int(v)); };
    add(d);
    d = {.flag = "--max-level",
         .metavar = "N",
         .iniKey = "max_level",
         .label = "max-level",
         .help =
             "Deepest subdivision level (regular: one axis cut per level, 0 automatic: 16 + 0.65 "
             "log2 of the primitive count, 4 deeper where a split saves enough, an explicit N "
             "builds by the report's rule alone, no cost stop; bvh: tree depth, 0 automatic: 64)",
         .kind = ParamKind::Int,
         .lo = 0,
         .hi = 48};
    d.schemes = kRegular | kBvh;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) {
        return double(k.build.scheme == SchemeKind::Bvh ? k.build.bvh.maxLevel
                                                        : k.build.regular.maxLevel);
    };
    d.set = [](K& k, double v) { k.build.regular.maxLevel = k.build.bvh.maxLevel = int(v); };
    add(d);
    // One knob for both schemes, as the report has one: the regular scheme refuses 0 when it
    // builds (a cell must stop on a count), the irregular one splits until no segment is left.
    // auto: 4, the cost stop deciding (an explicit value turns it off).
    d = {.flag = "--max-objects",
         .metavar = "N",
         .iniKey = "max_objects",
         .label = "max-objects",
         .help =
             "Stop subdividing a cell holding at most N primitives (irregular: 0 never stops; "
             "regular and bvh: at least 1); auto: 4 (bvh: 2), and a cost estimate stops cells "
             "where a split does not pay; an explicit N builds by the report's rule alone (no "
             "cost stop)",
         .kind = ParamKind::Int,
         .lo = 0,
         .hi = 1000000};
    d.autoWord = "auto";
    d.autoValue = kAutoObjects;
    d.schemes = kAccelerated;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) {
        return double(k.build.scheme == SchemeKind::Irregular ? k.build.irregular.maxObjects
                      : k.build.scheme == SchemeKind::Bvh     ? k.build.bvh.maxObjects
                                                              : k.build.regular.maxObjects);
    };
    d.set = [](K& k, double v) {
        k.build.regular.maxObjects = k.build.irregular.maxObjects = k.build.bvh.maxObjects = int(v);
    };
    add(d);
    d = {.flag = "--step",
         .metavar = "M",
         .iniKey = "step",
         .label = "step",
         .help =
             "Next-cell method: exact, or the report's push (lancer view with --pick: the "
             "playback step to stop at instead, first, last or N from 0)",
         .kind = ParamKind::Enum};
    d.names = {"exact", "push"};
    d.schemes = kRegular;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.regular.step); };
    d.set = [](K& k, double v) { k.build.regular.step = StepMethod(int(v)); };
    add(d);
    d = {.flag = "--delta",
         .metavar = "D",
         .iniKey = "delta",
         .label = "delta",
         .help = "Push distance of --step push, relative to the scene size",
         .kind = ParamKind::Real,
         .lo = 1e-15,
         .hi = 0.5};
    d.schemes = kRegular;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return k.build.regular.delta; };
    d.set = [](K& k, double v) { k.build.regular.delta = v; };
    d.when = [](const K& k) { return k.build.regular.step == StepMethod::Push; };
    add(d);
    d = {.flag = "--split-axes",
         .metavar = "A",
         .iniKey = "split_axes",
         .label = "split axes",
         .help =
             "Axis per BSP level: cycle (x, y, z in turn, the report's) or cost (the cheapest by "
             "an area estimate)",
         .kind = ParamKind::Enum};
    d.names = {"cycle", "cost"};
    d.schemes = kRegular;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.regular.splitAxes); };
    d.set = [](K& k, double v) { k.build.regular.splitAxes = SplitAxes(int(v)); };
    add(d);
    d = {.flag = "--full-table",
         .metavar = "",
         .iniKey = "full_table",
         .label = "full table",
         .help = "One full directory table instead of sub-tables",
         .kind = ParamKind::Switch};
    d.schemes = kRegular;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.regular.fullTable); };
    d.set = [](K& k, double v) { k.build.regular.fullTable = v != 0.0; };
    add(d);
    d = {.flag = "--world-frame",
         .metavar = "",
         .iniKey = "turned_frame",
         .label = "turned frame",
         .help =
             "Build the regular grid or the BVH along the world's axes even where a turned "
             "subtree's own axes give its primitives much smaller boxes (docs/regular.md, "
             "\"Turned scenes\")",
         .kind = ParamKind::Switch};
    d.flagValue = false;
    d.schemes = kRegular | schemeBit(SchemeKind::Bvh);
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) {
        return double(k.build.scheme == SchemeKind::Bvh ? k.build.bvh.turnedFrame
                                                        : k.build.regular.turnedFrame);
    };
    d.set = [](K& k, double v) {
        k.build.regular.turnedFrame = k.build.bvh.turnedFrame = v != 0.0;
    };
    add(d);
    d = {.flag = "--no-cost-stop",
         .metavar = "",
         .iniKey = "cost_stop",
         .label = "cost stop",
         .help =
             "With max-level 0 and max-objects auto, split cells (irregular: screen cells) down "
             "to 4 primitives or the automatic max-level even where the cost estimate says a "
             "split does not pay (the report's rule, which an explicit max-level or max-objects "
             "also gives)",
         .kind = ParamKind::Switch};
    d.flagValue = false;
    d.schemes = kAccelerated;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) {
        return double(k.build.scheme == SchemeKind::Irregular ? k.build.irregular.costStop
                      : k.build.scheme == SchemeKind::Bvh     ? k.build.bvh.costStop
                                                              : k.build.regular.costStop);
    };
    d.set = [](K& k, double v) {
        k.build.regular.costStop = k.build.irregular.costStop = k.build.bvh.costStop = v != 0.0;
    };
    add(d);
    d = {.flag = "--bsp-heuristic",
         .metavar = "H",
         .iniKey = "bsp_heuristic",
         .label = "BSP heuristic",
         .help = "Choice of the screen BSP's splitting segment",
         .kind = ParamKind::Enum};
    d.names = {"first", "balanced", "fewest-cuts"};
    d.schemes = kIrregular;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.irregular.heuristic); };
    d.set = [](K& k, double v) { k.build.irregular.heuristic = BspHeuristic(int(v)); };
    add(d);
    d = {.flag = "--irregular-frame",
         .metavar = "F",
         .iniKey = "irregular_frame",
         .label = "primary rays",
         .help =
             "What primary rays walk: camera (the camera-frame structure) or projective (zones in "
             "screen x/z, y/z)",
         .kind = ParamKind::Enum};
    d.names = {"camera", "projective"};
    d.schemes = kIrregular;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.irregular.frame); };
    d.set = [](K& k, double v) { k.build.irregular.frame = IrregularFrame(int(v)); };
    add(d);
    d = {.flag = "--no-mailbox",
         .metavar = "",
         .iniKey = "mailboxes",
         .label = "mailboxes",
         .help = "Turn the mailboxes off (to measure their effect)",
         .kind = ParamKind::Switch};
    d.flagValue = false;
    d.schemes = kAccelerated;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.mailboxes); };
    d.set = [](K& k, double v) { k.build.mailboxes = v != 0.0; };
    add(d);
    d = {.flag = "--no-light-buffer",
         .metavar = "",
         .iniKey = "light_buffer",
         .label = "light buffer",
         .help = "Trace shadow rays without the light buffer (to measure its effect)",
         .kind = ParamKind::Switch};
    d.flagValue = false;
    d.schemes = kAccelerated;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.lightBuffer); };
    d.set = [](K& k, double v) { k.build.lightBuffer = v != 0.0; };
    add(d);
    // Every scheme's builder reads it; brute force builds nothing worth bounding, so the regular
    // and irregular schemes only. A change rebuilds under the new budget.
    d = {.flag = "--memory-budget",
         .metavar = "SIZE",
         .iniKey = "memory_budget",
         .label = "memory budget",
         .help =
             "Bytes a structure and its light buffer may take while they are built (512M, 2G, "
             "1.5GiB; 0: an eighth of physical memory); over it the irregular scheme stops "
             "subdividing (refused when even its coarsest structure does not fit), the regular one "
             "is refused; a light buffer over a quarter of it is left out",
         .kind = ParamKind::Size};
    d.schemes = kAccelerated;
    d.effect = ChangeEffect::Rebuild;
    d.get = [](const K& k) { return double(k.build.memoryBudget); };
    d.set = [](K& k, double v) { k.build.memoryBudget = size_t(v); };
    add(d);

    d = {.flag = "--threads",
         .metavar = "N",
         .iniKey = "threads",
         .label = "threads",
         .help = "Worker threads (0: all cores)",
         .kind = ParamKind::Int,
         .lo = 0,
         .hi = 1024};
    d.effect = ChangeEffect::Rerender;
    d.get = [](const K& k) { return double(k.threads); };
    d.set = [](K& k, double v) { k.threads = int(v); };
    add(d);
    d = {.flag = "--bounces",
         .metavar = "N",
         .iniKey = "bounces",
         .label = "bounces",
         .help = "Reflection/refraction depth; 0 = primary and shadow rays only",
         .kind = ParamKind::Int,
         .lo = 0,
         .hi = 64};
    d.effect = ChangeEffect::Rerender;
    d.get = [](const K& k) { return double(k.shading.bounces); };
    d.set = [](K& k, double v) { k.shading.bounces = int(v); };
    add(d);
    d = {.flag = "--offset",
         .metavar = "E",
         .iniKey = "offset",
         .label = "offset",
         .help = "Secondary-ray origin offset, relative to the scene scale",
         .kind = ParamKind::Real,
         .lo = 0.0,
         .hi = 1e-2};
    d.effect = ChangeEffect::Rerender;
    d.get = [](const K& k) { return k.shading.offsetScale; };
    d.set = [](K& k, double v) { k.shading.offsetScale = v; };
    add(d);
    d = {.flag = "--precision",
         .metavar = "P",
         .iniKey = "precision",
         .label = "precision",
         .help =
             "Arithmetic of the primitives' tests: double, or float (single precision, to measure "
             "the depth error it makes; the walk and the CSG stay in double)",
         .kind = ParamKind::Enum};
    d.names = {"double", "float"};
    d.effect = ChangeEffect::Rerender;
    d.get = [](const K& k) { return double(k.shading.precision); };
    d.set = [](K& k, double v) { k.shading.precision = Precision(int(v)); };
    add(d);
    d = {.flag = "--no-shadows",
         .metavar = "",
         .iniKey = "shadows",
         .label = "shadows",
         .help = "Trace no shadow rays",
         .kind = ParamKind::Switch};
    d.flagValue = false;
    d.effect = ChangeEffect::Rerender;
    d.get = [](const K& k) { return double(k.shading.shadows); };
    d.set = [](K& k, double v) { k.shading.shadows = v != 0.0; };
    add(d);
    d = {.flag = "--no-reflections",
         .metavar = "",
         .iniKey = "reflections",
         .label = "reflection",
         .help = "Trace no reflected rays",
         .kind = ParamKind::Switch};
    d.flagValue = false;
    d.effect = ChangeEffect::Rerender;
    d.get = [](const K& k) { return double(k.shading.reflections); };
    d.set = [](K& k, double v) { k.shading.reflections = v != 0.0; };
    add(d);
    d = {.flag = "--no-refractions",
         .metavar = "",
         .iniKey = "refractions",
         .label = "refraction",
         .help = "Trace no refracted rays",
         .kind = ParamKind::Switch};
    d.flagValue = false;
    d.effect = ChangeEffect::Rerender;
    d.get = [](const K& k) { return double(k.shading.refractions); };
    d.set = [](K& k, double v) { k.shading.refractions = v != 0.0; };
    add(d);

    d = {.flag = "--facets",
         .metavar = "F",
         .iniKey = nullptr,
         .label = "facets",
         .help =
             "Round shapes of .csg files: exact (the true circle, sphere, cylinder, cone), or "
             "openscad (OpenSCAD's polygons and polyhedra of them by $fn, $fa, $fs)",
         .kind = ParamKind::Enum};
    d.names = {"exact", "openscad"};
    d.reach = ViewerReach::Startup;
    d.get = [](const K& k) { return double(k.read.facets); };
    d.set = [](K& k, double v) { k.read.facets = Facets(int(v)); };
    add(d);
    d = {.flag = "--camera",
         .metavar = "FILE",
         .iniKey = nullptr,
         .label = "camera",
         .help =
             "A camera in the .camera.json sidecar's keys (the viewer's Copy JSON), replacing the "
             "scene's",
         .kind = ParamKind::Path};
    d.reach = ViewerReach::Startup;
    d.path = &Knobs::cameraPath;
    add(d);
    d = {.flag = "--stats",
         .metavar = "FILE",
         .iniKey = nullptr,
         .label = "stats",
         .help = "Write statistics as JSON to this file",
         .kind = ParamKind::Path};
    d.reach = ViewerReach::BatchOnly;
    d.path = &Knobs::statsPath;
    add(d);
    d = {.flag = "--depth",
         .metavar = "FILE",
         .iniKey = nullptr,
         .label = "depth",
         .help = "Write the primary hit distances as a PFM to this file",
         .kind = ParamKind::Path};
    d.reach = ViewerReach::BatchOnly;
    d.path = &Knobs::depthPath;
    add(d);
    return t;
}

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    // The shortest form that reads back to the same double.
    for (int p = 1; p <= 17; ++p) {
        char s[32];
        std::snprintf(s, sizeof s, "%.*g", p, v);
        if (std::strtod(s, nullptr) == v) return s;
    }
    return buf;
}

std::string schemesText(uint8_t schemes) {
    if (schemes == kAllSchemes) return "all";
    std::string out;
    for (int i = 0; i < kSchemeCount; ++i)
        if (schemes & schemeBit(SchemeKind(i)))
            out += (out.empty() ? "" : ", ") + std::string(schemeName(SchemeKind(i)));
    return out;
}

}  // namespace

std::span<const ParamDesc> paramTable() {
    static const std::vector<ParamDesc> table = makeTable();
    return table;
}

const ParamDesc* findParam(const std::string& flag) {
    for (const ParamDesc& d : paramTable())
        if (flag == d.flag) return &d;
    return nullptr;
}

bool applies(const ParamDesc& d, const Knobs& k) {
    return (d.schemes & schemeBit(k.build.scheme)) && (!d.when || d.when(k));
}

ChangeEffect changeEffect(const Knobs& before, const Knobs& after) {
    ChangeEffect e = ChangeEffect::None;
    for (const ParamDesc& d : paramTable()) {
        if (d.reach != ViewerReach::Panel || !d.get || d.get(before) == d.get(after)) continue;
        if (!applies(d, after)) continue;
        if (d.effect == ChangeEffect::Rebuild) return ChangeEffect::Rebuild;
        if (d.effect == ChangeEffect::Rerender) e = ChangeEffect::Rerender;
    }
    return e;
}

std::string formatValue(const ParamDesc& d, const Knobs& k) {
    switch (d.kind) {
        case ParamKind::Int:
            if (d.autoWord && d.get(k) == d.autoValue) return d.autoWord;
            return std::to_string(int(d.get(k)));
        case ParamKind::Real:
            return number(d.get(k));
        case ParamKind::Enum:
            return d.names[size_t(d.get(k))];
        case ParamKind::Switch:
            return d.get(k) != 0.0 ? "1" : "0";
        case ParamKind::Size:
            return std::to_string(size_t(d.get(k)));
        case ParamKind::Path:
            return k.*d.path;
    }
    return "";
}

bool parseValue(const ParamDesc& d, const std::string& text, Knobs& k) {
    switch (d.kind) {
        case ParamKind::Int: {
            if (d.autoWord && text == d.autoWord) {
                d.set(k, d.autoValue);
                return true;
            }
            long long v = 0;
            auto r = std::from_chars(text.data(), text.data() + text.size(), v);
            if (r.ec != std::errc() || r.ptr != text.data() + text.size()) return false;
            if (double(v) < d.lo || double(v) > d.hi) return false;
            d.set(k, double(v));
            return true;
        }
        case ParamKind::Real: {
            char* end = nullptr;
            double v = std::strtod(text.c_str(), &end);
            if (text.empty() || *end || !std::isfinite(v) || v < d.lo || v > d.hi) return false;
            d.set(k, v);
            return true;
        }
        case ParamKind::Enum:
            for (size_t i = 0; i < d.names.size(); ++i)
                if (text == d.names[i]) {
                    d.set(k, double(i));
                    return true;
                }
            return false;
        case ParamKind::Switch:
            if (text != "0" && text != "1") return false;
            d.set(k, text == "1" ? 1.0 : 0.0);
            return true;
        case ParamKind::Size:
            if (text == "0") {
                d.set(k, 0.0);
                return true;
            }
            try {
                d.set(k, double(parseMemoryBudget(text)));
                return true;
            } catch (const std::invalid_argument&) {
                return false;
            }
        case ParamKind::Path:
            k.*d.path = text;
            return true;
    }
    return false;
}

void copyValue(const ParamDesc& d, const Knobs& from, Knobs& to) {
    if (d.kind == ParamKind::Path)
        to.*d.path = from.*d.path;
    else
        d.set(to, d.get(from));
}

void applyAssignments(const std::string& list, Knobs& k) {
    Knobs out = k;
    std::stringstream in(list);
    std::string item;
    bool any = false;
    while (std::getline(in, item, ',')) {
        const size_t eq = item.find('=');
        const std::string name = item.substr(0, eq);
        const ParamDesc* d = findParam("--" + name);
        for (const ParamDesc& e : paramTable())
            if (!d && e.iniKey && name == e.iniKey) d = &e;
        if (eq == std::string::npos || !d)
            throw std::invalid_argument("'" + item + "' is not NAME=VALUE with NAME an option (" +
                                        "max-level=16)");
        if (d->reach != ViewerReach::Panel || d->kind == ParamKind::Path)
            throw std::invalid_argument("'" + name + "' is not a parameter the viewer changes");
        if (!parseValue(*d, item.substr(eq + 1), out))
            throw std::invalid_argument("'" + item + "': not a value of --" + name);
        any = true;
    }
    if (!any) throw std::invalid_argument("no NAME=VALUE given");
    k = out;
}

std::string optionsMarkdown() {
    static const char* reach[] = {"panel", "image size", "at start", "batch only"};
    const Knobs defaults;
    std::ostringstream o;
    o << "| option | values | default | schemes | viewer | what it does |\n"
      << "|---|---|---|---|---|---|\n";
    for (const ParamDesc& d : paramTable()) {
        std::string flag = d.flag, values, def;
        if (*d.metavar) flag += std::string(" ") + d.metavar;
        switch (d.kind) {
            case ParamKind::Int:
            case ParamKind::Real:
                values = d.kind == ParamKind::Int ? std::to_string((long long)d.lo) + " to " +
                                                        std::to_string((long long)d.hi)
                                                  : number(d.lo) + " to " + number(d.hi);
                if (d.autoWord) values += std::string(", ") + d.autoWord;
                def = formatValue(d, defaults);
                if (d.kind == ParamKind::Int &&
                    (d.flag == std::string("--width") || d.flag == std::string("--height")))
                    def = "the scene's";
                break;
            case ParamKind::Enum:
                for (const char* n : d.names)
                    values += (values.empty() ? "" : ", ") + std::string(n);
                def = formatValue(d, defaults);
                break;
            case ParamKind::Switch:
                values = "flag";
                def = std::string(d.label) + (d.get(defaults) != 0.0 ? " on" : " off");
                break;
            case ParamKind::Size:
                values = "bytes, K, M, G, T";
                def = d.get(defaults) != 0.0 ? formatValue(d, defaults)
                                             : "an eighth of physical memory";
                break;
            case ParamKind::Path:
                values = "file";
                def = "none";
                break;
        }
        o << "| `" << flag << "` | " << values << " | " << def << " | " << schemesText(d.schemes)
          << " | " << reach[int(d.reach)] << " | " << d.help << " |\n";
    }
    return o.str();
}

}  // namespace lancer::cli
