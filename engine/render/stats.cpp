#include "engine/render/stats.h"

namespace lancer {

nlohmann::json statsJson(const Scene& scene, const Accelerator& accel, const RenderOptions& opt,
                         const RenderStats& rs) {
    const BuildParams& p = accel.params();
    const AccelInfo& info = accel.info();
    const RayCounters& c = rs.counters;
    nlohmann::json j;
    j["scene"] = scene.name;
    j["scheme"] = schemeName(p.scheme);
    j["width"] = opt.width;
    j["height"] = opt.height;
    j["threads"] = rs.threads;
    j["build_ms"] = info.buildMs;
    j["render_ms"] = rs.renderMs;
    for (const RayCounters::Field& f : RayCounters::fields()) j[f.key] = c.*f.member;
    j["regions"] = info.regions;
    j["memory_bytes"] = info.memoryBytes;
    // The scheme's own max-objects (the automatic one's count); the regular scheme's other
    // knobs are written for every scheme, as they always were (DESIGN.md section 6 lists
    // max_level and step).
    j["max_level"] = p.scheme == SchemeKind::Bvh ? p.bvh.maxLevel : p.regular.maxLevel;
    j["max_objects"] = p.scheme == SchemeKind::Irregular ? p.irregular.objects()
                       : p.scheme == SchemeKind::Bvh     ? p.bvh.objects()
                                                         : p.regular.objects();
    j["step"] = stepName(p.regular.step);
    j["delta"] = p.regular.delta;
    j["bsp_heuristic"] = heuristicName(p.irregular.heuristic);
    j["mailboxes"] = accel.usesMailboxes();
    j["bounces"] = opt.shading.bounces;
    j["primitives"] = scene.prims.size();
    j["live_primitives"] = scene.livePrimitives().size();
    j["dropped_primitives"] = scene.droppedPrims;
    j["model_error"] = scene.modelError;
    j["openscad_mesh_error"] = scene.openScadMeshError;
    double rays = c.rays ? double(c.rays) : 1.0;
    j["prim_tests_per_ray"] = double(c.primTests) / rays;
    j["region_visits_per_ray"] = double(c.regionVisits) / rays;
    j["cancelled"] = rs.cancelled;
    for (const auto& [k, v] : info.extra.items()) j[k] = v;
    return j;
}

}  // namespace lancer
