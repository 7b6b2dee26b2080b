#include "app/bench/embree_peer.h"

#include <chrono>
#include <stdexcept>

#ifdef LANCER_HAVE_EMBREE
#include <embree3/rtcore.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#endif

namespace lancer::bench {

bool EmbreePeer::supports(const Scene& scene) {
    for (const CsgNode& n : scene.tree.nodes)
        if (n.op == Op::Intersection || n.op == Op::Difference) return false;
    return true;
}

#ifndef LANCER_HAVE_EMBREE

bool EmbreePeer::available() { return false; }
struct EmbreePeer::Impl {};
EmbreePeer::EmbreePeer(const Scene&) { throw std::runtime_error("this build has no Embree"); }
EmbreePeer::~EmbreePeer() = default;
RenderStats EmbreePeer::render(const RenderOptions&, Image&) const { return {}; }

#else

bool EmbreePeer::available() { return true; }

namespace {

/// Closest hit of one of Lancer's primitives, for Embree's user geometry.
void userBounds(const RTCBoundsFunctionArguments* args) {
    const auto* prims = static_cast<const std::vector<const Primitive*>*>(args->geometryUserPtr);
    const Box3& b = (*prims)[args->primID]->worldBox;
    *args->bounds_o = {float(b.lo.x), float(b.lo.y), float(b.lo.z), 0.0f,
                       float(b.hi.x), float(b.hi.y), float(b.hi.z), 0.0f};
}

bool userHit(const Primitive& p, const RTCRay& ray, float& t) {
    Ray r{{ray.org_x, ray.org_y, ray.org_z}, {ray.dir_x, ray.dir_y, ray.dir_z}};
    Span s[2];
    int n = p.spans(r, 0, s);
    for (int i = 0; i < n; ++i)
        for (double ti : {s[i].in.t, s[i].out.t})
            if (ti >= ray.tnear && ti < ray.tfar) {
                t = float(ti);
                return true;
            }
    return false;
}

void userIntersect(const RTCIntersectFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto* prims = static_cast<const std::vector<const Primitive*>*>(args->geometryUserPtr);
    auto* rh = reinterpret_cast<RTCRayHit*>(args->rayhit);
    float t;
    if (!userHit(*(*prims)[args->primID], rh->ray, t)) return;
    rh->ray.tfar = t;
    rh->hit.geomID = args->geomID;
    rh->hit.primID = args->primID;
    rh->hit.Ng_x = rh->hit.Ng_y = rh->hit.Ng_z = 0.0f;
}

void userOccluded(const RTCOccludedFunctionNArguments* args) {
    if (!args->valid[0]) return;
    const auto* prims = static_cast<const std::vector<const Primitive*>*>(args->geometryUserPtr);
    auto* ray = reinterpret_cast<RTCRay*>(args->ray);
    float t;
    if (userHit(*(*prims)[args->primID], *ray, t)) ray->tfar = -kInf;
}

bool convex(const Polygon& pg) {
    int ax = (pg.drop + 1) % 3, ay = (pg.drop + 2) % 3;
    size_t n = pg.p.size();
    int sign = 0;
    for (size_t i = 0; i < n; ++i) {
        const Vec3 &a = pg.p[i], &b = pg.p[(i + 1) % n], &c = pg.p[(i + 2) % n];
        double cr = (b[ax] - a[ax]) * (c[ay] - b[ay]) - (b[ay] - a[ay]) * (c[ax] - b[ax]);
        int s = cr > 0 ? 1 : cr < 0 ? -1 : 0;
        if (s && sign && s != sign) return false;
        if (s) sign = s;
    }
    return true;
}

}  // namespace

struct EmbreePeer::Impl {
    const Scene* scene;
    RTCDevice device = nullptr;
    RTCScene rtc = nullptr;
    std::vector<uint32_t> sphereIds, triangleIds;  // Embree primID -> Lancer primitive
    std::vector<const Primitive*> userPrims;
    std::vector<uint32_t> userIds;
    unsigned sphereGeom = RTC_INVALID_GEOMETRY_ID, triangleGeom = RTC_INVALID_GEOMETRY_ID,
             userGeom = RTC_INVALID_GEOMETRY_ID;

