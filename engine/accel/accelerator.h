// The acceleration schemes as one closed set: brute force (the reference), the regular
// subdivision and the irregular subdivision of Arnaldi, Priol and Bouatouch (1986), and a BVH
// (the modern baseline). Each is a class meeting AccelerationScheme, an alternative of
// Accelerator::Impl at its SchemeKind's index, and a row of kSchemeTable (build_params.h).
#pragma once

#include <concepts>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <variant>

#include "engine/accel/brute_force.h"
#include "engine/accel/build_guard.h"
#include "engine/accel/build_params.h"
#include "engine/accel/bvh/bvh.h"
#include "engine/accel/irregular/irregular.h"
#include "engine/accel/light_buffer.h"
#include "engine/accel/regular/regular_grid.h"

namespace lancer {

/// What every scheme is: built from the scene and its own knobs (`S::config` picks them out of
/// BuildParams; the scheme's figures go to `extra`, the guard bounds and cancels the build),
/// it walks a ray with any observer (the render's null one, the trace's recording one) and
/// reports its regions and bytes. Its regions' description lives in structure_view.h. A scheme
/// may also have `occluded(ray, tmin, tmax, ctx, obs, hit)`, intersect()'s answer by a walk
/// that stops at the first boundary it is sure of (shadow rays take it when it is there).
template <class S>
concept AccelerationScheme = requires(const S& s, const Scene& scene, const BuildParams& p,
                                      nlohmann::json& extra, BuildGuard* guard, const Ray& ray,
                                      TraceContext& ctx, NullObserver& null, RecordingObserver& rec,
                                      Hit& hit) {
    { S::kKind } -> std::convertible_to<SchemeKind>;
    { S::build(scene, S::config(p), extra, guard) } -> std::same_as<S>;
    { s.intersect(ray, 0.0, 1.0, ctx, null, hit) } -> std::same_as<bool>;
    { s.intersect(ray, 0.0, 1.0, ctx, rec, hit) } -> std::same_as<bool>;
    { s.regionCount() } -> std::convertible_to<size_t>;
    { s.memoryBytes() } -> std::convertible_to<size_t>;
    { s.usesMailboxes() } -> std::convertible_to<bool>;
};

/// What a built structure reports: `--stats` and the viewer show it.
struct AccelInfo {
    double buildMs = 0.0;
    size_t regions = 1;
    size_t memoryBytes = 0;
    nlohmann::json extra = nlohmann::json::object();  ///< scheme-specific figures
    /// Depth of the scene's tree the structure was built on (TraceContext's scratch buffers),
    /// so a render need not walk the tree again (10 ms on a union of 600,000); -1: not known.
    int treeDepth = -1;
    uint64_t sceneId = 0;  ///< Scene::preparedId of the scene it was built over
};

class Accelerator {
  public:
    /// The schemes, alternative i being scheme SchemeKind(i) (checked below).
    using Impl = std::variant<BruteForce, RegularGrid, IrregularSubdivision, Bvh>;

