#include "engine/render/ray_tree.h"

#include <cmath>
#include <ostream>
#include <sstream>

namespace lancer {

namespace {

/// The counters a walk's events account for, as the walks count them in TraceContext.
RayCounters countEvents(RayKind kind, const std::vector<WalkEvent>& events) {
    RayCounters c;
    c.rays = 1;
    c.primaryRays = kind == RayKind::Primary;
    c.shadowRays = kind == RayKind::Shadow;
    for (const WalkEvent& e : events) {
        switch (e.kind) {
            case WalkEvent::Region:
                ++c.regionVisits;
                break;
            case WalkEvent::PrimTest:
                ++c.primTests;
                break;
            case WalkEvent::MailboxHit:
                ++c.mailboxHits;
                break;
            case WalkEvent::Pointer:
                ++c.pointerSteps;
                break;
            case WalkEvent::Error:
                ++c.walkErrors;
                break;
            case WalkEvent::LightBufferClear:
                ++c.lightBufferSkips;
                break;
            default:
                break;
        }
    }
    return c;
}

}  // namespace

void RayTreeRecorder::rayBegin(RayKind kind, int depth, int light, const Ray& ray, double tmin,
                               double tmax) {
    // A ray's walk runs from its begin to its end before any other ray begins (its children
    // are cast once it has ended), so the events since the last begin are all its own.
    events.clear();
    RecordingObserver::rayBegin(kind, depth, light, ray, tmin, tmax);
    TracedRay r;
    r.kind = kind;
    r.depth = depth;
    r.light = light;
    r.origin = ray.o;
    r.direction = ray.d;
    r.tmin = tmin;
    r.tmax = tmax;
    const int self = int(rays.size());
    if (kind == RayKind::Shadow) {
        r.parent = size_t(depth) < shadedAt_.size() ? shadedAt_[size_t(depth)] : -1;
    } else {
        r.parent = depth > 0 ? shadedAt_[size_t(depth - 1)] : -1;
        shadedAt_.resize(size_t(depth) + 1, -1);
        shadedAt_[size_t(depth)] = self;
    }
    rays.push_back(std::move(r));
}

void RayTreeRecorder::blocker(const Hit& hit) {
    RecordingObserver::blocker(hit);
    if (!rays.empty()) rays.back().hit = hit;
}

void RayTreeRecorder::rayEnd(const RayEnd& end) {
    RecordingObserver::rayEnd(end);
    if (rays.empty()) return;
    TracedRay& r = rays.back();
    if (end.kind != RayKind::Shadow) {
        r.hit = end.hit;
        r.point = end.point;
        r.normal = end.normal;
    }
    r.occluded = end.occluded;
    r.counters = countEvents(r.kind, events);
    r.events = std::move(events);
    events.clear();
}

std::vector<size_t> TracedRay::regionSteps() const {
    std::vector<size_t> steps;
    for (size_t i = 0; i < events.size(); ++i)
        if (events[i].isRegion()) steps.push_back(i);
    return steps;
}

std::string TracedRay::toString() const {
    std::ostringstream os;
    os.precision(10);
    os << rayKindName(kind);
    if (parent >= 0) os << " of #" << parent;
    if (light >= 0) os << " to light " << light;
    os << " from (" << origin.x << ", " << origin.y << ", " << origin.z << ") dir (" << direction.x
       << ", " << direction.y << ", " << direction.z << ") t = [" << tmin << ", " << tmax << "]: ";
    if (kind == RayKind::Shadow)
        os << (occluded ? "occluded by p" + std::to_string(hit.prim) : std::string("lit"));
    else
        os << hit.toString();
    os << "; " << counters.primTests << " tests, " << counters.mailboxHits << " mailbox hits, "
       << counters.regionVisits << " regions";
    return os.str();
}

std::string RayTree::toString(const Scene* scene) const {
    std::ostringstream os;
    os << "pixel (" << x << ", " << y << ") of " << width << "x" << height << ": "
       << counters.toString() << "\n";
    std::vector<int> generation(rays.size(), 0);
    for (size_t i = 0; i < rays.size(); ++i) {
        const TracedRay& r = rays[i];
        if (r.parent >= 0) generation[i] = generation[size_t(r.parent)] + 1;
        const std::string indent(size_t(2 * generation[i]), ' ');
        os << indent << "#" << i << " " << r.toString() << "\n";
        for (const WalkEvent& e : r.events) {
            const bool inRegion = e.kind == WalkEvent::PrimTest ||
                                  e.kind == WalkEvent::MailboxHit || e.kind == WalkEvent::Spans;
            os << indent << (inRegion ? "    " : "  ") << e.toString(scene) << "\n";
        }
    }
    return os.str();
}

RayTree tracePixel(const Scene& scene, const Accelerator& accel, const ShadingOptions& shading,
                   const Camera& cam, int x, int y, int w, int h) {
    const Tracer tracer(scene, accel, shading);
    const PrimaryRays primary(cam, w, h);
    const LightBuffer eye = accel.eyeBuffer(scene, cam);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    ctx.useMailboxes = accel.usesMailboxes();
    RayTreeRecorder rec;
    Hit hit;
    RayTree tree;
    tree.x = x;
    tree.y = y;
    tree.width = w;
    tree.height = h;
    tree.color = tracer.pixel(primary, eye, x, y, ctx, rec, hit);
    tree.counters = ctx.counters;
    tree.rays = std::move(rec.rays);
    // A shadow ray's blocker is told as a Hit alone: its point and normal, as for any hit.
    for (TracedRay& r : tree.rays) {
        if (r.kind != RayKind::Shadow || !r.hit.valid()) continue;
        const SurfacePoint s = tracer.surface(Ray{r.origin, r.direction}, r.hit);
        r.point = s.p;
        r.normal = s.n;
    }
    return tree;
}

namespace {

nlohmann::json vec(const Vec3& v) { return {v.x, v.y, v.z}; }

/// JSON has no infinity: an unbounded t is written as null.
nlohmann::json tJson(double t) { return std::isfinite(t) ? nlohmann::json(t) : nlohmann::json(); }

nlohmann::json spansJson(const SpanList& spans) {
    nlohmann::json a = nlohmann::json::array();
    for (const Span& s : spans)
        a.push_back({{"t_in", s.in.t},
                     {"prim_in", s.in.prim},
                     {"t_out", s.out.t},
                     {"prim_out", s.out.prim}});
    return a;
}

nlohmann::json axesJson(int mask) {
    std::string s;
    for (int a = 0; a < 3; ++a)
        if (mask >> a & 1) s += char('x' + a);
    return s;
}

}  // namespace

nlohmann::json toJson(const WalkEvent& e, const RegionCornersFn& corners) {
    nlohmann::json j;
    switch (e.kind) {
        case WalkEvent::Region:
            j = {{"event", "region"}, {"region", e.a}, {"t0", tJson(e.t0)}, {"t1", tJson(e.t1)}};
            if (corners) {
                nlohmann::json c = nlohmann::json::array();
                for (const Vec3& p : corners(e.a)) c.push_back(vec(p));
                j["corners"] = c;
            }
            break;
        case WalkEvent::Pointer:
            j = {{"event", "pointer"}, {"from", e.a}, {"to", e.b}, {"corner", e.corner}};
            break;
        case WalkEvent::PrimTest:
            j = {{"event", "prim_test"}, {"prim", e.a}, {"spans", spansJson(e.spans)}};
            break;
        case WalkEvent::MailboxHit:
            j = {{"event", "mailbox_hit"}, {"prim", e.a}};
            break;
        case WalkEvent::Spans:
            j = {{"event", "region_spans"}, {"spans", spansJson(e.spans)}};
            break;
        case WalkEvent::Error:
            j = {{"event", "walk_error"}, {"what", e.what}};
            break;
        case WalkEvent::Locate:
            j = {{"event", "locate"}, {"point", vec(e.point)}, {"region", e.b}};
            break;
        case WalkEvent::Exit:
            j = {{"event", "exit"},
                 {"t", tJson(e.t0)},
                 {"point", vec(e.point)},
                 {"axis", e.axis},
                 {"ties", axesJson(e.ties)}};
            break;
        case WalkEvent::Lookup:
            j = {{"event", "lookup"},
                 {"point", vec(e.point)},
                 {"cell", {e.cell[0], e.cell[1], e.cell[2]}},
                 {"leaf", e.b}};
            break;
        case WalkEvent::Push:
            j = {{"event", "push"}, {"point", vec(e.point)}, {"axes", axesJson(e.ties)}};
            break;
        case WalkEvent::IndexStep:
            j = {{"event", "index_step"},
                 {"axis", e.axis},
                 {"cell", {e.cell[0], e.cell[1], e.cell[2]}}};
            break;
        case WalkEvent::Rope:
            j = {{"event", "rope"},
                 {"from", e.a},
                 {"to", e.b},
                 {"axis", e.axis / 2},
                 {"side", e.axis % 2 ? "high" : "low"}};
            break;
        case WalkEvent::Stretch:
            j = {{"event", "stretch"}, {"index", e.a}, {"t0", tJson(e.t0)}, {"t1", tJson(e.t1)}};
            break;
        case WalkEvent::LightBufferClear:
            j = {{"event", "light_buffer_clear"}};
            break;
        case WalkEvent::Blocker:
            j = {{"event", "blocker"}, {"prim", e.a}, {"t", tJson(e.t0)}};
            break;
        case WalkEvent::RayBegin:
            j = {{"event", "ray_begin"},
                 {"kind", rayKindName(RayKind(e.axis))},
                 {"tmin", tJson(e.t0)},
                 {"tmax", tJson(e.t1)}};
            break;
        case WalkEvent::RayEnd:
            j = {{"event", "ray_end"}, {"kind", rayKindName(RayKind(e.axis))}};
            if (RayKind(e.axis) == RayKind::Shadow)
                j["occluded"] = e.b != 0;
            else if (e.a != kNoPrim)
                j["hit"] = {{"t", e.t0}, {"prim", e.a}, {"point", vec(e.point)}};
            else
                j["hit"] = nullptr;
            break;
    }
    return j;
}

nlohmann::json toJson(const TracedRay& r, const Scene& scene, const RegionCornersFn& corners) {
    nlohmann::json j = {{"kind", rayKindName(r.kind)},
                        {"parent", r.parent},
                        {"depth", r.depth},
                        {"origin", vec(r.origin)},
                        {"direction", vec(r.direction)},
                        {"tmin", tJson(r.tmin)},
                        {"tmax", tJson(r.tmax)}};
    if (r.kind == RayKind::Shadow) {
        j["light"] = r.light;
        j["occluded"] = r.occluded;
    }
    nlohmann::json ev = nlohmann::json::array();
    for (const WalkEvent& e : r.events) ev.push_back(toJson(e, corners));
    j["events"] = std::move(ev);
    if (r.hit.valid()) {
        j["hit"] = {{"t", r.hit.t},
                    {"prim", r.hit.prim},
                    {"primitive", scene.prims[r.hit.prim].toString()},
                    {"point", vec(r.point)},
                    {"normal", vec(r.normal)}};
    } else {
        j["hit"] = nullptr;
    }
    j["counters"] = toJson(r.counters);
    return j;
}

nlohmann::json toJson(const RayCounters& c) {
    return {{"rays", c.rays},
            {"primary_rays", c.primaryRays},
            {"shadow_rays", c.shadowRays},
            {"prim_tests", c.primTests},
            {"mailbox_hits", c.mailboxHits},
            {"region_visits", c.regionVisits},
            {"pointer_steps", c.pointerSteps},
            {"walk_errors", c.walkErrors},
            {"light_buffer_skips", c.lightBufferSkips}};
}

std::ostream& operator<<(std::ostream& os, const TracedRay& r) { return os << r.toString(); }

std::ostream& operator<<(std::ostream& os, const RayTree& t) { return os << t.toString(); }

}  // namespace lancer
