#include <iostream>
#include <nlohmann/json.hpp>

#include "app/cli/commands.h"
#include "engine/accel/structure_view.h"
#include "engine/render/ray_csg.h"
#include "engine/render/ray_tree.h"
#include "engine/scene/loader.h"

namespace lancer::cli {

int runTrace(const CommonOptions& o, const TraceOptions& t) {
    try {
        Scene scene = loadSceneWithCamera(o);
        auto accel = buildAccelerator(scene, o.knobs.build, buildProgressOnStderr());
        // The size and camera `render` resolves from the same options, so the pixel's rays are
        // the ones render traces.
        int w, h;
        resolveSize(o, scene, w, h);
        const Camera& cam = scene.camera;
        if (t.x < 0 || t.x >= w || t.y < 0 || t.y >= h)
            throw std::invalid_argument("--pixel " + std::to_string(t.x) + " " +
                                        std::to_string(t.y) + " is outside the " +
                                        std::to_string(w) + "x" + std::to_string(h) + " image");
        const RayTree tree = tracePixel(scene, *accel, o.knobs.shading, cam, t.x, t.y, w, h);
        const TracedRay& primary = tree.rays.front();
        // Each ray's wasted work (docs/viewer.md, "Wasted work"), from its recorded events.
        // Region corners and each step's reason are read from the structure walked.
        const StructureView view(scene, *accel);
        std::vector<RayWaste> waste;
        for (const TracedRay& r : tree.rays)
            waste.push_back(wastedWork(scene, r, rayCsg(scene, view, r)));
        // A ray's JSON gains "wasted" (its counts) and each wasted test's event its class.
        auto addWaste = [](nlohmann::json& ray, const RayWaste& w) {
            const WasteCounts& c = w.total;
            ray["wasted"] = {
                {"tests", c.tests},   {"wasted", c.wasted()},        {"repeats", c.repeats},
                {"misses", c.misses}, {"beyond_exit", c.beyondExit}, {"no_effect", c.noEffect}};
            nlohmann::json& ev = ray["events"];
            for (size_t i = 0; i < w.perEvent.size() && i < ev.size(); ++i)
                if (w.perEvent[i] != Waste::None) ev[i]["wasted"] = wasteName(w.perEvent[i]);
        };

        if (t.json) {
            // Every region event carries the region's 8 world corners and its step's reason.
            const RegionCornersFn corners = [&view](uint32_t id) {
                const std::array<Vec3, 8> c = view.regionCorners(id);
                return std::vector<Vec3>(c.begin(), c.end());
            };
            nlohmann::json j;
            j["scene"] = o.scene;
            j["scheme"] = schemeName(o.knobs.build.scheme);
            j["pixel"] = {t.x, t.y};
            j["width"] = w;
            j["height"] = h;
            j["camera"] = nlohmann::json::parse(cam.toJson());
            j["bounces"] = o.knobs.shading.bounces;
            nlohmann::json p = toJson(primary, scene, corners, &view);
            addWaste(p, waste.front());
            j["ray"] = {{"origin", p["origin"]}, {"direction", p["direction"]}};
            j["events"] = p["events"];
            j["hit"] = p["hit"];
            if (primary.hit.valid()) {
                // Whether the primary ray enters a solid there (its direction against the normal).
                j["hit"]["entering"] = glm::dot(primary.normal, primary.direction) < 0.0;
            }
            // The pixel's counts over its whole ray tree: render's per-pixel counters.
            j["prim_tests"] = tree.counters.primTests;
            j["mailbox_hits"] = tree.counters.mailboxHits;
            j["region_visits"] = tree.counters.regionVisits;
            j["walk_errors"] = tree.counters.walkErrors;
            j["counters"] = toJson(tree.counters);
            nlohmann::json rays = nlohmann::json::array();
            for (size_t i = 0; i < tree.rays.size(); ++i) {
                rays.push_back(toJson(tree.rays[i], scene, corners, &view));
                addWaste(rays.back(), waste[i]);
            }
            j["rays"] = std::move(rays);
            std::cout << j.dump(2) << "\n";
            return 0;
        }
        std::cout.precision(10);
        std::cout << "scene " << o.scene << ", scheme " << schemeName(o.knobs.build.scheme)
                  << ", bounces " << o.knobs.shading.bounces << "\n"
                  << tree.toString(&scene, &view);
        std::cout << "primitive tests " << tree.counters.primTests << ", mailbox hits "
                  << tree.counters.mailboxHits << ", regions " << tree.counters.regionVisits
                  << " (the pixel's " << tree.rays.size() << " rays)\n";
        for (size_t i = 0; i < tree.rays.size(); ++i)
            std::cout << "wasted work of #" << i << ": " << waste[i].total.toString() << "\n";
        if (primary.hit.valid())
            std::cout << "hit " << primary.hit << " " << scene.prims[primary.hit.prim].toString()
                      << "\n    point " << toString(primary.point) << " normal "
                      << toString(primary.normal) << "\n";
        else
            std::cout << "no hit\n";
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 2;
    }
}

}  // namespace lancer::cli
