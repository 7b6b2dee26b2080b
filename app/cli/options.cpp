#include "app/cli/options.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "engine/scene/loader.h"
#include "engine/util/format.h"

namespace lancer::cli {

void addCommonOptions(CLI::App& app, CommonOptions& o) {
    const Knobs defaults;
    for (const ParamDesc& d : paramTable()) {
        const ParamDesc* p = &d;
        Knobs* k = &o.knobs;
        std::string help = d.help;
        if (d.schemes != kAllSchemes) {
            std::string only;
            for (int i = 0; i < kSchemeCount; ++i)
                if (d.schemes & schemeBit(SchemeKind(i)))
                    only += (only.empty() ? "" : " and ") + std::string(schemeName(SchemeKind(i)));
            help += " (" + only + " scheme" + (only.find(" and ") != std::string::npos ? "s" : "") +
                    ")";
        }
        CLI::Option* opt = nullptr;
        switch (d.kind) {
            case ParamKind::Int:
                if (d.autoWord) {  // a number or the automatic value's word
                    const std::string expected =
                        "expected an integer in " + std::to_string((long long)d.lo) + ".." +
                        std::to_string((long long)d.hi) + " or " + d.autoWord;
                    opt = app.add_option_function<std::string>(
                                 d.flag, [p, k](const std::string& v) { parseValue(*p, v, *k); },
                                 help)
                              ->check(CLI::Validator(
                                  [p, expected](std::string& v) {
                                      Knobs scratch;
                                      return parseValue(*p, v, scratch) ? std::string()
                                                                        : v + ": " + expected;
                                  },
                                  "N"));
                    break;
                }
                opt = app.add_option_function<long long>(
                             d.flag, [p, k](const long long& v) { p->set(*k, double(v)); }, help)
                          ->check(CLI::Range((long long)d.lo, (long long)d.hi));
                break;
            case ParamKind::Real:
                opt = app.add_option_function<double>(
                             d.flag, [p, k](const double& v) { p->set(*k, v); }, help)
                          ->check(CLI::Range(d.lo, d.hi));
                break;
            case ParamKind::Enum: {
                std::vector<std::string> names(d.names.begin(), d.names.end());
                std::string set = "{";
                for (const std::string& n : names) set += (set.size() > 1 ? ", " : "") + n;
                opt =
                    app.add_option_function<std::string>(
                           d.flag, [p, k](const std::string& v) { parseValue(*p, v, *k); }, help)
                        ->transform(CLI::IsMember(names, CLI::ignore_case).description(set + "}"));
                break;
            }
            case ParamKind::Switch:
                opt = app.add_flag_function(
                    d.flag, [p, k](std::int64_t) { p->set(*k, p->flagValue ? 1.0 : 0.0); }, help);
                break;
            case ParamKind::Size:
                opt = app.add_option_function<std::string>(
                             d.flag, [p, k](const std::string& v) { parseValue(*p, v, *k); },
                             help + " (here: " + formatBytes(defaultMemoryBudget()) + ")")
                          ->check(CLI::Validator(
                              [](std::string& v) {
                                  if (v == "0") return std::string();
                                  try {
                                      parseMemoryBudget(v);
                                      return std::string();
                                  } catch (const std::invalid_argument& e) {
                                      return std::string(e.what());
                                  }
                              },
                              "SIZE"));
                break;
            case ParamKind::Path:
                opt = app.add_option(d.flag, o.knobs.*d.path, help);
                break;
        }
        if (d.kind != ParamKind::Switch && d.kind != ParamKind::Path && d.kind != ParamKind::Size &&
            d.reach != ViewerReach::Window)
            opt->default_str(formatValue(d, defaults));
        if (*d.metavar) opt->type_name(d.metavar);
    }
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
    const int ow = o.knobs.width, oh = o.knobs.height;
    w = scene.width;
    h = scene.height;
    if (ow && oh) {
        w = ow;
        h = oh;
    } else if (ow) {
        h = std::max(1, int(std::lround(double(ow) * scene.height / scene.width)));
        w = ow;
    } else if (oh) {
        w = std::max(1, int(std::lround(double(oh) * scene.width / scene.height)));
        h = oh;
    }
}

RenderOptions renderOptions(const CommonOptions& o, const Scene& scene) {
    RenderOptions ro;
    ro.threads = o.knobs.threads;
    ro.shading = o.knobs.shading;
    resolveSize(o, scene, ro.width, ro.height);
    return ro;
}

Scene loadSceneWithCamera(const CommonOptions& o) {
    Scene scene = loadScene(o.scene, o.knobs.read);
    if (!o.knobs.cameraPath.empty()) applyCameraFile(scene, o.knobs.cameraPath);
    return scene;
}

namespace {

size_t editDistance(const std::string& a, const std::string& b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= b.size(); ++j) {
            size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1])});
            diag = up;
        }
    }
    return row[b.size()];
}

/// The known name nearest to `word`, if it is near enough to be a slip of the keyboard.
std::string nearest(const std::string& word, const std::vector<std::string>& known) {
    std::string best;
    size_t bestDistance = std::max<size_t>(2, word.size() / 3) + 1;
    for (const std::string& n : known)
        if (size_t dist = editDistance(word, n); dist < bestDistance) {
            bestDistance = dist;
            best = n;
        }
    return best;
}

}  // namespace

std::string parseErrorMessage(const CLI::App& app, const CLI::ParseError& e,
                              const std::vector<std::string>& args) {
    std::string msg = "error: " + std::string(e.what());
    // Options and subcommands of the subcommand that was given (or of the program).
    const CLI::App* where = &app;
    std::vector<std::string> options, commands;
    for (const CLI::App* sub : app.get_subcommands({})) {
        commands.push_back(sub->get_name());
        for (const std::string& a : args)
            if (a == sub->get_name()) where = sub;
    }
    for (const CLI::App* a : {&app, where})
        for (const CLI::Option* opt : a->get_options())
            for (const std::string& n : opt->get_lnames()) options.push_back("--" + n);
    std::vector<std::string> suggestions;
    bool afterCommand = where == &app;
    for (const std::string& a : args) {
        if (!afterCommand) {
            afterCommand = a == where->get_name();
            continue;
        }
        std::string word = a.substr(0, a.find('='));
        if (word.rfind("--", 0) == 0) {
            if (std::find(options.begin(), options.end(), word) != options.end()) continue;
            if (std::string n = nearest(word, options); !n.empty())
                suggestions.push_back(word + ": did you mean " + n + "?");
        } else if (where == &app && !word.empty() && word[0] != '-' &&
                   dynamic_cast<const CLI::ExtrasError*>(&e)) {
            if (std::string n = nearest(word, commands); !n.empty() && n != word)
                suggestions.push_back(word + ": did you mean " + n + "?");
        }
    }
    for (const std::string& s : suggestions) msg += "\n  " + s;
    return msg + "\nRun with --help for more information.";
}

}  // namespace lancer::cli
