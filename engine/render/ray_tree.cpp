#include "engine/render/ray_tree.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <sstream>

#include "engine/accel/structure_view.h"

namespace lancer {

namespace {

/// The counters a walk's events account for, as the walks count them in TraceContext.
RayCounters countEvents(RayKind kind, const std::vector<WalkEvent>& events) {
    RayCounters c;
    c.rays = 1;
    c.primaryRays = kind == RayKind::Primary;
    c.shadowRays = kind == RayKind::Shadow;
    for (const WalkEvent& e : events) {
        switch (e.kind()) {
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

namespace {

/// Six significant digits: a sentence's numbers are read, not compared.
std::string num6(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.6g", x);
    return buf;
}

std::string pt6(const Vec3& p) {
    std::string s = "(";
    s.append(num6(p.x)).append(", ").append(num6(p.y)).append(", ").append(num6(p.z));
    return s.append(")");
}

/// Ten significant digits: a pushed point differs from the exit point by a small delta.
std::string pt10(const Vec3& p) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.10g, %.10g, %.10g)", p.x, p.y, p.z);
    return buf;
}

std::string cellText(const std::array<uint32_t, 3>& c) {
    std::string s = "(";
    s.append(std::to_string(c[0])).append(", ").append(std::to_string(c[1])).append(", ");
    return s.append(std::to_string(c[2])).append(")");
}

std::string primText(uint32_t p, const Scene* scene) {
    std::string s = "p";
    s += std::to_string(p);
    if (scene && p < scene->prims.size()) s.append(" ").append(scene->prims[p].toString());
    return s;
}

/// How a region step's frame runs along the ray: per axis +1 (the ray goes to the high side),
/// -1 or 0; brute force in the world's axes, regular in its grid's, camera-frame slabs in the
/// camera frame's, projective regions in depth alone (a ray from the eye keeps its u and v and
/// goes deeper; a shadow ray in its light's structure keeps them too and heads up to the light).
struct FrameSides {
    int sign[3] = {0, 0, 0};
    bool irregular = false;
};

FrameSides sidesOf(const StructureView& view, const RegionInfo& info, const Vec3& dir) {
    FrameSides f;
    const RegionKind kind = info.kind;
    Vec3 d = dir;
    if (kind == RegionKind::Slab) d = view.irregular()->frame().vector(dir);
    if (kind == RegionKind::Leaf) d = view.regular()->frame().toFrame(dir);
    if (kind == RegionKind::ProjectiveSlab || kind == RegionKind::NearRegion)
        d = Vec3(0, 0, info.light >= 0 ? -1 : 1);
    f.irregular = kind == RegionKind::Slab || kind == RegionKind::ProjectiveSlab ||
                  kind == RegionKind::NearRegion;
    for (int a = 0; a < 3; ++a) f.sign[a] = d[a] > 0.0 ? 1 : (d[a] < 0.0 ? -1 : 0);
    return f;
}

/// "+x" for the side of axis a the ray leaves through.
std::string signedAxis(const FrameSides& f, int a) {
    return std::string(f.sign[a] < 0 ? "-" : "+") + char('x' + a);
}

/// "+x face", "+x-y edge", "+x+y-z corner"; an irregular region's depth face is its "far depth
/// plane" or "near depth plane".
std::string exitFace(const FrameSides& f, int ties) {
    if (f.irregular && ties == 4) return f.sign[2] < 0 ? "near depth plane" : "far depth plane";
    std::string s;
    int n = 0;
    for (int a = 0; a < 3; ++a)
        if (ties >> a & 1) s += signedAxis(f, a), ++n;
    return s + (n == 1 ? " face" : n == 2 ? " edge" : " corner");
}

/// " -> sub-table 3 -> sub-table 9": the sub-tables a lookup of `cell` passes through.
std::string subTables(const StructureView& view, const std::array<uint32_t, 3>& cell) {
    std::string s;
    if (const RegularGrid* g = view.regular())
        for (uint32_t t : g->directory().subTablesOf(cell[0], cell[1], cell[2]))
            s += " -> sub-table " + std::to_string(t);
    return s;
}

/// The next region, named, with its depth range for irregular slabs.
std::string nextName(const StructureView& view, uint32_t id) {
    std::string s = "-> " + regionName(view, id);
    const RegionInfo r = view.region(id);
    if (r.kind == RegionKind::Slab || r.kind == RegionKind::ProjectiveSlab ||
        r.kind == RegionKind::NearRegion)
        s += ", depth " + num6(r.frameBox.lo.z) + " to " + num6(r.frameBox.hi.z);
    return s;
}

/// How a walk (the ray's, or a light-buffer stretch's) finds its first region: by the directory
/// (regular), the screen BSP and the zone's slabs (camera frame), the pixel's zone (projective).
/// `arrow`: name the region after "-> " (a next step), else as the step's own.
std::string startText(const StructureView& view, const walk::Locate* locate,
                      const walk::Lookup* lookup, uint32_t region, bool arrow) {
    std::string s;
    if (lookup) {
        s = "starts at " + pt6(lookup->point) + ": directory cell " + cellText(lookup->cell);
        if (arrow) return s + subTables(view, lookup->cell) + " " + nextName(view, region);
        const std::string via = subTables(view, lookup->cell);
        return s + (via.empty() ? "" : " (through" + via.substr(3) + ")") + " of " +
               regionName(view, region);
    }
    if (locate) {
        const RegionInfo at = view.region(locate->region);
        s = "starts at " + pt6(locate->point) +
            (at.kind == RegionKind::Slab ? ", located by the screen BSP and the zone's depth slabs"
             : at.light >= 0 ? " in the zone of its light's projective structure that holds it"
                             : " in its pixel's projective zone");
        return s + (arrow ? " " + nextName(view, region) : ", in " + regionName(view, region));
    }
    return arrow ? "starts " + nextName(view, region)
                 : "starts in " + regionName(view, region) + ", which holds every primitive";
}

}  // namespace

std::string regionName(const StructureView& view, uint32_t region) {
    const RegionInfo r = view.region(region);
    const std::string id = " (region " + std::to_string(region) + ")";
    // A light's structure: "light 1's projective slab 3 of zone 40 (region 9000)".
    const std::string owner = r.light >= 0 ? "light " + std::to_string(r.light) + "'s " : "";
    switch (r.kind) {
        case RegionKind::SceneBox:
            return "the scene box";
        case RegionKind::Leaf:
            return "leaf " + std::to_string(region);
        case RegionKind::Slab:
            return "slab " + std::to_string(r.slab) + " of zone " + std::to_string(r.zone) + id;
        case RegionKind::ProjectiveSlab:
            return owner + "projective slab " + std::to_string(r.slab) + " of zone " +
                   std::to_string(r.zone) + id;
        case RegionKind::NearRegion:
            return (owner.empty() ? "the " : owner) + "near region" + id;
        case RegionKind::BvhInner:
            return "node " + std::to_string(region) + " (depth " + std::to_string(r.level) + ")";
        case RegionKind::BvhLeaf:
            return "leaf node " + std::to_string(region) + " (depth " + std::to_string(r.level) +
                   ", " + std::to_string(r.prims.size()) + " prims)";
    }
    return "region " + std::to_string(region);
}

namespace {

/// The BVH's steps: each node visited, what it did (its children's boxes met, in the order
/// walked; a leaf's hit or none), and the nodes skipped for lying beyond the hit.
std::vector<StepReason> explainBvhSteps(const TracedRay& r, const StructureView& view,
                                        const Scene* scene) {
    const std::vector<WalkEvent>& ev = r.events;
    const std::vector<size_t> steps = r.regionSteps();
    std::vector<StepReason> out(steps.size());
    for (size_t k = 0; k < steps.size(); ++k) {
        const walk::Region& reg = ev[steps[k]].as<walk::Region>();
        const size_t end = k + 1 < steps.size() ? steps[k + 1] : ev.size();
        const RegionInfo info = view.region(reg.region);
        std::string s = (k == 0 ? "the walk starts at the root, " : "") +
                        regionName(view, reg.region) + ", its box met on t = [" + num6(reg.t0) +
                        ", " + num6(reg.t1) + "]: ";
        std::vector<std::string> culled, unheld;  // beyond the hit; not holding a blocked start
        bool told = false;
        for (size_t i = steps[k] + 1; i < end; ++i) {
            if (const auto* c = ev[i].get<walk::Children>()) {
                told = true;
                if (c->count == 0) {
                    s += "the ray meets none of its children's boxes";
                } else if (c->count == 1) {
                    s += "only child " + std::to_string(c->nodes[0]) +
                         "'s box is met (at t = " + num6(c->t0s[0]) + ")";
                } else {
                    s += std::to_string(c->count) + " children's boxes are met; the nearest, " +
                         std::to_string(c->nodes[0]) + " (at t = " + num6(c->t0s[0]) +
                         "), first, then";
                    for (int j = 1; j < c->count; ++j)
                        s += (j > 1 ? ", " : " ") + std::to_string(c->nodes[size_t(j)]) +
                             " (at t = " + num6(c->t0s[size_t(j)]) + ")";
                    s += " unless a hit comes before them";
                }
            } else if (const auto* u = ev[i].get<walk::Culled>()) {
                (u->blocked ? unheld : culled)
                    .push_back(std::to_string(u->node) + " (its box begins at t = " + num6(u->t0) +
                               ")");
            }
        }
        if (!told && info.kind == RegionKind::BvhLeaf) {
            const bool hitHere = r.kind != RayKind::Shadow && r.hit.valid() && r.hit.t >= reg.t0 &&
                                 r.hit.t <= reg.t1;
            s += info.prims.empty() ? "an empty leaf"
                 : hitHere ? "its primitives give the hit on " + primText(r.hit.prim, scene) +
                                 " at t = " + num6(r.hit.t) + " inside its box"
                           : "no boundary of its tree lies inside its box";
        }
        auto skipped = [&s](const char* why, const std::vector<std::string>& nodes) {
            if (nodes.empty()) return;
            s += why;
            for (size_t i = 0; i < nodes.size(); ++i) s += (i ? ", node " : " node ") + nodes[i];
        };
        skipped("; then skipped, beyond the hit found:", culled);
        skipped(
            "; then skipped, the shadow ray being blocked by a span that starts after its "
            "start, and these boxes not holding that start (only a primitive there could "
            "hold it):",
            unheld);
        out[k].text = std::move(s);
        out[k].next =
            k + 1 < steps.size() ? int64_t(ev[steps[k + 1]].as<walk::Region>().region) : -1;
    }
    return out;
}

}  // namespace

std::vector<StepReason> explainSteps(const TracedRay& r, const StructureView& view,
                                     const Scene* scene) {
    if (view.bvh()) return explainBvhSteps(r, view, scene);
    const std::vector<WalkEvent>& ev = r.events;
    const std::vector<size_t> steps = r.regionSteps();
    std::vector<StepReason> out(steps.size());
    for (size_t k = 0; k < steps.size(); ++k) {
        const walk::Region& reg = ev[steps[k]].as<walk::Region>();
        const size_t end = k + 1 < steps.size() ? steps[k + 1] : ev.size();
        const RegionInfo info = view.region(reg.region);
        const FrameSides sides = sidesOf(view, info, r.direction);
        const std::string here = regionName(view, reg.region);
        std::string s;

        // The walk's start: what came before its first region.
        if (k == 0) {
            const walk::Locate* locate = nullptr;
            const walk::Lookup* lookup = nullptr;
            const walk::Stretch* stretch = nullptr;
            for (size_t i = 0; i < steps[0]; ++i) {
                if (const auto* e = ev[i].get<walk::Locate>()) locate = e;
                if (const auto* e = ev[i].get<walk::Lookup>()) lookup = e;
                if (const auto* e = ev[i].get<walk::Stretch>()) stretch = e;
            }
            if (stretch)
                s += "light-buffer stretch " + std::to_string(stretch->index) + " t = [" +
                     num6(stretch->t0) + ", " + num6(stretch->t1) + "] ";
            else
                s += "the walk ";
            s += startText(view, locate, lookup, reg.region, false) + "; ";
        }

        // What follows the region's own events: its exit and the way to the next region, or
        // the ray's end; then, for a shadow ray, the next light-buffer stretch's start.
        const walk::Exit* exit = nullptr;
        const walk::Rope* rope = nullptr;
        const walk::IndexStep* index = nullptr;
        const walk::Push* push = nullptr;
        const walk::Lookup* lookup = nullptr;
        const walk::Error* error = nullptr;
        const walk::Blocker* blocker = nullptr;
        const walk::Stretch* stretch = nullptr;
        const walk::Locate* locate = nullptr;
        std::vector<const walk::Pointer*> pointers;
        for (size_t i = steps[k] + 1; i < end; ++i) {
            const WalkEvent& e = ev[i];
            if (const auto* x = e.get<walk::Exit>()) exit = x;
            if (const auto* x = e.get<walk::Rope>()) rope = x;
            if (const auto* x = e.get<walk::IndexStep>()) index = x;
            if (const auto* x = e.get<walk::Push>()) push = x;
            if (const auto* x = e.get<walk::Lookup>()) lookup = x;
            if (const auto* x = e.get<walk::Pointer>()) pointers.push_back(x);
            if (const auto* x = e.get<walk::Error>()) error = x;
            if (const auto* x = e.get<walk::Blocker>()) blocker = x;
            if (const auto* x = e.get<walk::Locate>()) locate = x;
            if (const auto* x = e.get<walk::Stretch>()) {
                stretch = x;
                lookup = nullptr;  // one after it starts the stretch's walk
                locate = nullptr;
            }
        }
        const bool hasNext = k + 1 < steps.size();
        const uint32_t next = hasNext ? ev[steps[k + 1]].as<walk::Region>().region : 0;
        const bool nextInWalk = hasNext && !stretch;
        StepReason& reason = out[k];
        reason.next = hasNext ? int64_t(next) : -1;

        if (exit) {
            s += "left " + here + " through its " + exitFace(sides, exit->ties) +
                 " at t = " + num6(exit->t) + " (point " + pt6(exit->point) + ")";
            if (rope) {
                s += "; the leaf's rope across that face " + nextName(view, rope->to);
            } else if (index && lookup) {
                s += "; exact index step " + signedAxis(sides, index->axis) +
                     " to directory cell " + cellText(lookup->cell) +
                     subTables(view, lookup->cell) + " " + nextName(view, lookup->leaf);
            } else if (push && lookup) {
                const int a = exit->axis;
                s += "; pushed by delta " + num6(std::abs(push->point[a] - exit->point[a])) +
                     " across " + exitFace(sides, push->axes) + " to " + pt10(push->point) +
                     ": directory cell " + cellText(lookup->cell) + subTables(view, lookup->cell) +
                     " " + nextName(view, lookup->leaf);
            } else if (!pointers.empty() && !error) {
                const RegionInfo to = view.region(pointers.back()->to);
                if (exit->ties == 4 && pointers.size() == 1) {
                    s += ": the next slab of the same zone, by corner pointer " +
                         std::to_string(pointers[0]->corner);
                } else {
                    s += ": crossed into zone " + std::to_string(to.zone) + " from zone " +
                         std::to_string(info.zone) + " by corner pointer";
                    if (pointers.size() > 1) s += "s";
                    for (size_t i = 0; i < pointers.size(); ++i) {
                        const walk::Pointer& p = *pointers[i];
                        const Box3 b = view.region(p.from).frameBox;
                        const int c = p.corner;
                        s += std::string(i ? "," : "") + " " + std::to_string(c) + " of region " +
                             std::to_string(p.from) + " (its corner at screen (" +
                             num6(c & 1 ? b.hi.x : b.lo.x) + ", " + num6(c & 2 ? b.hi.y : b.lo.y) +
                             "), depth " + num6(c & 4 ? b.hi.z : b.lo.z) + ")";
                    }
                }
                s += " " + nextName(view, pointers.back()->to);
            } else if (nextInWalk) {
                s += info.kind == RegionKind::NearRegion
                         ? ": the first slab of the pixel's zone " + nextName(view, next)
                     : info.light >= 0 ? ": the next slab of the same zone toward the light " +
                                             nextName(view, next)
                                       : ": the next slab of the same zone " + nextName(view, next);
            } else if (!error) {
                s += ", on the structure's border: the ray leaves the structure's box there";
            }
        }
        if (error) s += std::string(exit ? "; " : "") + "walk error: " + error->what;
        if (!exit && !error) {
            const bool last = k + 1 == steps.size();
            if (blocker && !stretch) {
                s += "blocked by " + primText(blocker->prim, scene) +
                     " at t = " + num6(blocker->t) + " inside this region: the light is hidden";
            } else if (last && r.kind != RayKind::Shadow && r.hit.valid()) {
                s += "hit " + primText(r.hit.prim, scene) + " at t = " + num6(r.hit.t) +
                     " inside this region";
            } else if (stretch) {
                s += "the light-buffer stretch ends at t = " + num6(reg.t1) + " inside this region";
            } else if (r.kind == RayKind::Shadow) {
                s += "the ray reaches its light at t = " + num6(reg.t1) +
                     " inside this region: nothing blocks it";
            } else if (std::isfinite(reg.t1) && reg.t1 < r.tmax) {
                // The irregular camera-frame walk also ends where the ray leaves the box of its
                // listed primitives with no boundary of a shared one ahead (shared()).
                s += "the ray leaves the structure's box, or the box of the primitives it lists "
                     "with no shared one's boundary ahead, at t = " +
                     num6(reg.t1) + ": nothing hit";
            } else {
                s += "the ray's interval ends inside this region: nothing hit";
            }
        }
        if (stretch) {
            s += "; light-buffer stretch " + std::to_string(stretch->index) + " t = [" +
                 num6(stretch->t0) + ", " + num6(stretch->t1) + "] ";
            s += hasNext ? startText(view, locate, lookup, next, true)
                         : std::string("meets no region");
        }
        reason.text = std::move(s);
    }
    return out;
}

std::string RayTree::toString(const Scene* scene, const StructureView* view) const {
    std::ostringstream os;
    os << "pixel (" << x << ", " << y << ") of " << width << "x" << height << ": "
       << counters.toString() << "\n";
    std::vector<int> generation(rays.size(), 0);
    for (size_t i = 0; i < rays.size(); ++i) {
        const TracedRay& r = rays[i];
        if (r.parent >= 0) generation[i] = generation[size_t(r.parent)] + 1;
        const std::string indent(size_t(2 * generation[i]), ' ');
        os << indent << "#" << i << " " << r.toString() << "\n";
        const std::vector<StepReason> why =
            view ? explainSteps(r, *view, scene) : std::vector<StepReason>();
        size_t step = 0;
        for (const WalkEvent& e : r.events) {
            const bool inRegion = e.kind() == WalkEvent::PrimTest ||
                                  e.kind() == WalkEvent::MailboxHit || e.kind() == WalkEvent::Spans;
            os << indent << (inRegion ? "    " : "  ") << e.toString(scene) << "\n";
            if (e.isRegion() && step < why.size())
                os << indent << "    why: " << why[step++].text << "\n";
        }
    }
    return os.str();
}

RayTree tracePixel(const Scene& scene, const Accelerator& accel, const ShadingOptions& shading,
                   const Camera& cam, int x, int y, int w, int h) {
    const Tracer tracer(scene, accel, shading);
    const PrimaryRays primary(cam, w, h);
    const std::shared_ptr<const LightBuffer> eye = accel.eyeBuffer(scene, cam);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    ctx.useMailboxes = accel.usesMailboxes();
    ctx.precision = shading.precision;
    RayTreeRecorder rec;
    Hit hit;
    RayTree tree;
    tree.x = x;
    tree.y = y;
    tree.width = w;
    tree.height = h;
    tree.color = tracer.pixel(primary, *eye, x, y, ctx, rec, hit);
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

namespace {

nlohmann::json cellJson(const std::array<uint32_t, 3>& c) { return {c[0], c[1], c[2]}; }

nlohmann::json nodeJson(uint32_t node) {
    return node == kNoNode ? nlohmann::json(nullptr) : nlohmann::json(node);
}

/// Each event's object in the trace JSON (its keys are the contract in DESIGN.md).
struct EventJson {
    const RegionCornersFn& corners;

    nlohmann::json operator()(const walk::Region& e) const {
        nlohmann::json j = {
            {"event", "region"}, {"region", e.region}, {"t0", tJson(e.t0)}, {"t1", tJson(e.t1)}};
        if (corners) {
            nlohmann::json c = nlohmann::json::array();
            for (const Vec3& p : corners(e.region)) c.push_back(vec(p));
            j["corners"] = c;
        }
        return j;
    }
    nlohmann::json operator()(const walk::Pointer& e) const {
        return {{"event", "pointer"}, {"from", e.from}, {"to", e.to}, {"corner", e.corner}};
    }
    nlohmann::json operator()(const walk::PrimTest& e) const {
        return {{"event", "prim_test"}, {"prim", e.prim}, {"spans", spansJson(e.spans)}};
    }
    nlohmann::json operator()(const walk::MailboxHit& e) const {
        return {{"event", "mailbox_hit"}, {"prim", e.prim}};
    }
    nlohmann::json operator()(const walk::Spans& e) const {
        return {{"event", "region_spans"}, {"spans", spansJson(e.spans)}};
    }
    nlohmann::json operator()(const walk::Error& e) const {
        return {{"event", "walk_error"}, {"what", e.what}};
    }
    nlohmann::json operator()(const walk::Locate& e) const {
        return {{"event", "locate"}, {"point", vec(e.point)}, {"region", e.region}};
    }
    nlohmann::json operator()(const walk::Exit& e) const {
        return {{"event", "exit"},
                {"t", tJson(e.t)},
                {"point", vec(e.point)},
                {"axis", e.axis},
                {"ties", axesJson(e.ties)}};
    }
    nlohmann::json operator()(const walk::Lookup& e) const {
        return {{"event", "lookup"},
                {"point", vec(e.point)},
                {"cell", cellJson(e.cell)},
                {"leaf", e.leaf}};
    }
    nlohmann::json operator()(const walk::Push& e) const {
        return {{"event", "push"}, {"point", vec(e.point)}, {"axes", axesJson(e.axes)}};
    }
    nlohmann::json operator()(const walk::IndexStep& e) const {
        return {{"event", "index_step"}, {"axis", e.axis}, {"cell", cellJson(e.cell)}};
    }
    nlohmann::json operator()(const walk::Rope& e) const {
        return {{"event", "rope"},
                {"from", e.from},
                {"to", e.to},
                {"axis", e.face / 2},
                {"side", e.face % 2 ? "high" : "low"}};
    }
    nlohmann::json operator()(const walk::Children& e) const {
        // "first" and "second" as when the walk was binary; "children" holds them all.
        nlohmann::json all = nlohmann::json::array();
        for (int i = 0; i < e.count; ++i)
            all.push_back({{"node", e.nodes[size_t(i)]}, {"t", tJson(e.t0s[size_t(i)])}});
        auto at = [&e](int i) { return i < e.count ? e.nodes[size_t(i)] : kNoNode; };
        auto tAt = [&e](int i) { return i < e.count ? e.t0s[size_t(i)] : kInf; };
        return {{"event", "children"},
                {"node", e.node},
                {"first", nodeJson(at(0))},
                {"first_t", tJson(tAt(0))},
                {"second", nodeJson(at(1))},
                {"second_t", tJson(tAt(1))},
                {"children", all}};
    }
    nlohmann::json operator()(const walk::Culled& e) const {
        return {{"event", "culled"},
                {"node", e.node},
                {"t0", tJson(e.t0)},
                {"hit_t", tJson(e.hitT)},
                {"blocked", e.blocked}};
    }
    nlohmann::json operator()(const walk::Restart& e) const {
        return {{"event", "restart"}, {"what", e.why}};
    }
    nlohmann::json operator()(const walk::Stretch& e) const {
        return {{"event", "stretch"}, {"index", e.index}, {"t0", tJson(e.t0)}, {"t1", tJson(e.t1)}};
    }
    nlohmann::json operator()(const walk::LightBufferClear&) const {
        return {{"event", "light_buffer_clear"}};
    }
    nlohmann::json operator()(const walk::Blocker& e) const {
        return {{"event", "blocker"}, {"prim", e.prim}, {"t", tJson(e.t)}};
    }
    nlohmann::json operator()(const walk::RayBegin& e) const {
        return {{"event", "ray_begin"},
                {"kind", rayKindName(e.kind)},
                {"tmin", tJson(e.tmin)},
                {"tmax", tJson(e.tmax)}};
    }
    nlohmann::json operator()(const walk::RayEnd& e) const {
        nlohmann::json j = {{"event", "ray_end"}, {"kind", rayKindName(e.kind)}};
        if (e.kind == RayKind::Shadow)
            j["occluded"] = e.occluded;
        else if (e.prim != kNoPrim)
            j["hit"] = {{"t", e.t}, {"prim", e.prim}, {"point", vec(e.point)}};
        else
            j["hit"] = nullptr;
        return j;
    }
};

}  // namespace

nlohmann::json toJson(const WalkEvent& e, const RegionCornersFn& corners) {
    return std::visit(EventJson{corners}, e.data);
}

nlohmann::json toJson(const TracedRay& r, const Scene& scene, const RegionCornersFn& corners,
                      const StructureView* view) {
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
    const std::vector<StepReason> why =
        view ? explainSteps(r, *view, &scene) : std::vector<StepReason>();
    size_t step = 0;
    for (const WalkEvent& e : r.events) {
        ev.push_back(toJson(e, corners));
        if (e.isRegion() && step < why.size()) ev.back()["why"] = why[step++].text;
    }
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
    nlohmann::json j = nlohmann::json::object();
    for (const RayCounters::Field& f : RayCounters::fields()) j[f.key] = c.*f.member;
    return j;
}

std::ostream& operator<<(std::ostream& os, const TracedRay& r) { return os << r.toString(); }

std::ostream& operator<<(std::ostream& os, const RayTree& t) { return os << t.toString(); }

}  // namespace lancer
