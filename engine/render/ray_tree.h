// A pixel's ray tree: every ray the tracer casts for one pixel (primary, one shadow ray per light
// the surface faces, reflection and refraction down to the bounce limit), each with its walk as
// the observer saw it. Recorded by the same code that renders (Tracer::pixel with an observer
// instead of NullObserver), so its counts are the renderer's per-pixel counters, and `lancer
// trace`, the viewer's ray playback and the tests read one thing.
#pragma once

#include <functional>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "engine/render/tracer.h"

namespace lancer {

/// One ray of a pixel's tree.
struct TracedRay {
    RayKind kind = RayKind::Primary;
    int parent = -1;  ///< index of the ray whose hit cast it; -1 for the primary ray
    int light = -1;   ///< shadow rays: the scene light it heads for; -1 otherwise
    int depth = 0;    ///< reflection/refraction bounces before it (shadow rays: their parent's)
    Vec3 origin{0.0}, direction{0.0};
    double tmin = 0.0, tmax = kInf;  ///< the interval the ray is walked over
    /// Its walk in order: RayBegin first, RayEnd last, the scheme's events between.
    std::vector<WalkEvent> events;
    /// The visible hit (shadow rays: the blocker found), kNoPrim when none.
    Hit hit;
    Vec3 point{0.0};        ///< at the hit
    Vec3 normal{0.0};       ///< at the hit: outward (solids), facing the ray (surfaces)
    bool occluded = false;  ///< shadow rays: the light is blocked
    RayCounters counters;   ///< counted from its events (rays, tests, mailbox hits, regions...)

    /// Index in `events` of each Region event, in order: the playback's steps.
    std::vector<size_t> regionSteps() const;
    /// "#2 shadow of #0 to light 1 from (..) dir (..) t = [0, 12]: occluded" (no newline).
    std::string toString() const;
};

/// The rays of one pixel, in the order traced (the primary first; a ray's children after it).
struct RayTree {
    int x = 0, y = 0, width = 0, height = 0;
    Vec3 color{0.0};       ///< the pixel's colour, as render() computes it
    RayCounters counters;  ///< the pixel's counters, as render() records them
    std::vector<TracedRay> rays;

    /// Indented text: each ray's line (indented by its generation), then its events below it.
    /// With a scene, primitive tests name the primitive.
    std::string toString(const Scene* scene = nullptr) const;
};

/// The observer that builds a RayTree: a RecordingObserver whose events are split per ray.
struct RayTreeRecorder : RecordingObserver {
    std::vector<TracedRay> rays;

    void rayBegin(RayKind kind, int depth, int light, const Ray& ray, double tmin, double tmax);
    void rayEnd(const RayEnd& end);
    void blocker(const Hit& hit);

  private:
    std::vector<int> shadedAt_;  ///< per depth: the last non-shadow ray begun there
};

/// Trace pixel (x, y) of a w x h image seen by `cam`, as render() does, recording its tree.
RayTree tracePixel(const Scene& scene, const Accelerator& accel, const ShadingOptions& shading,
                   const Camera& cam, int x, int y, int w, int h);

/// The 8 world-space corners of a region, corner i + 2j + 4k (docs/design.md section 6, "Trace
/// JSON"); empty when unknown.
using RegionCornersFn = std::function<std::vector<Vec3>(uint32_t region)>;

/// One event as the trace JSON writes it ({"event": "region", "region", "t0", "t1", ...});
/// region events carry "corners" when `corners` gives them.
nlohmann::json toJson(const WalkEvent& e, const RegionCornersFn& corners = {});
/// A ray as the trace JSON's "rays" lists it: kind, parent, light (shadow rays), origin,
/// direction, tmin, tmax, events, hit (null when none), occluded (shadow rays).
nlohmann::json toJson(const TracedRay& r, const Scene& scene, const RegionCornersFn& corners = {});
/// The trace JSON's counters: prim_tests, mailbox_hits, region_visits, ...
nlohmann::json toJson(const RayCounters& c);

std::ostream& operator<<(std::ostream& os, const TracedRay& r);
std::ostream& operator<<(std::ostream& os, const RayTree& t);

}  // namespace lancer
