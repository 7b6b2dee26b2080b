// The traversal's observer: every scheme, the light buffer and the tracer's shading report what
// they do to an object of this shape. Rendering passes NullObserver, whose empty inline members
// cost nothing (calls whose arguments cost something to form are also wrapped in
// `if constexpr (Obs::kActive)`); `lancer trace`, the viewer's ray playback and the tests pass a
// RecordingObserver, or the ray tree's recorder built on it (engine/render/ray_tree.h).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/model/span.h"

namespace lancer {

struct Scene;

/// The visible hit: a span boundary on primitive `prim`.
struct Hit {
    double t = kInf;
    uint32_t prim = kNoPrim;
    uint8_t part = 0;
    bool flip = false;
    bool valid() const { return prim != kNoPrim; }
    /// "t = 4.25 on p3 (part 1)", or "no hit".
    std::string toString() const;
};

/// Why a ray of a pixel's tree was cast.
enum class RayKind : uint8_t { Primary, Shadow, Reflection, Refraction };
/// "primary", "shadow", "reflection", "refraction" (the trace JSON's names).
const char* rayKindName(RayKind k);

/// How a ray of a pixel's tree ended, as the tracer tells it.
struct RayEnd {
    RayKind kind = RayKind::Primary;
    Hit hit;           ///< the visible hit; none for shadow rays (their blocker comes as blocker())
    Vec3 point{0.0};   ///< the hit point
    Vec3 normal{0.0};  ///< outward (solids), facing the ray (surfaces)
    bool occluded = false;  ///< shadow rays: something lies between the origin and the light
};

struct NullObserver {
    static constexpr bool kActive = false;
    // The walk inside a region.
    void region(uint32_t /*id*/, double /*t0*/, double /*t1*/) {}
    void primTest(uint32_t /*prim*/, const Span* /*spans*/, int /*n*/) {}
    void mailboxHit(uint32_t /*prim*/) {}
    void regionSpans(const SpanList& /*spans*/) {}
    // A node of the tree evaluated (evalTree): its spans along the whole line. Not reached from
    // the render path (wrapped in `if constexpr (Obs::kActive)`).
    void csgNode(int /*node*/, const SpanList& /*spans*/) {}
    void walkError(const char* /*what*/) {}
    // From region to region. Irregular: the region a walk starts in, the exit (with the tied
    // axes: face, edge or corner) and each corner pointer followed.
    void locate(const Vec3& /*point*/, uint32_t /*region*/) {}
    void regionExit(double /*t*/, const Vec3& /*point*/, int /*axis*/, int /*ties*/) {}
    void pointer(uint32_t /*from*/, uint32_t /*to*/, int /*corner*/) {}
    // Regular: the directory cell looked up (start and step), the pushed point (push), the
    // index step (exact) or the rope followed (exact, a face one leaf covers).
    void lookup(const Vec3& /*point*/, const uint32_t /*cell*/[3], uint32_t /*leaf*/) {}
    void push(const Vec3& /*point*/, int /*axes*/) {}
    void indexStep(int /*axis*/, const uint32_t /*cell*/[3]) {}
    void rope(uint32_t /*from*/, int /*face*/, uint32_t /*to*/) {}
    // BVH: an inner node's children the ray's interval meets, in the order they are visited
    // (`second` kNoNode when one or none is met), with the t each box is entered at; a node
    // left unvisited because its box begins beyond the hit found.
    void nodeChildren(uint32_t /*node*/, uint32_t /*first*/, double /*t0First*/,
                      uint32_t /*second*/, double /*t0Second*/) {}
    void nodeCulled(uint32_t /*node*/, double /*t0*/, double /*best*/) {}
    void walkRestart(const char* /*why*/) {}
    // Shadow rays and the light buffer: each stretch walked, none to walk, what blocked it.
    void stretch(int /*index*/, double /*t0*/, double /*t1*/) {}
    void lightBufferClear() {}
    void blocker(const Hit& /*hit*/) {}
    // The tracer: a ray of the pixel's tree begins (depth: bounces before it; light: the
    // shadow ray's light, else -1) and ends.
    void rayBegin(RayKind /*kind*/, int /*depth*/, int /*light*/, const Ray& /*ray*/,
                  double /*tmin*/, double /*tmax*/) {}
    void rayEnd(const RayEnd& /*end*/) {}
};

/// One event of a walk, in order. Which fields are set depends on the kind (see each kind).
struct WalkEvent {
    enum Kind : uint8_t {
        Region,      ///< a: region id; t0, t1: the ray's interval in it
        Pointer,     ///< a -> b by the corner pointer at `corner` (bit 0 x, 1 y, 2 z high)
        PrimTest,    ///< a: primitive; spans: its spans along the whole line
        MailboxHit,  ///< a: primitive whose spans the mailbox held
        Spans,       ///< spans: the region's tree along the whole line
        Error,       ///< what: why the walk ended
        Locate,      ///< point: where the walk starts (world); b: its region
        Exit,        ///< t0: where the region is left; point (world); axis; ties: axes mask
        Lookup,      ///< point: the point located (world); cell: directory cell; b: leaf
        Push,        ///< point: the exit point pushed across the axes in `ties` (world)
        IndexStep,   ///< axis: the exit axis; cell: the next cell's indices
        Rope,        ///< a -> b by the rope of face `axis` (2 * axis + 1 for the high face)
        Children,    ///< BVH: node `corner`'s children met, a (entered at t0) then b (at t1)
        Culled,      ///< BVH: node a not entered: its box begins at t0, beyond the hit at t1
        Restart,     ///< what: why the walk starts again another way (BVH: in box-entry order)
        Stretch,     ///< a: index; t0, t1: a stretch the light buffer leaves to walk
        LightBufferClear,  ///< the light buffer shows nothing can block: no walk
        Blocker,           ///< a: the primitive that blocks a shadow ray; t0: where
        RayBegin,  ///< point: origin; t0, t1: [tmin, tmax]; axis: RayKind; b: depth; corner: light
        RayEnd,  ///< axis: RayKind; a: hit primitive (kNoPrim: none); t0: hit t; point; b: occluded
    } kind = Region;
    uint32_t a = 0, b = 0;
    int corner = -1;
    double t0 = 0.0, t1 = 0.0;
    SpanList spans;
    std::string what;
    Vec3 point{0.0};
    uint32_t cell[3] = {0, 0, 0};
    int axis = -1;
    int ties = 0;

