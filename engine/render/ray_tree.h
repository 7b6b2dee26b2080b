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

class StructureView;  // engine/accel/structure_view.h

/// Why the walk goes on from one region step: a sentence, and the region it names as the next
/// step's region.
struct StepReason {
    /// "left leaf 812 through its +x face at t = 3.21 (point (..)); exact index step +x to
    /// directory cell (12, 4, 7) -> leaf 977", "hit p17 sphere .. at t = 4.5 inside this region".
    /// The region the walk goes on to is named last, after "-> ".
    std::string text;
    int64_t next = -1;  ///< the next step's region; -1 when the ray ends in this region
};

/// One reason per region step of `r` (regionSteps() order), built from its recorded events and
/// the structure they were recorded in (region names, zones and slabs, directory sub-tables):
/// how the walk reached its first region; how it leaves each region and reaches the next (the
/// exit face, edge or corner; the rope, the exact index step or the pushed point and the
/// directory cell; the corner pointers; the next slab in depth; the next light-buffer stretch);
/// or how the ray ends there (the hit, the blocker, the structure's border, the end of its
/// interval, a walk error). With a scene, primitives are described.
std::vector<StepReason> explainSteps(const TracedRay& r, const StructureView& view,
                                     const Scene* scene = nullptr);
/// A region as the reasons name it: "leaf 977", "slab 0 of zone 12 (region 81)", "projective
/// slab 3 of zone 40 (region 900)", "the near region (region 1200)", "the scene box".
std::string regionName(const StructureView& view, uint32_t region);

/// The rays of one pixel, in the order traced (the primary first; a ray's children after it).
struct RayTree {
    int x = 0, y = 0, width = 0, height = 0;
    Vec3 color{0.0};       ///< the pixel's colour, as render() computes it
    RayCounters counters;  ///< the pixel's counters, as render() records them
    std::vector<TracedRay> rays;

    /// Indented text: each ray's line (indented by its generation), then its events below it.
    /// With a scene, primitive tests name the primitive; with the structure the rays were
    /// walked in, each region step is followed by its reason ("why: ...", explainSteps).
    std::string toString(const Scene* scene = nullptr, const StructureView* view = nullptr) const;
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
/// direction, tmin, tmax, events, hit (null when none), occluded (shadow rays). With the
/// structure, each region event also carries "why": its step's reason (explainSteps).
nlohmann::json toJson(const TracedRay& r, const Scene& scene, const RegionCornersFn& corners = {},
                      const StructureView* view = nullptr);
/// The trace JSON's counters: prim_tests, mailbox_hits, region_visits, ...
nlohmann::json toJson(const RayCounters& c);

std::ostream& operator<<(std::ostream& os, const TracedRay& r);
std::ostream& operator<<(std::ostream& os, const RayTree& t);

}  // namespace lancer
