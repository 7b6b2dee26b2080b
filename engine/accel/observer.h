// The traversal's observer: every scheme, the light buffer and the tracer's shading report what
// they do to an object of this shape. Rendering passes NullObserver, whose empty inline members
// cost nothing (calls whose arguments cost something to form are also wrapped in
// `if constexpr (Obs::kActive)`); `lancer trace`, the viewer's ray playback and the tests pass a
// RecordingObserver, or the ray tree's recorder built on it (engine/render/ray_tree.h).
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
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
    // BVH: a wide node's children (at most four) whose boxes the ray's interval meets, in the
    // order they are visited, with the t each box is entered at; a node left unvisited because
    // its box begins beyond the hit found (`blocked`: a shadow ray's walk that knows it is
    // blocked, and skips every box not holding the ray's start).
    void nodeChildren(uint32_t /*node*/, const uint32_t* /*children*/, const double* /*t0s*/,
                      int /*count*/) {}
    void nodeCulled(uint32_t /*node*/, double /*t0*/, double /*best*/, bool /*blocked*/) {}
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

/// The events of a walk, each with its own named fields; a WalkEvent holds one of them.
namespace walk {
/// A region entered, with the ray's interval in it (regions are the playback's steps).
struct Region {
    uint32_t region = 0;
    double t0 = 0.0, t1 = 0.0;
    bool operator==(const Region&) const = default;
};
/// Irregular: from region `from` to `to` by the corner pointer at `corner` (bit 0 x, 1 y, 2 z
/// high).
struct Pointer {
    uint32_t from = 0, to = 0;
    int corner = 0;
    bool operator==(const Pointer&) const = default;
};
/// A primitive tested, with its spans along the whole line.
struct PrimTest {
    uint32_t prim = 0;
    SpanList spans;
    bool operator==(const PrimTest&) const = default;
};
/// A primitive whose spans the mailbox held.
struct MailboxHit {
    uint32_t prim = 0;
    bool operator==(const MailboxHit&) const = default;
};
/// The region's tree evaluated along the whole line.
struct Spans {
    SpanList spans;
    bool operator==(const Spans&) const = default;
};
/// Why the walk ended early.
struct Error {
    std::string what;
    bool operator==(const Error&) const = default;
};
/// Irregular: where the walk starts (world) and the region found there.
struct Locate {
    Vec3 point{0.0};
    uint32_t region = 0;
    bool operator==(const Locate&) const = default;
};
/// Where the region is left: t, the point (world), the exit axis and the tied axes' mask (one
/// bit: a face, two: an edge, three: a corner).
struct Exit {
    double t = 0.0;
    Vec3 point{0.0};
    int axis = -1;
    int ties = 0;
    bool operator==(const Exit&) const = default;
};
/// Regular: the point located (world), its directory cell and the leaf found.
struct Lookup {
    Vec3 point{0.0};
    std::array<uint32_t, 3> cell{};
    uint32_t leaf = 0;
    bool operator==(const Lookup&) const = default;
};
/// Regular, push step: the exit point pushed across the axes in `axes` (world).
struct Push {
    Vec3 point{0.0};
    int axes = 0;
    bool operator==(const Push&) const = default;
};
/// Regular, exact step: the exit axis and the next cell's indices.
struct IndexStep {
    int axis = -1;
    std::array<uint32_t, 3> cell{};
    bool operator==(const IndexStep&) const = default;
};
/// Regular, exact step: from leaf `from` to `to` by the rope of face `face` (2 * axis, + 1 for
/// the high face), a face one leaf covers.
struct Rope {
    uint32_t from = 0;
    int face = 0;
    uint32_t to = 0;
    bool operator==(const Rope&) const = default;
};
/// BVH: the children of wide node `node` (its binary node's descendants, down to four) whose
/// boxes are met, nodes[0, count) entered at t0s[0, count), in the order walked.
struct Children {
    static constexpr int kMax = 4;  ///< the BVH's width (kBvhWidth)
    uint32_t node = 0;
    int count = 0;
    std::array<uint32_t, kMax> nodes{};
    std::array<double, kMax> t0s{};
    bool operator==(const Children&) const = default;
};
/// BVH: node `node` not entered: its box begins at t0, beyond the hit at hitT; or, `blocked`, a
/// shadow ray known to be blocked (a span starts at hitT) skips a box that does not hold its
/// start, being left only to rule out that the ray begins inside a primitive.
struct Culled {
    uint32_t node = 0;
    double t0 = 0.0, hitT = 0.0;
    bool blocked = false;
    bool operator==(const Culled&) const = default;
};
/// Why the walk starts again another way (BVH: in box-entry order).
struct Restart {
    std::string why;
    bool operator==(const Restart&) const = default;
};
/// A stretch [t0, t1] the light buffer leaves to walk, the `index`th of the ray.
struct Stretch {
    int index = 0;
    double t0 = 0.0, t1 = 0.0;
    bool operator==(const Stretch&) const = default;
};
/// The light buffer shows nothing can block the shadow ray: no walk.
struct LightBufferClear {
    bool operator==(const LightBufferClear&) const = default;
};
/// The primitive that blocks a shadow ray, and where.
struct Blocker {
    uint32_t prim = 0;
    double t = 0.0;
    bool operator==(const Blocker&) const = default;
};
/// A ray of the pixel's tree begins: why it was cast, the bounces before it, the shadow ray's
/// light (else -1), its origin and interval.
struct RayBegin {
    RayKind kind = RayKind::Primary;
    int depth = 0;
    int light = -1;
    Vec3 origin{0.0};
    double tmin = 0.0, tmax = 0.0;
    bool operator==(const RayBegin&) const = default;
};
/// A ray of the pixel's tree ends: the primitive hit (kNoPrim: none) at t and point; for a
/// shadow ray, whether it is occluded.
struct RayEnd {
    RayKind kind = RayKind::Primary;
    uint32_t prim = kNoPrim;
    double t = 0.0;
    Vec3 point{0.0};
    bool occluded = false;
    bool operator==(const RayEnd&) const = default;
};
}  // namespace walk

