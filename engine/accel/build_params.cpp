#include "engine/accel/build_params.h"

namespace lancer {

const char* schemeName(SchemeKind k) {
    switch (k) {
        case SchemeKind::Brute:
            return "brute";
        case SchemeKind::Regular:
            return "regular";
        case SchemeKind::Irregular:
            return "irregular";
    }
    return "?";
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

}  // namespace lancer
