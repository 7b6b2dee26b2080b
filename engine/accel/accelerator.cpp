#include "engine/accel/accelerator.h"

#include <chrono>
#include <future>
#include <optional>
#include <stdexcept>

namespace lancer {

namespace {

/// An accelerated scheme's structure, from `build`, and its light buffer, counted in its memory
/// and reported in `extra`. The light buffer needs only the scene, so it is built on another
/// thread meanwhile: the structure's build is single-threaded, and on balls4 the buffer took 5-7
/// of the 40-50 ms the two took one after the other.
template <class Structure, class Build, class Clock>
std::unique_ptr<Accelerator> withLightBuffer(const Scene& scene, const BuildParams& params,
                                             const BuildGuard& guard, Build&& build,
                                             Clock&& elapsedMs) {
    // The buffer stops with the build: a cancelled build waits for it below.
    std::future<LightBuffer> lightBuffer;
    if (params.lightBuffer)
        lightBuffer = std::async(std::launch::async, [&scene, stop = guard.control().stop] {
            return LightBuffer(scene, LightBuffer::kBins, stop);
        });
    AccelInfo info;
    info.treeDepth = scene.tree.depth();
    std::optional<Structure> s;
    try {
        s.emplace(build(info));
    } catch (...) {
        if (lightBuffer.valid()) lightBuffer.wait();  // it reads the scene
        throw;
    }
    info.regions = s->regionCount();
    info.memoryBytes = s->memoryBytes();
    LightBuffer lb = lightBuffer.valid() ? lightBuffer.get() : LightBuffer();
    guard.poll();  // the buffer may have stopped early
    if (params.lightBuffer) {
        info.memoryBytes += lb.memoryBytes();
        info.extra["light_buffer_bytes"] = lb.memoryBytes();
        info.extra["light_buffer_lights"] = lb.mappedLights();
    }
    info.buildMs = elapsedMs();
    return std::make_unique<Accelerator>(std::move(*s), params, std::move(info), std::move(lb));
}

}  // namespace

std::unique_ptr<Accelerator> buildAccelerator(const Scene& scene, const BuildParams& params,
                                              const BuildControl& control) {
    if (!scene.prepared) throw std::logic_error("buildAccelerator: scene not prepared");
    BuildGuard guard(params.memoryBudget, control);
    auto start = std::chrono::steady_clock::now();
    auto elapsedMs = [&] {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
    };
    switch (params.scheme) {
        case SchemeKind::Brute: {
            AccelInfo info;
            info.treeDepth = scene.tree.depth();
            BruteForce b = BruteForce::build(scene, BruteConfig{}, info.extra);
            info.regions = b.regionCount();
            info.memoryBytes = b.memoryBytes();
            info.buildMs = elapsedMs();
            return std::make_unique<Accelerator>(std::move(b), params, std::move(info));
        }
        case SchemeKind::Regular:
            return withLightBuffer<RegularGrid>(
                scene, params, guard,
                [&](AccelInfo& info) {
                    return RegularGrid::build(scene, params.regular, info.extra, &guard);
                },
                elapsedMs);
        case SchemeKind::Irregular:
            return withLightBuffer<IrregularSubdivision>(
                scene, params, guard,
                [&](AccelInfo& info) {
                    return IrregularSubdivision::build(scene, params.irregular, info.extra, &guard);
                },
                elapsedMs);
    }
    throw std::logic_error("buildAccelerator: unknown scheme");
}

}  // namespace lancer