/// One event of a walk, in order: one of walk::*, told apart by kind().
struct WalkEvent {
    /// The alternatives, in the order of Kind.
    using Data = std::variant<walk::Region, walk::Pointer, walk::PrimTest, walk::MailboxHit,
                              walk::Spans, walk::Error, walk::Locate, walk::Exit, walk::Lookup,
                              walk::Push, walk::IndexStep, walk::Rope, walk::Children, walk::Culled,
                              walk::Restart, walk::Stretch, walk::LightBufferClear, walk::Blocker,
                              walk::RayBegin, walk::RayEnd>;
    /// Data's alternative index, by name (for switches).
    enum Kind : uint8_t {
        Region,
        Pointer,
        PrimTest,
        MailboxHit,
        Spans,
        Error,
        Locate,
        Exit,
        Lookup,
        Push,
        IndexStep,
        Rope,
        Children,
        Culled,
        Restart,
        Stretch,
        LightBufferClear,
        Blocker,
        RayBegin,
        RayEnd,
    };
    Data data;  ///< the event's own fields

    /// Which event this is.
    Kind kind() const { return Kind(data.index()); }
    /// The event as E; E must be the one held.
    template <class E>
    const E& as() const {
        return std::get<E>(data);
    }
    /// The event as E, or null when it is another.
    template <class E>
    const E* get() const {
        return std::get_if<E>(&data);
    }
    /// One line, no newline: "region 12 t = [0.5, 1.25]", "test p3 spans {...}". With a scene,
    /// a primitive's description follows its number.
    std::string toString(const Scene* scene = nullptr) const;
    bool operator==(const WalkEvent&) const = default;
    /// The event opens a region's stretch of the walk (regions are the playback's steps).
    bool isRegion() const { return kind() == Region; }
};

