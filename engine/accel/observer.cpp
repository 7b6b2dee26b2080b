#include "engine/accel/observer.h"

#include <cstdio>
#include <ostream>

#include "engine/scene/scene.h"

namespace lancer {

namespace {

/// Ten significant digits: enough to tell regions apart, short enough to read.
std::string num(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.10g", x);
    return buf;
}

std::string pt(const Vec3& p) {
    std::string s = "(";
    s.append(num(p.x)).append(", ").append(num(p.y)).append(", ").append(num(p.z));
    return s.append(")");
}

std::string interval(double t0, double t1) { return "t = [" + num(t0) + ", " + num(t1) + "]"; }

std::string cells(const uint32_t c[3]) {
    std::string s = "[";
    s.append(std::to_string(c[0])).append(", ").append(std::to_string(c[1])).append(", ");
    return s.append(std::to_string(c[2])).append("]");
}

/// "x", "xy", "xyz": the axes set in `mask`.
std::string axes(int mask) {
    std::string s;
    for (int a = 0; a < 3; ++a)
        if (mask >> a & 1) s += char('x' + a);
    return s.empty() ? "-" : s;
}

/// BVH events' "no node" (kNoNode, engine/accel/bvh/bvh.h).
constexpr uint32_t kNoNodeId = 0xffffffffu;

std::string prim(uint32_t p, const Scene* scene) {
    std::string s = "p";
    s += std::to_string(p);
    if (scene && p < scene->prims.size()) s.append(" ").append(scene->prims[p].toString());
    return s;
}

}  // namespace

const char* rayKindName(RayKind k) {
    switch (k) {
        case RayKind::Primary:
            return "primary";
        case RayKind::Shadow:
            return "shadow";
        case RayKind::Reflection:
            return "reflection";
        case RayKind::Refraction:
            return "refraction";
    }
    return "?";
}

std::string Hit::toString() const {
    if (!valid()) return "no hit";
    return "t = " + num(t) + " on p" + std::to_string(prim) + " (part " + std::to_string(part) +
           (flip ? ", flipped" : "") + ")";
}

namespace {

/// Each event's line (WalkEvent::toString).
struct EventText {
    const Scene* scene;

    std::string operator()(const walk::Region& e) const {
        return "region " + std::to_string(e.region) + "  " + interval(e.t0, e.t1);
    }
    std::string operator()(const walk::Pointer& e) const {
        return "pointer " + std::to_string(e.from) + " -> " + std::to_string(e.to) + " (corner " +
               std::to_string(e.corner) + ")";
    }
    std::string operator()(const walk::PrimTest& e) const {
        return "test " + prim(e.prim, scene) + "  spans " + lancer::toString(e.spans);
    }
    std::string operator()(const walk::MailboxHit& e) const {
        return "mailbox hit p" + std::to_string(e.prim);
    }
    std::string operator()(const walk::Spans& e) const {
        return "region tree spans " + lancer::toString(e.spans);
    }
    std::string operator()(const walk::Error& e) const { return "WALK ERROR: " + e.what; }
    std::string operator()(const walk::Locate& e) const {
        return "start at " + pt(e.point) + " in region " + std::to_string(e.region);
    }
    std::string operator()(const walk::Exit& e) const {
        const int n = (e.ties & 1) + (e.ties >> 1 & 1) + (e.ties >> 2 & 1);
        const char* through = n == 1 ? "face" : n == 2 ? "edge" : "corner";
        return "exit at t = " + num(e.t) + " " + pt(e.point) + " through " + through + " " +
               axes(e.ties);
    }
    std::string operator()(const walk::Lookup& e) const {
        return "directory cell " + cells(e.cell.data()) + " of " + pt(e.point) + " -> leaf " +
               std::to_string(e.leaf);
    }
    std::string operator()(const walk::Push& e) const {
        return "pushed across " + axes(e.axes) + " to " + pt(e.point);
    }
    std::string operator()(const walk::IndexStep& e) const {
        return "index step on " + axes(1 << e.axis) + " to cell " + cells(e.cell.data());
    }
    std::string operator()(const walk::Rope& e) const {
        return "rope " + std::to_string(e.from) + " -> " + std::to_string(e.to) + " across face " +
               (e.face % 2 ? "+" : "-") + axes(1 << (e.face / 2));
    }
    std::string operator()(const walk::Children& e) const {
        const std::string node = "node " + std::to_string(e.node);
        if (e.count == 0) return node + ": the ray meets no child's box";
        std::string s = node + ":";
        for (int i = 0; i < e.count; ++i)
            s += (i ? ", then child " : " child ") + std::to_string(e.nodes[size_t(i)]) +
                 " at t = " + num(e.t0s[size_t(i)]);
        return s;
    }
    std::string operator()(const walk::Culled& e) const {
        if (e.blocked)
            return "node " + std::to_string(e.node) +
                   " skipped: blocked (a span starts at t = " + num(e.hitT) +
                   "), and its box does not hold the ray's start";
        return "node " + std::to_string(e.node) + " skipped: its box begins at t = " + num(e.t0) +
               ", beyond the hit at t = " + num(e.hitT);
    }
    std::string operator()(const walk::Restart& e) const { return "walk restarts: " + e.why; }
    std::string operator()(const walk::Stretch& e) const {
        return "light buffer stretch " + std::to_string(e.index) + "  " + interval(e.t0, e.t1);
    }
    std::string operator()(const walk::LightBufferClear&) const {
        return "light buffer: nothing can block it, no walk";
    }
    std::string operator()(const walk::Blocker& e) const {
        return "blocked at t = " + num(e.t) + " by " + prim(e.prim, scene);
    }
    std::string operator()(const walk::RayBegin& e) const {
        return std::string(rayKindName(e.kind)) + " ray begins at " + pt(e.origin) + "  " +
               interval(e.tmin, e.tmax);
    }
    std::string operator()(const walk::RayEnd& e) const {
        if (e.kind == RayKind::Shadow) return e.occluded ? "ray ends: occluded" : "ray ends: lit";
        if (e.prim == kNoPrim) return "ray ends: no hit";
        return "ray ends: hit t = " + num(e.t) + " on " + prim(e.prim, scene) + " at " +
               pt(e.point);
    }
};

}  // namespace

std::string WalkEvent::toString(const Scene* scene) const {
    return std::visit(EventText{scene}, data);
}

std::ostream& operator<<(std::ostream& os, const Hit& h) { return os << h.toString(); }

std::ostream& operator<<(std::ostream& os, const WalkEvent& e) { return os << e.toString(); }

}  // namespace lancer
