#include "engine/accel/accelerator.h"

#include <chrono>
#include <future>
#include <optional>
#include <stdexcept>

#include "engine/util/format.h"

namespace lancer {

namespace {

/// An accelerated scheme's structure, from `build`, and its light buffers (the lights', and the
/// scene camera's eye buffer when the scheme has one), counted in its memory and reported in
/// `extra`. The light buffers need only the scene, so they are built on another thread
/// meanwhile: on balls4 the lights' buffer took 5-7 of the 40-50 ms the two took one after the
/// other. The eye buffer is built here rather than by each render: on balls:6 it is some 25 ms
/// of one thread, every frame of an unmoved camera the same.
/// The lights' buffer and the turned boxes do not depend on the camera: `previous`
/// (BuildControl::previous), built over the same prepared scene with the same light buffer
/// setting and budget, lends them (copied: balls4's buffer is 1.6 MB, built in 5-7 ms).
template <class Structure, class Build, class Clock>
std::unique_ptr<Accelerator> withLightBuffer(const Scene& scene, const BuildParams& params,
                                             bool buffered, const BuildGuard& guard,
                                             const Accelerator* previous, Build&& build,
                                             Clock&& elapsedMs) {
    // The buffers stop with the build: a cancelled build waits for them below.
    // Both are cut by the primitives' boxes along the scene's turned frame, when it has one
    // (the frame the regular grid takes; chosen here too, which costs a pass over the
    // transforms when nothing is turned and a minimization per frame scored).
    struct Buffers {
        LightBuffer lights, eye;
        std::shared_ptr<const FrameChoice> turned;
    };
    const bool lend = buffered && previous && scene.preparedId != 0 &&
                      previous->info().sceneId == scene.preparedId &&
                      previous->params().scheme != SchemeKind::Brute &&
                      previous->params().lightBuffer == params.lightBuffer &&
                      previous->params().memoryBudget == params.memoryBudget;
    std::future<Buffers> lightBuffer;
    if (lend)
        lightBuffer = std::async(
            std::launch::async, [&scene, &params, previous, stop = guard.control().stop] {
                std::shared_ptr<const FrameChoice> turned = previous->turnedBoxes();
                Buffers b{previous->lightBuffer(), {}, turned};
                b.eye = Accelerator::makeEyeBuffer(scene, scene.camera, params, stop, turned.get());
                return b;
            });
    else if (buffered)
        lightBuffer =
            std::async(std::launch::async, [&scene, &params, stop = guard.control().stop] {
                auto turned = std::make_shared<const FrameChoice>(chooseGridFrame(scene));
                Buffers b{LightBuffer(scene, LightBuffer::kBins, stop, turned.get()), {}, {}};
                b.eye = Accelerator::makeEyeBuffer(scene, scene.camera, params, stop, turned.get());
                if (turned->frame.turned) b.turned = std::move(turned);
                return b;
            });
    AccelInfo info;
    info.treeDepth = scene.tree.depth();
    info.sceneId = scene.preparedId;
    std::optional<Structure> s;
    try {
        s.emplace(build(info));
    } catch (...) {
        if (lightBuffer.valid()) lightBuffer.wait();  // it reads the scene
        throw;
    }
    info.regions = s->regionCount();
    info.memoryBytes = s->memoryBytes();
    Buffers lb = lightBuffer.valid() ? lightBuffer.get() : Buffers();
    guard.poll();  // the buffers may have stopped early
    std::shared_ptr<const LightBuffer> eye;
    if (buffered) {
        info.memoryBytes += lb.lights.memoryBytes() + lb.eye.memoryBytes() +
                            (lb.turned ? lb.turned->boxes.size() * sizeof(Box3) : 0);
        info.extra["light_buffer_bytes"] = lb.lights.memoryBytes();
        info.extra["light_buffer_lights"] = lb.lights.mappedLights();
        info.extra["light_buffer_lent"] = lend;
        if (Accelerator::hasEyeBuffer(params, scene.camera)) {
            info.extra["eye_buffer_bytes"] = lb.eye.memoryBytes();
            eye = std::make_shared<const LightBuffer>(std::move(lb.eye));
        }
    } else if (params.lightBuffer) {
        info.extra["light_buffer_left_out"] =
            formatBytes(LightBuffer::bytesAtMost(scene.lights.size())) +
            " is over a quarter of the memory budget (--memory-budget " +
            formatBytes(guard.given()) + ")";
    }
    info.buildMs = elapsedMs();
    return std::make_unique<Accelerator>(std::move(*s), params, std::move(info),
                                         std::move(lb.lights), std::move(eye), scene.camera.from,
                                         std::move(lb.turned));
}

/// Scheme `S`'s structure: brute force alone (nothing to walk around, so no light buffer), an
/// accelerated scheme with its light buffers.
template <class S, class Clock>
std::unique_ptr<Accelerator> buildOne(const Scene& scene, const BuildParams& params, bool buffered,
                                      BuildGuard& guard, const Accelerator* previous,
                                      Clock&& elapsedMs) {
    if constexpr (S::kKind == SchemeKind::Brute) {
        AccelInfo info;
        info.treeDepth = scene.tree.depth();
        info.sceneId = scene.preparedId;
        S b = S::build(scene, S::config(params), info.extra, &guard);
        info.regions = b.regionCount();
        info.memoryBytes = b.memoryBytes();
        info.buildMs = elapsedMs();
        return std::make_unique<Accelerator>(std::move(b), params, std::move(info));
    } else {
        // A scheme whose build takes a previous structure of its kind gets the one given, when it
        // is of its kind and over the same scene (its build checks the rest).
        const S* prev = previous && previous->info().sceneId == scene.preparedId
                            ? std::get_if<S>(&previous->impl())
                            : nullptr;
        return withLightBuffer<S>(
            scene, params, buffered, guard, previous,
            [&](AccelInfo& info) {
                if constexpr (requires {
                                  S::build(scene, S::config(params), info.extra, &guard, prev);
                              })
                    return S::build(scene, S::config(params), info.extra, &guard, prev);
                else
                    return S::build(scene, S::config(params), info.extra, &guard);
            },
            elapsedMs);
    }
}

/// The build of the alternative of Accelerator::Impl whose kind `params` names.
template <class Clock, size_t... I>
std::unique_ptr<Accelerator> buildScheme(const Scene& scene, const BuildParams& params,
                                         bool buffered, BuildGuard& guard,
                                         const Accelerator* previous, Clock&& elapsedMs,
                                         std::index_sequence<I...>) {
    std::unique_ptr<Accelerator> out;
    ((params.scheme == SchemeKind(I)
          ? (void)(out = buildOne<std::variant_alternative_t<I, Accelerator::Impl>>(
                       scene, params, buffered, guard, previous, elapsedMs))
          : (void)0),
     ...);
    if (!out) throw std::logic_error("buildAccelerator: unknown scheme");
    return out;
}

}  // namespace

std::unique_ptr<Accelerator> buildAccelerator(const Scene& scene, const BuildParams& params,
                                              const BuildControl& control) {
    if (!scene.prepared) throw std::logic_error("buildAccelerator: scene not prepared");
    // The light buffer is held with the structure, so its bytes (known before it is built) come
    // out of the budget. It only shortens shadow rays' walks (the same hits without it): when it
    // would take more than a quarter of the budget, it is left out and the structure gets all.
    const size_t budget = params.memoryBudget ? params.memoryBudget : defaultMemoryBudget();
    const size_t lightBytes = params.scheme != SchemeKind::Brute && params.lightBuffer
                                  ? LightBuffer::bytesAtMost(scene.lights.size()) +
                                        (Accelerator::hasEyeBuffer(params, scene.camera)
                                             ? LightBuffer::bytesAtMost(1, LightBuffer::kBins, 1)
                                             : 0)
                                  : 0;
    const bool buffered = params.lightBuffer && lightBytes <= budget / 4;
    BuildGuard guard(budget, control, buffered ? lightBytes : 0);
    auto start = std::chrono::steady_clock::now();
    auto elapsedMs = [&] {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
            .count();
    };
    return buildScheme(scene, params, buffered, guard, control.previous, elapsedMs,
                       std::make_index_sequence<kSchemeCount>());
}

}  // namespace lancer