static_assert(
    std::is_same_v<std::variant_alternative_t<WalkEvent::Region, WalkEvent::Data>, walk::Region> &&
        std::is_same_v<std::variant_alternative_t<WalkEvent::Rope, WalkEvent::Data>, walk::Rope> &&
        std::is_same_v<std::variant_alternative_t<WalkEvent::RayEnd, WalkEvent::Data>,
                       walk::RayEnd> &&
        std::variant_size_v<WalkEvent::Data> == WalkEvent::RayEnd + 1,
    "WalkEvent::Kind names Data's alternatives in order");

struct RecordingObserver {
    static constexpr bool kActive = true;
    std::vector<WalkEvent> events;

    void region(uint32_t id, double t0, double t1) { add(walk::Region{id, t0, t1}); }
    void primTest(uint32_t prim, const Span* spans, int n) {
        add(walk::PrimTest{prim, SpanList(spans, spans + n)});
    }
    void mailboxHit(uint32_t prim) { add(walk::MailboxHit{prim}); }
    void regionSpans(const SpanList& s) { add(walk::Spans{s}); }
    /// Not recorded: a walk's events keep the primitives' spans and the tree's, from which
    /// evalNodes (engine/render/ray_csg.h) gets every node's again with evalTree.
    void csgNode(int /*node*/, const SpanList& /*spans*/) {}
    void walkError(const char* what) { add(walk::Error{what}); }
    void locate(const Vec3& point, uint32_t region) { add(walk::Locate{point, region}); }
    void regionExit(double t, const Vec3& point, int axis, int ties) {
        add(walk::Exit{t, point, axis, ties});
    }
    void pointer(uint32_t from, uint32_t to, int corner) { add(walk::Pointer{from, to, corner}); }
    void lookup(const Vec3& point, const uint32_t cell[3], uint32_t leaf) {
        add(walk::Lookup{point, {cell[0], cell[1], cell[2]}, leaf});
    }
    void push(const Vec3& point, int axes) { add(walk::Push{point, axes}); }
    void indexStep(int axis, const uint32_t cell[3]) {
        add(walk::IndexStep{axis, {cell[0], cell[1], cell[2]}});
    }
    void rope(uint32_t from, int face, uint32_t to) { add(walk::Rope{from, face, to}); }
    void nodeChildren(uint32_t node, const uint32_t* children, const double* t0s, int count) {
        walk::Children c{node, count, {}, {}};
        for (int i = 0; i < count && i < walk::Children::kMax; ++i)
            c.nodes[size_t(i)] = children[i], c.t0s[size_t(i)] = t0s[i];
        add(std::move(c));
    }
    void nodeCulled(uint32_t node, double t0, double best, bool blocked) {
        add(walk::Culled{node, t0, best, blocked});
    }
    void walkRestart(const char* why) { add(walk::Restart{why}); }
    void stretch(int index, double t0, double t1) { add(walk::Stretch{index, t0, t1}); }
    void lightBufferClear() { add(walk::LightBufferClear{}); }
    void blocker(const Hit& hit) { add(walk::Blocker{hit.prim, hit.t}); }
    void rayBegin(RayKind kind, int depth, int light, const Ray& ray, double tmin, double tmax) {
        add(walk::RayBegin{kind, depth, light, ray.o, tmin, tmax});
    }
    void rayEnd(const RayEnd& end) {
        add(walk::RayEnd{end.kind, end.hit.prim, end.hit.t, end.point, end.occluded});
    }

  private:
    template <class E>
    void add(E&& e) {
        events.push_back(WalkEvent{std::forward<E>(e)});
    }
};

std::ostream& operator<<(std::ostream& os, const Hit& h);
std::ostream& operator<<(std::ostream& os, const WalkEvent& e);

}  // namespace lancer
