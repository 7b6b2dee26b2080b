// The acceleration schemes as one closed set: brute force (the reference), the regular
// subdivision and the irregular subdivision of Arnaldi, Priol and Bouatouch (1986).
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>

#include "engine/accel/brute_force.h"
#include "engine/accel/build_guard.h"
#include "engine/accel/irregular/irregular.h"
#include "engine/accel/light_buffer.h"
#include "engine/accel/regular/regular_grid.h"

namespace lancer {

enum class SchemeKind : uint8_t { Brute, Regular, Irregular };
enum class StepMethod : uint8_t { Exact, Push };
enum class BspHeuristic : uint8_t { First, Balanced, FewestCuts };
/// Regular scheme: the axis each level of the BSP cuts. Cycle: x, y, z in turn (the report's);
/// cost: per level, the axis of least estimated cost (regular_grid.cpp, planSchedule).
enum class SplitAxes : uint8_t { Cycle, Cost };
/// Irregular scheme: primary rays walk the camera-frame structure, or the projective zones.
enum class IrregularFrame : uint8_t { Camera, Projective };

const char* schemeName(SchemeKind k);
const char* stepName(StepMethod s);
const char* heuristicName(BspHeuristic h);
const char* splitAxesName(SplitAxes s);
const char* irregularFrameName(IrregularFrame f);

/// Builder parameters: a plain struct the command line, the viewer and the tests fill in.
struct BuildParams {
    SchemeKind scheme = SchemeKind::Brute;
    /// Deepest subdivision level (regular: total BSP depth, one axis cut per level). 24 and 4
    /// measured best for the regular scheme (README, "Regular subdivision"): balls4 11.7
    /// primitive tests per ray (at 18 / 2: 65), and no built-in CSG scene explodes (at 24 / 2
    /// lattice does, where box faces run through other boxes). Were 18 and 2.
    int maxLevel = 24;
    int maxObjects = 4;  ///< stop subdividing a cell holding at most this many primitives
    StepMethod step = StepMethod::Exact;
    double delta = 1e-6;  ///< push distance, relative to the scene box's largest extent
    BspHeuristic heuristic = BspHeuristic::Balanced;
    SplitAxes splitAxes = SplitAxes::Cost;  ///< regular: which axis each level cuts
    bool mailboxes = true;                  ///< --no-mailbox turns them off to measure their effect
    /// Accelerated schemes: shorten shadow rays with the light buffer (light_buffer.h);
    /// --no-light-buffer turns it off to measure its effect. Brute force never uses it.
    bool lightBuffer = true;
    bool fullTable = false;  ///< regular: one full directory table instead of sub-tables
    IrregularFrame irregularFrame = IrregularFrame::Projective;  ///< --irregular-frame
    /// Bytes the structure may take while it is built (--memory-budget); 0: defaultMemoryBudget()
    /// (build_guard.h). A build over it stops subdividing or is refused, naming the budget.
    size_t memoryBudget = 0;
};

/// What a built structure reports: `--stats` and the viewer show it.
struct AccelInfo {
    double buildMs = 0.0;
    size_t regions = 1;
    size_t memoryBytes = 0;
    nlohmann::json extra = nlohmann::json::object();  ///< scheme-specific figures
};

class Accelerator {
  public:
    using Impl = std::variant<BruteForce, RegularGrid, IrregularSubdivision>;

    Accelerator(Impl impl, BuildParams params, AccelInfo info, LightBuffer lightBuffer = {})
        : impl_(std::move(impl)),
          params_(params),
          info_(std::move(info)),
          lightBuffer_(std::move(lightBuffer)) {}

    /// Nearest visible hit with t in (tmin, tmax]; reports the walk to `obs`.
    template <class Obs>
    bool intersect(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                   Hit& hit) const {
        return std::visit(
            [&](const auto& s) { return s.intersect(ray, tmin, tmax, ctx, obs, hit); }, impl_);
    }
    /// Whether the shadow ray toward scene light `light` (its direction points at the light)
    /// meets anything with t in (0, tmax]: the answer intersect() gives. The accelerated schemes
    /// first ask the light buffer which stretches of the ray can meet anything at all, and walk
    /// only those (light_buffer.h).
    template <class Obs>
    bool occluded(const Ray& ray, double tmax, uint32_t light, TraceContext& ctx, Obs& obs) const {
        Hit hit;
        if (!lightBuffer_.empty()) {
            LightBuffer::Segment seg[LightBuffer::kSlots];
            const int n = lightBuffer_.shadowSegments(ray.o, ray.d, light, tmax, seg);
            if (n >= 0) {  // else the buffer does not know: the whole ray below
                ctx.counters.lightBufferSkips += n == 0;
                for (int i = 0; i < n; ++i) {
                    // Each stretch is a walk of its own: a fresh mailbox id, so the primitives a
                    // stretch tests are fresh to it (a walk's boundary check relies on that).
                    if (i > 0) ctx.newStamp();
                    if (intersect(ray, seg[i].t0, seg[i].t1, ctx, obs, hit)) return true;
                }
                return false;
            }
        }
        return intersect(ray, 0.0, tmax, ctx, obs, hit);
    }
    /// The light buffer built from a perspective camera's eye (light_buffer.h), for primary
    /// rays: the regular scheme's, when it uses a light buffer; empty otherwise (brute force is
    /// the reference, and the irregular scheme's projective zones already start primary rays
    /// where they meet their first region).
    LightBuffer eyeBuffer(const Scene& scene, const Camera& cam) const {
        if (!params_.lightBuffer || params_.scheme != SchemeKind::Regular ||
            cam.projection != Projection::Perspective)
            return {};
        return LightBuffer(scene.bounds, scene.minBox, {cam.from}, LightBuffer::kBins, 1);
    }
    bool usesMailboxes() const {
        return params_.mailboxes &&
               std::visit([](const auto& s) { return s.usesMailboxes(); }, impl_);
    }
    const BuildParams& params() const { return params_; }
    const AccelInfo& info() const { return info_; }
    const Impl& impl() const { return impl_; }

  private:
    Impl impl_;
    BuildParams params_;
    AccelInfo info_;
    LightBuffer lightBuffer_;  ///< empty for brute force and with --no-light-buffer
};

/// Build the scheme named in `params` over a prepared scene. Throws std::invalid_argument for
/// parameters that are refused (for example a max level whose structure would not fit), and
/// BuildCancelled when `control.stop` is requested (within 100 ms: the builders poll it).
std::unique_ptr<Accelerator> buildAccelerator(const Scene& scene, const BuildParams& params,
                                              const BuildControl& control = {});

}  // namespace lancer