    /// `eye`: the eye buffer of the camera at `eyeFrom` (eyeBuffer() returns it for a camera
    /// there), null when none was built with the structure; `turned`: the primitives' turned
    /// boxes the buffers were cut by (null: none), for the eye buffers of other cameras.
    Accelerator(Impl impl, BuildParams params, AccelInfo info, LightBuffer lightBuffer = {},
                std::shared_ptr<const LightBuffer> eye = {}, Vec3 eyeFrom = Vec3(0.0),
                std::shared_ptr<const FrameChoice> turned = {})
        : impl_(std::move(impl)),
          params_(params),
          info_(std::move(info)),
          lightBuffer_(std::move(lightBuffer)),
          eyeBuffer_(std::move(eye)),
          eyeFrom_(eyeFrom),
          turned_(std::move(turned)) {}

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
                if constexpr (Obs::kActive)
                    if (n == 0) obs.lightBufferClear();
                for (int i = 0; i < n; ++i) {
                    // Each stretch is a walk of its own: a fresh mailbox id, so the primitives a
                    // stretch tests are fresh to it (a walk's boundary check relies on that).
                    if (i > 0) ctx.newStamp();
                    obs.stretch(i, seg[i].t0, seg[i].t1);
                    double t0 = seg[i].t0, t1 = seg[i].t1;
                    if (ctx.precision == Precision::Float) widenForFloat(ray, t0, t1, 0.0, tmax);
                    if (blockedIn(ray, light, t0, t1, ctx, obs, hit)) {
                        obs.blocker(hit);
                        return true;
                    }
                }
                return false;
            }
        }
        const bool blocked = blockedIn(ray, light, 0.0, tmax, ctx, obs, hit);
        if constexpr (Obs::kActive)
            if (blocked) obs.blocker(hit);
        return blocked;
    }
    /// The light buffer built from a perspective camera's eye (light_buffer.h), for primary
    /// rays: the regular scheme's, when it uses a light buffer; empty otherwise (brute force is
    /// the reference, and the irregular scheme's projective zones already start primary rays
    /// where they meet their first region). The one built with the structure for the scene's
    /// camera when `cam` has its eye; else built now. Never null.
    std::shared_ptr<const LightBuffer> eyeBuffer(const Scene& scene, const Camera& cam) const {
        if (eyeBuffer_ && cam.projection == Projection::Perspective && cam.from == eyeFrom_)
            return eyeBuffer_;
        return std::make_shared<const LightBuffer>(
            makeEyeBuffer(scene, cam, params_, {}, turned_.get()));
    }
    /// Whether a scheme built with `params` gives `cam` an eye buffer.
    static bool hasEyeBuffer(const BuildParams& params, const Camera& cam) {
        return params.lightBuffer && params.scheme == SchemeKind::Regular &&
               cam.projection == Projection::Perspective;
    }
    /// The eye buffer of `cam` for a scheme built with `params` (empty when it has none), the
    /// boxes cut by their turned ones (`turned`; null: none); a requested `stop` ends it early,
    /// empty.
    static LightBuffer makeEyeBuffer(const Scene& scene, const Camera& cam,
                                     const BuildParams& params, std::stop_token stop = {},
                                     const FrameChoice* turned = nullptr) {
        if (!hasEyeBuffer(params, cam)) return {};
        return LightBuffer::forEye(scene, cam.from, std::move(stop), turned);
    }
    bool usesMailboxes() const {
        return params_.mailboxes &&
               std::visit([](const auto& s) { return s.usesMailboxes(); }, impl_);
    }
    const BuildParams& params() const { return params_; }
    const AccelInfo& info() const { return info_; }
    /// The lights' buffer (light_buffer.h): empty for brute force and with --no-light-buffer.
    const LightBuffer& lightBuffer() const { return lightBuffer_; }
    /// The primitives' turned boxes the buffers were cut by, or null.
    const std::shared_ptr<const FrameChoice>& turnedBoxes() const { return turned_; }
    const Impl& impl() const { return impl_; }

  private:
    /// intersect()'s answer for a shadow ray's stretch toward scene light `light`: by the
    /// scheme's own `occluded` walk when it has one (it may stop at any boundary, `hit`, rather
    /// than the nearest), or its walk toward that light.
    template <class Obs>
    bool blockedIn(const Ray& ray, uint32_t light, double tmin, double tmax, TraceContext& ctx,
                   Obs& obs, Hit& hit) const {
        return std::visit(
            [&](const auto& s) {
                if constexpr (requires {
                                  s.intersectTowardLight(ray, light, tmin, tmax, ctx, obs, hit);
                              })
                    return s.intersectTowardLight(ray, light, tmin, tmax, ctx, obs, hit);
                else if constexpr (requires { s.occluded(ray, tmin, tmax, ctx, obs, hit); })
                    return s.occluded(ray, tmin, tmax, ctx, obs, hit);
                else
                    return s.intersect(ray, tmin, tmax, ctx, obs, hit);
            },
            impl_);
    }

    Impl impl_;
    BuildParams params_;
    AccelInfo info_;
    LightBuffer lightBuffer_;  ///< empty for brute force and with --no-light-buffer
    std::shared_ptr<const LightBuffer> eyeBuffer_;  ///< the scene camera's eye buffer, or null
    Vec3 eyeFrom_;                                  ///< where eyeBuffer_ was built from
    std::shared_ptr<const FrameChoice> turned_;     ///< the buffers' turned boxes, or null
};

// Each alternative of Accelerator::Impl is a scheme, at its SchemeKind's index: a scheme added
// to the table but not to Impl (or the other way round, or out of order) does not compile.
static_assert(std::variant_size_v<Accelerator::Impl> == size_t(kSchemeCount),
              "Accelerator::Impl holds one alternative per row of kSchemeTable");
static_assert(
    []<size_t... I>(std::index_sequence<I...>) {
        return ((AccelerationScheme<std::variant_alternative_t<I, Accelerator::Impl>> &&
                 std::variant_alternative_t<I, Accelerator::Impl>::kKind == SchemeKind(I)) &&
                ...);
    }(std::make_index_sequence<kSchemeCount>()),
    "alternative i of Accelerator::Impl meets AccelerationScheme with kKind "
    "SchemeKind(i)");

/// Build the scheme named in `params` over a prepared scene. Throws std::invalid_argument for
/// parameters that are refused (for example a max level whose structure would not fit), and
/// BuildCancelled when `control.stop` is requested (within 100 ms: the builders poll it).
std::unique_ptr<Accelerator> buildAccelerator(const Scene& scene, const BuildParams& params,
                                              const BuildControl& control = {});

}  // namespace lancer