    /// One line, no newline: "region 12 t = [0.5, 1.25]", "test p3 spans {...}". With a scene,
    /// a primitive's description follows its number.
    std::string toString(const Scene* scene = nullptr) const;
    bool operator==(const WalkEvent&) const = default;
    /// The event opens a region's stretch of the walk (regions are the playback's steps).
    bool isRegion() const { return kind == Region; }
};

struct RecordingObserver {
    static constexpr bool kActive = true;
    std::vector<WalkEvent> events;

    void region(uint32_t id, double t0, double t1) {
        WalkEvent& e = add(WalkEvent::Region);
        e.a = id;
        e.t0 = t0;
        e.t1 = t1;
    }
    void primTest(uint32_t prim, const Span* spans, int n) {
        WalkEvent& e = add(WalkEvent::PrimTest);
        e.a = prim;
        e.spans.assign(spans, spans + n);
    }
    void mailboxHit(uint32_t prim) { add(WalkEvent::MailboxHit).a = prim; }
    void regionSpans(const SpanList& s) { add(WalkEvent::Spans).spans = s; }
    /// Not recorded: a walk's events keep the primitives' spans and the tree's, from which
    /// evalNodes (engine/render/ray_csg.h) gets every node's again with evalTree.
    void csgNode(int /*node*/, const SpanList& /*spans*/) {}
    void walkError(const char* what) { add(WalkEvent::Error).what = what; }
    void locate(const Vec3& point, uint32_t region) {
        WalkEvent& e = add(WalkEvent::Locate);
        e.point = point;
        e.b = region;
    }
    void regionExit(double t, const Vec3& point, int axis, int ties) {
        WalkEvent& e = add(WalkEvent::Exit);
        e.t0 = t;
        e.point = point;
        e.axis = axis;
        e.ties = ties;
    }
    void pointer(uint32_t from, uint32_t to, int corner) {
        WalkEvent& e = add(WalkEvent::Pointer);
        e.a = from;
        e.b = to;
        e.corner = corner;
    }
    void lookup(const Vec3& point, const uint32_t cell[3], uint32_t leaf) {
        WalkEvent& e = add(WalkEvent::Lookup);
        e.point = point;
        for (int i = 0; i < 3; ++i) e.cell[i] = cell[i];
        e.b = leaf;
    }
    void push(const Vec3& point, int axes) {
        WalkEvent& e = add(WalkEvent::Push);
        e.point = point;
        e.ties = axes;
    }
    void indexStep(int axis, const uint32_t cell[3]) {
        WalkEvent& e = add(WalkEvent::IndexStep);
        e.axis = axis;
        for (int i = 0; i < 3; ++i) e.cell[i] = cell[i];
    }
    void rope(uint32_t from, int face, uint32_t to) {
        WalkEvent& e = add(WalkEvent::Rope);
        e.a = from;
        e.b = to;
        e.axis = face;
    }
    void nodeChildren(uint32_t node, uint32_t first, double t0First, uint32_t second,
                      double t0Second) {
        WalkEvent& e = add(WalkEvent::Children);
        e.corner = int(node);
        e.a = first;
        e.t0 = t0First;
        e.b = second;
        e.t1 = t0Second;
    }
    void nodeCulled(uint32_t node, double t0, double best) {
        WalkEvent& e = add(WalkEvent::Culled);
        e.a = node;
        e.t0 = t0;
        e.t1 = best;
    }
    void walkRestart(const char* why) { add(WalkEvent::Restart).what = why; }
    void stretch(int index, double t0, double t1) {
        WalkEvent& e = add(WalkEvent::Stretch);
        e.a = uint32_t(index);
        e.t0 = t0;
        e.t1 = t1;
    }
    void lightBufferClear() { add(WalkEvent::LightBufferClear); }
    void blocker(const Hit& hit) {
        WalkEvent& e = add(WalkEvent::Blocker);
        e.a = hit.prim;
        e.t0 = hit.t;
    }
    void rayBegin(RayKind kind, int depth, int light, const Ray& ray, double tmin, double tmax) {
        WalkEvent& e = add(WalkEvent::RayBegin);
        e.axis = int(kind);
        e.b = uint32_t(depth);
        e.corner = light;
        e.point = ray.o;
        e.t0 = tmin;
        e.t1 = tmax;
    }
    void rayEnd(const RayEnd& end) {
        WalkEvent& e = add(WalkEvent::RayEnd);
        e.a = end.hit.prim;
        e.t0 = end.hit.t;
        e.point = end.point;
        e.b = end.occluded;
        e.axis = int(end.kind);
    }

  private:
    WalkEvent& add(WalkEvent::Kind k) {
        events.emplace_back();
        events.back().kind = k;
        return events.back();
    }
};

std::ostream& operator<<(std::ostream& os, const Hit& h);
std::ostream& operator<<(std::ostream& os, const WalkEvent& e);

}  // namespace lancer
