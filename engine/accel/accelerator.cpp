#include "engine/accel/accelerator.h"

#include <chrono>
#include <stdexcept>

namespace lancer {

const char* schemeName(SchemeKind k) {
    switch (k) {
        case SchemeKind::Brute: return "brute";
        case SchemeKind::Regular: return "regular";
        case SchemeKind::Irregular: return "irregular";
    }
    return "?";
}

const char* stepName(StepMethod s) { return s == StepMethod::Exact ? "exact" : "push"; }

const char* heuristicName(BspHeuristic h) {
    switch (h) {
        case BspHeuristic::First: return "first";
        case BspHeuristic::Balanced: return "balanced";
        case BspHeuristic::FewestCuts: return "fewest-cuts";
    }
    return "?";
}

const char* splitAxesName(SplitAxes s) { return s == SplitAxes::Cycle ? "cycle" : "cost"; }

const char* irregularFrameName(IrregularFrame f) {
    return f == IrregularFrame::Camera ? "camera" : "projective";
}

namespace {

/// The light buffer of an accelerated scheme, counted in its memory and reported in `extra`.
LightBuffer lightBufferFor(const Scene& scene, const BuildParams& params, AccelInfo& info) {
    if (!params.lightBuffer) return {};
    LightBuffer lb(scene);
    info.memoryBytes += lb.memoryBytes();
    info.extra["light_buffer_bytes"] = lb.memoryBytes();
    info.extra["light_buffer_lights"] = lb.mappedLights();
    return lb;
}

}  // namespace

std::unique_ptr<Accelerator> buildAccelerator(const Scene& scene, const BuildParams& params) {
    if (!scene.prepared) throw std::logic_error("buildAccelerator: scene not prepared");
    auto start = std::chrono::steady_clock::now();
    auto elapsedMs = [&] {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
    };
    switch (params.scheme) {
        case SchemeKind::Brute: {
            BruteForce b(scene);
            AccelInfo info;
            info.regions = b.regionCount();
            info.memoryBytes = b.memoryBytes();
            info.buildMs = elapsedMs();
            return std::make_unique<Accelerator>(std::move(b), params, std::move(info));
        }
        case SchemeKind::Regular: {
            RegularGrid g(scene, params);
            AccelInfo info;
            info.regions = g.regionCount();
            info.memoryBytes = g.memoryBytes();
            info.extra = g.extra();
            LightBuffer lb = lightBufferFor(scene, params, info);
            info.buildMs = elapsedMs();
            return std::make_unique<Accelerator>(std::move(g), params, std::move(info), std::move(lb));
        }
        case SchemeKind::Irregular: {
            AccelInfo info;
            IrregularSubdivision s = IrregularSubdivision::build(scene, params, info.extra);
            info.regions = s.regionCount();
            info.memoryBytes = s.memoryBytes();
            LightBuffer lb = lightBufferFor(scene, params, info);
            info.buildMs = elapsedMs();
            return std::make_unique<Accelerator>(std::move(s), params, std::move(info), std::move(lb));
        }
    }
    throw std::logic_error("buildAccelerator: unknown scheme");
}

}  // namespace lancer
