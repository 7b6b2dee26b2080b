#include "engine/accel/build_params.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <ostream>
#include <sstream>

namespace lancer {

const char* schemeName(SchemeKind k) {
    return size_t(k) < kSchemeTable.size() ? schemeInfo(k).name : "?";
}

std::optional<SchemeKind> schemeFromName(std::string_view name) {
    for (const SchemeInfo& s : kSchemeTable)
        if (name == s.name) return s.kind;
    return std::nullopt;
}

std::vector<std::string> schemeNames() {
    std::vector<std::string> out;
    for (const SchemeInfo& s : kSchemeTable) out.push_back(s.name);
    return out;
}

const char* stepName(StepMethod s) { return s == StepMethod::Exact ? "exact" : "push"; }

const char* heuristicName(BspHeuristic h) {
    switch (h) {
        case BspHeuristic::First:
            return "first";
        case BspHeuristic::Balanced:
            return "balanced";
        case BspHeuristic::FewestCuts:
            return "fewest-cuts";
    }
    return "?";
}

const char* splitAxesName(SplitAxes s) { return s == SplitAxes::Cycle ? "cycle" : "cost"; }

const char* irregularFrameName(IrregularFrame f) {
    return f == IrregularFrame::Camera ? "camera" : "projective";
}

int automaticMaxLevel(size_t primitives) {
    const double n = double(std::max<size_t>(primitives, 1));
    return std::clamp(int(std::lround(16.0 + 0.65 * std::log2(n))), 8, 48);
}

namespace {

/// The automatic base level, lowered as the build asked (RegularConfig::autoLevelDrop).
int droppedBaseLevel(const RegularConfig& config, size_t primitives) {
    return std::max(automaticMaxLevel(primitives) - config.autoLevelDrop, 1);
}

}  // namespace

int effectiveMaxLevel(const RegularConfig& config, size_t primitives) {
    if (config.maxLevel > 0) return config.maxLevel;
    const int base = droppedBaseLevel(config, primitives);
    return config.usesCostStop() ? std::min(base + kGainDepth, 48) : base;
}

int gainLevel(const RegularConfig& config, size_t primitives) {
    if (!config.usesCostStop()) return std::numeric_limits<int>::max();
    return droppedBaseLevel(config, primitives);
}

std::string maxObjectsText(int maxObjects) {
    return maxObjects == kAutoObjects ? "auto" : std::to_string(maxObjects);
}

std::string toString(const BuildParams& p) {
    std::ostringstream os;
    os.precision(17);
    os << schemeName(p.scheme);
    if (p.scheme == SchemeKind::Regular) {
        const RegularConfig& r = p.regular;
        os << " --max-level " << r.maxLevel << " --max-objects " << maxObjectsText(r.maxObjects)
           << " --step " << stepName(r.step);
        if (r.step == StepMethod::Push) os << " --delta " << r.delta;
        os << " --split-axes " << splitAxesName(r.splitAxes);
        if (r.fullTable) os << " --full-table";
        if (!r.turnedFrame) os << " --world-frame";
        if (!r.costStop) os << " --no-cost-stop";
    } else if (p.scheme == SchemeKind::Irregular) {
        const IrregularConfig& i = p.irregular;
        os << " --max-objects " << maxObjectsText(i.maxObjects) << " --bsp-heuristic "
           << heuristicName(i.heuristic) << " --irregular-frame " << irregularFrameName(i.frame);
        if (!i.costStop) os << " --no-cost-stop";
    } else if (p.scheme == SchemeKind::Bvh) {
        const BvhConfig& b = p.bvh;
        os << " --max-level " << b.maxLevel << " --max-objects " << maxObjectsText(b.maxObjects);
        if (!b.costStop) os << " --no-cost-stop";
        if (!b.turnedFrame) os << " --world-frame";
    }
    if (p.scheme != SchemeKind::Brute) {
        if (!p.mailboxes) os << " --no-mailbox";
        if (!p.lightBuffer) os << " --no-light-buffer";
    }
    return os.str();
}

std::ostream& operator<<(std::ostream& os, const BuildParams& p) { return os << toString(p); }

}  // namespace lancer
