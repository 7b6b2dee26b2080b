#include <iostream>
#include <nlohmann/json.hpp>

#include "app/cli/commands.h"
#include "engine/scene/loader.h"

namespace lancer::cli {

namespace {

nlohmann::json vec(const Vec3& v) { return {v.x, v.y, v.z}; }

nlohmann::json spansJson(const SpanList& spans) {
    nlohmann::json a = nlohmann::json::array();
    for (const Span& s : spans)
        a.push_back({{"t_in", s.in.t},
                     {"prim_in", s.in.prim},
                     {"t_out", s.out.t},
                     {"prim_out", s.out.prim}});
    return a;
}

nlohmann::json eventsJson(const std::vector<WalkEvent>& events) {
    nlohmann::json a = nlohmann::json::array();
    for (const WalkEvent& e : events) {
        switch (e.kind) {
            case WalkEvent::Region:
                a.push_back({{"event", "region"}, {"region", e.a}, {"t0", e.t0}, {"t1", e.t1}});
                break;
            case WalkEvent::Pointer:
                a.push_back(
                    {{"event", "pointer"}, {"from", e.a}, {"to", e.b}, {"corner", e.corner}});
                break;
            case WalkEvent::PrimTest:
                a.push_back({{"event", "prim_test"}, {"prim", e.a}, {"spans", spansJson(e.spans)}});
                break;
            case WalkEvent::MailboxHit:
                a.push_back({{"event", "mailbox_hit"}, {"prim", e.a}});
                break;
            case WalkEvent::Spans:
                a.push_back({{"event", "region_spans"}, {"spans", spansJson(e.spans)}});
                break;
            case WalkEvent::Error:
                a.push_back({{"event", "walk_error"}, {"what", e.what}});
                break;
        }
    }
    return a;
}

void printEvents(const Scene& scene, const std::vector<WalkEvent>& events) {
    for (const WalkEvent& e : events) {
        switch (e.kind) {
            case WalkEvent::Region:
                std::cout << "  region " << e.a << "  t = [" << e.t0 << ", " << e.t1 << "]\n";
                break;
            case WalkEvent::Pointer:
                std::cout << "  pointer " << e.a << " -> " << e.b << " (corner " << e.corner
                          << ")\n";
                break;
            case WalkEvent::PrimTest:
                std::cout << "    test p" << e.a << " " << scene.prims[e.a].toString()
                          << "\n      spans " << toString(e.spans) << "\n";
                break;
            case WalkEvent::MailboxHit:
                std::cout << "    mailbox hit p" << e.a << "\n";
                break;
            case WalkEvent::Spans:
                std::cout << "    region tree spans " << toString(e.spans) << "\n";
                break;
            case WalkEvent::Error:
                std::cout << "  WALK ERROR: " << e.what << "\n";
                break;
        }
    }
}

}  // namespace

int runTrace(const CommonOptions& o, const TraceOptions& t) {
    try {
        Scene scene = loadScene(o.scene);
        auto accel = buildAccelerator(scene, o.build, buildProgressOnStderr());
        int w, h;
        resolveSize(o, scene, w, h);
        if (t.x < 0 || t.x >= w || t.y < 0 || t.y >= h)
            throw std::invalid_argument("--pixel " + std::to_string(t.x) + " " +
                                        std::to_string(t.y) + " is outside the " +
                                        std::to_string(w) + "x" + std::to_string(h) + " image");
        Tracer tracer(scene, *accel, o.render.shading);
        TraceContext ctx(scene.prims.size(), scene.tree.depth());
        ctx.useMailboxes = accel->usesMailboxes();
        Ray ray = scene.camera.primaryRay(t.x, t.y, w, h);
        RecordingObserver obs;
        Hit hit;
        bool found = tracer.nearest(ray, 0.0, kInf, ctx, obs, hit);

        nlohmann::json j;
        j["scene"] = o.scene;
        j["scheme"] = schemeName(o.build.scheme);
        j["pixel"] = {t.x, t.y};
        j["ray"] = {{"origin", vec(ray.o)}, {"direction", vec(ray.d)}};
        j["events"] = eventsJson(obs.events);
        j["prim_tests"] = ctx.counters.primTests;
        j["mailbox_hits"] = ctx.counters.mailboxHits;
        j["region_visits"] = ctx.counters.regionVisits;
        j["walk_errors"] = ctx.counters.walkErrors;
        if (found) {
            SurfacePoint s = tracer.surface(ray, hit);
            j["hit"] = {{"t", hit.t},
                        {"prim", hit.prim},
                        {"primitive", scene.prims[hit.prim].toString()},
                        {"point", vec(s.p)},
                        {"normal", vec(s.n)},
                        {"entering", s.entering}};
        } else {
            j["hit"] = nullptr;
        }
        if (t.json) {
            std::cout << j.dump(2) << "\n";
            return 0;
        }
        std::cout.precision(10);
        std::cout << "pixel (" << t.x << ", " << t.y << ") of " << w << "x" << h << ", scheme "
                  << schemeName(o.build.scheme) << "\n"
                  << ray.toString() << "\n";
        printEvents(scene, obs.events);
        std::cout << "primitive tests " << ctx.counters.primTests << ", mailbox hits "
                  << ctx.counters.mailboxHits << ", regions " << ctx.counters.regionVisits << "\n";
        if (found)
            std::cout << "hit t = " << hit.t << " on p" << hit.prim << " "
                      << scene.prims[hit.prim].toString() << "\n    point "
                      << j["hit"]["point"].dump() << " normal " << j["hit"]["normal"].dump()
                      << "\n";
        else
            std::cout << "no hit\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 2;
    }
}

}  // namespace lancer::cli
