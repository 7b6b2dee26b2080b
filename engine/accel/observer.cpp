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

std::string WalkEvent::toString(const Scene* scene) const {
    switch (kind) {
        case Region:
            return "region " + std::to_string(a) + "  " + interval(t0, t1);
        case Pointer:
            return "pointer " + std::to_string(a) + " -> " + std::to_string(b) + " (corner " +
                   std::to_string(corner) + ")";
        case PrimTest:
            return "test " + prim(a, scene) + "  spans " + lancer::toString(spans);
        case MailboxHit:
            return "mailbox hit p" + std::to_string(a);
        case Spans:
            return "region tree spans " + lancer::toString(spans);
        case Error:
            return "WALK ERROR: " + what;
        case Locate:
            return "start at " + pt(point) + " in region " + std::to_string(b);
        case Exit: {
            const int n = (ties & 1) + (ties >> 1 & 1) + (ties >> 2 & 1);
            const char* through = n == 1 ? "face" : n == 2 ? "edge" : "corner";
            return "exit at t = " + num(t0) + " " + pt(point) + " through " + through + " " +
                   axes(ties);
        }
        case Lookup:
            return "directory cell " + cells(cell) + " of " + pt(point) + " -> leaf " +
                   std::to_string(b);
        case Push:
            return "pushed across " + axes(ties) + " to " + pt(point);
        case IndexStep:
            return "index step on " + axes(1 << axis) + " to cell " + cells(cell);
        case Rope:
            return "rope " + std::to_string(a) + " -> " + std::to_string(b) + " across face " +
                   (axis % 2 ? "+" : "-") + axes(1 << (axis / 2));
        case Children: {
            const std::string node = "node " + std::to_string(corner);
            if (a == kNoNodeId) return node + ": the ray meets neither child's box";
            std::string s = node + ": child " + std::to_string(a) + " at t = " + num(t0);
            if (b != kNoNodeId) s += ", then child " + std::to_string(b) + " at t = " + num(t1);
            return s;
        }
        case Restart:
            return "walk restarts: " + what;
        case Culled:
            return "node " + std::to_string(a) + " skipped: its box begins at t = " + num(t0) +
                   ", beyond the hit at t = " + num(t1);
        case Stretch:
            return "light buffer stretch " + std::to_string(a) + "  " + interval(t0, t1);
        case LightBufferClear:
            return "light buffer: nothing can block it, no walk";
        case Blocker:
            return "blocked at t = " + num(t0) + " by " + prim(a, scene);
        case RayBegin:
            return std::string(rayKindName(RayKind(axis))) + " ray begins at " + pt(point) + "  " +
                   interval(t0, t1);
        case RayEnd:
            if (axis == int(RayKind::Shadow)) return b ? "ray ends: occluded" : "ray ends: lit";
            if (a == kNoPrim) return "ray ends: no hit";
            return "ray ends: hit t = " + num(t0) + " on " + prim(a, scene) + " at " + pt(point);
    }
    return "?";
}

std::ostream& operator<<(std::ostream& os, const Hit& h) { return os << h.toString(); }

std::ostream& operator<<(std::ostream& os, const WalkEvent& e) { return os << e.toString(); }

}  // namespace lancer
