#include "engine/scene/scene.h"

#include <atomic>
#include <cmath>

#include "engine/model/restriction.h"
#include "engine/util/huge_pages.h"

namespace lancer {

void Scene::prepare() {
    if (std::string err = checkSurfacesUnderUnions(tree, prims); !err.empty())
        throw SceneError((name.empty() ? "" : name + ": ") + err);
    MinimizedBoxes mb = minimizeBoxes(tree, prims);
    minBox = std::move(mb.box);
    droppedPrims = mb.dropped;
    minimizeIterations = mb.iterations;
    if (droppedPrims > 0) {
        std::vector<char> keep(prims.size(), 0);
        for (size_t i = 0; i < prims.size(); ++i) keep[i] = !minBox[i].isEmpty();
        CsgTree t;
        t.root = restrictTree(tree, tree.root, keep, t);
        tree = std::move(t);
    }
    bounds = Box3::empty();
    for (uint32_t p : tree.primitives()) bounds.expand(minBox[p]);
    // Read at random by every walk over a union of spheres: huge pages spare most TLB misses.
    packedSpheres.clear();
    reserveHuge(packedSpheres, prims.size());
    packedSpheres.assign(prims.size(), PackedSphere{});
    for (size_t i = 0; i < prims.size(); ++i)
        if (const Sphere* sp = std::get_if<Sphere>(&prims[i].shape); sp && !prims[i].hasXf)
            packedSpheres[i] = {sp->c, sp->r};
    prepared = true;
    static std::atomic<uint64_t> preparations{0};
    preparedId = ++preparations;
}

int Scene::primSpansFloat(uint32_t p, const Ray& ray, Span* out) const {
    if (p < packedSpheres.size() && packedSpheres[p].r >= 0.0)
        return sphereSpansOf(glm::vec3(packedSpheres[p].c), float(packedSpheres[p].r),
                             RayF{glm::vec3(ray.o), glm::vec3(ray.d)}, p, out);
    return prims[p].spansFloat(ray, p, out);
}

void Scene::frameCamera(const Vec3& dir, const Vec3& upv) {
    Box3 b = bounds.isEmpty() ? Box3{Vec3(-1.0), Vec3(1.0)} : bounds;
    Vec3 c = b.center();
    double radius = std::max(0.5 * glm::length(b.extent()), 1e-6);
    camera.at = c;
    camera.up = upv;
    camera.fov = 40.0;
    double dist = radius / std::sin(glm::radians(camera.fov) * 0.5) * 1.05;
    camera.from = c - glm::normalize(dir) * dist;
    camera.orthoHeight = 2.1 * radius;
}

void Scene::defaultLights() {
    Box3 b = bounds.isEmpty() ? Box3{Vec3(-1.0), Vec3(1.0)} : bounds;
    Vec3 c = b.center();
    double r = std::max(glm::length(b.extent()), 1e-6);
    Vec3 f, rr, u;
    camera.basis(f, rr, u);
    lights = {{c + r * (-f + rr + 1.5 * u), Vec3(0.7)},
              {c + r * (-f - 1.2 * rr + 0.5 * u), Vec3(0.4)},
              {c + r * (0.5 * f + 2.0 * u), Vec3(0.3)}};
}

double Scene::scale() const {
    if (bounds.isEmpty()) return 1.0;
    double m = 1.0;
    for (int a = 0; a < 3; ++a) m = std::max({m, std::abs(bounds.lo[a]), std::abs(bounds.hi[a])});
    return m;
}

}  // namespace lancer