    uint32_t primOf(unsigned geom, unsigned prim) const {
        if (geom == sphereGeom) return sphereIds[prim];
        if (geom == triangleGeom) return triangleIds[prim];
        return userIds[prim];
    }
};

EmbreePeer::EmbreePeer(const Scene& scene) : impl_(std::make_unique<Impl>()) {
    if (!supports(scene))
        throw std::invalid_argument("Embree peer: the scene is not a union of primitives");
    auto start = std::chrono::steady_clock::now();
    Impl& m = *impl_;
    m.scene = &scene;
    m.device = rtcNewDevice(nullptr);
    m.rtc = rtcNewScene(m.device);
    std::vector<Vec3> spheres;  // centre; radius kept alongside
    std::vector<double> radii;
    std::vector<std::array<Vec3, 3> > tris;
    for (uint32_t id : scene.livePrimitives()) {
        const Primitive& p = scene.prims[id];
        if (const Sphere* s = std::get_if<Sphere>(&p.shape); s && !p.hasXf) {
            spheres.push_back(s->c), radii.push_back(s->r), m.sphereIds.push_back(id);
        } else if (const Triangle* t = std::get_if<Triangle>(&p.shape); t && !p.hasXf) {
            tris.push_back({t->p[0], t->p[1], t->p[2]}), m.triangleIds.push_back(id);
        } else if (const Polygon* pg = std::get_if<Polygon>(&p.shape);
                   pg && !p.hasXf && convex(*pg)) {
            for (size_t i = 1; i + 1 < pg->p.size(); ++i)
                tris.push_back({pg->p[0], pg->p[i], pg->p[i + 1]}), m.triangleIds.push_back(id);
        } else {
            m.userPrims.push_back(&p), m.userIds.push_back(id);
        }
    }
    if (!spheres.empty()) {
        RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), spheres.size()));
        for (size_t i = 0; i < spheres.size(); ++i)
            v[4 * i] = float(spheres[i].x), v[4 * i + 1] = float(spheres[i].y),
                  v[4 * i + 2] = float(spheres[i].z), v[4 * i + 3] = float(radii[i]);
        rtcCommitGeometry(g);
        m.sphereGeom = rtcAttachGeometry(m.rtc, g);
        rtcReleaseGeometry(g);
    }
    if (!tris.empty()) {
        RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 3 * tris.size()));
        auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), tris.size()));
        for (size_t i = 0; i < tris.size(); ++i)
            for (int k = 0; k < 3; ++k) {
                for (int a = 0; a < 3; ++a)
                    v[9 * i + 3 * size_t(k) + size_t(a)] = float(tris[i][size_t(k)][a]);
                idx[3 * i + size_t(k)] = unsigned(3 * i + size_t(k));
            }
        rtcCommitGeometry(g);
        m.triangleGeom = rtcAttachGeometry(m.rtc, g);
        rtcReleaseGeometry(g);
    }
    if (!m.userPrims.empty()) {
        RTCGeometry g = rtcNewGeometry(m.device, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(g, unsigned(m.userPrims.size()));
        rtcSetGeometryUserData(g, &m.userPrims);
        rtcSetGeometryBoundsFunction(g, userBounds, nullptr);
        rtcSetGeometryIntersectFunction(g, userIntersect);
        rtcSetGeometryOccludedFunction(g, userOccluded);
        rtcCommitGeometry(g);
        m.userGeom = rtcAttachGeometry(m.rtc, g);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(m.rtc);
    buildMs_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

EmbreePeer::~EmbreePeer() {
    if (impl_ && impl_->rtc) rtcReleaseScene(impl_->rtc);
    if (impl_ && impl_->device) rtcReleaseDevice(impl_->device);
}

RenderStats EmbreePeer::render(const RenderOptions& opt, Image& img) const {
    using Clock = std::chrono::steady_clock;
    const Impl& m = *impl_;
    const Scene& scene = *m.scene;
    RenderStats stats;
    stats.threads = effectiveThreads(opt.threads);
    const int w = img.width, h = img.height;
    double scale = scene.scale();
    const PrimaryRays primary(scene.camera, w, h);
    std::atomic<uint64_t> rays{0}, shadows{0};
    auto start = Clock::now();
    tbb::task_arena arena(stats.threads);
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range2d<int>(0, h, opt.tile, 0, w, opt.tile),
            [&](const tbb::blocked_range2d<int>& r) {
                RTCIntersectContext ctx;
                rtcInitIntersectContext(&ctx);
                uint64_t nRays = 0, nShadow = 0;
                for (int y = r.rows().begin(); y < r.rows().end(); ++y)
                    for (int x = r.cols().begin(); x < r.cols().end(); ++x) {
                        Ray ray = primary(x, y);
                        RTCRayHit rh{};
                        rh.ray = {float(ray.o.x),
                                  float(ray.o.y),
                                  float(ray.o.z),
                                  0.0f,
                                  float(ray.d.x),
                                  float(ray.d.y),
                                  float(ray.d.z),
                                  0.0f,
                                  float(kInf),
                                  0xffffffffu,
                                  0,
                                  0};
                        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                        rtcIntersect1(m.rtc, &ctx, &rh);
                        ++nRays;
                        size_t i = img.index(x, y);
                        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
                            img.color[i] = glm::vec3(scene.background);
                            continue;
                        }
                        uint32_t id = m.primOf(rh.hit.geomID, rh.hit.primID);
                        const Primitive& prim = scene.prims[id];
                        img.depth[i] = rh.ray.tfar;
                        img.hitPrim[i] = id;
                        Vec3 p = ray.at(rh.ray.tfar);
                        Vec3 n = prim.normal(p, 0);
                        if (glm::dot(n, ray.d) > 0) n = -n;
                        const Material& mat = scene.materials[size_t(prim.material)];
                        Vec3 c = mat.ambient * mat.color;
                        double eps = opt.shading.offsetScale *
                                     std::max({scale, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
                        Vec3 o = p + eps * n;
                        for (const Light& light : scene.lights) {
                            Vec3 L = light.position - o;
                            double dist = glm::length(L);
                            double ndl = glm::dot(n, L) / dist;
                            if (ndl <= 0) continue;
                            RTCRay sr{float(o.x),
                                      float(o.y),
                                      float(o.z),
                                      0.0f,
                                      float(L.x / dist),
                                      float(L.y / dist),
                                      float(L.z / dist),
                                      0.0f,
                                      float(dist),
                                      0xffffffffu,
                                      0,
                                      0};
                            rtcOccluded1(m.rtc, &ctx, &sr);
                            ++nRays, ++nShadow;
                            if (sr.tfar >= 0.0f) c += light.color * (mat.diffuse * ndl) * mat.color;
                        }
                        img.color[i] = glm::vec3(c);
                    }
                rays += nRays;
                shadows += nShadow;
            });
    });
    stats.renderMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    stats.counters.rays = rays;
    stats.counters.shadowRays = shadows;
    stats.counters.primaryRays = uint64_t(w) * uint64_t(h);
    return stats;
}

#endif

}  // namespace lancer::bench
