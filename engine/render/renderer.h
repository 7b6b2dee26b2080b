// Multithreaded rendering over tiles (oneTBB), with per-pixel counters and cancellation.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <optional>

#include "engine/render/image.h"
#include "engine/render/tracer.h"

namespace lancer {

struct RenderOptions {
    int width = 512, height = 512;
    int threads = 0;  ///< 0: all cores
    int tile = 16;
    ShadingOptions shading;
    std::optional<Camera> camera;  ///< overrides scene.camera (the viewer moves its own camera)
};

struct RenderStats {
    RayCounters counters;
    double renderMs = 0.0;
    int threads = 1;
    bool cancelled = false;
};

/// Pixels of one progressive pass: those on the `stride` lattice that were not on the
/// `previousStride` lattice (0: none rendered before), in rows [rowBegin, rowEnd) (rowEnd -1:
/// to the last row), so a long pass can be rendered, and shown, band by band.
struct PassLattice {
    int stride = 1;
    int previousStride = 0;
    int rowBegin = 0, rowEnd = -1;
    bool contains(int x, int y) const {
        if (x % stride || y % stride) return false;
        return previousStride == 0 || (x % previousStride) || (y % previousStride);
    }
    /// Pixels of a width x height image in this pass.
    size_t pixels(int width, int height) const {
        const int end = rowEnd < 0 ? height : std::min(rowEnd, height);
        size_t n = 0;
        for (int y = std::max(0, rowBegin); y < end; ++y)
            for (int x = 0; x < width; ++x) n += contains(x, y);
        return n;
    }
};

/// Render the pixels of `pass` into `img` (already sized). Stops early, with
/// `cancelled` set, when `*cancel` becomes true. `progress` counts finished pixels. `eye`: the
/// accelerator's eye buffer for this camera (Accelerator::eyeBuffer), when the caller renders
/// several passes of one view and builds it once; null: built here.
RenderStats render(const Scene& scene, const Accelerator& accel, const RenderOptions& opt,
                   Image& img, PassLattice pass = {}, const std::atomic<bool>* cancel = nullptr,
                   std::atomic<size_t>* progress = nullptr, const LightBuffer* eye = nullptr);

/// Threads a render with `requested` threads uses (0: all cores).
int effectiveThreads(int requested);

/// A worker's trace context as render() makes it: scratch for a tree of `treeDepth`, mailboxes
/// as the structure uses them, the primitives' tests in `precision`. Every pass over an image
/// (the render, the viewer's region costs) takes its contexts from here.
TraceContext workerContext(const Scene& scene, const Accelerator& accel, int treeDepth,
                           Precision precision);

}  // namespace lancer
