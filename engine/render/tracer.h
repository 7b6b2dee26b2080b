// Whitted shading (ambient, Lambert, Phong, shadows, mirror reflection, refraction), tracing
// every ray, primary or secondary, through the same acceleration scheme.
#pragma once

#include <cmath>

#include "engine/accel/accelerator.h"

namespace lancer {

struct ShadingOptions {
    int bounces = 3;  ///< reflection/refraction depth; 0 = primary and shadow rays only
    bool shadows = true;
    bool reflections = true;
    bool refractions = true;
    /// Secondary rays start at p + eps * n, n the geometric normal on the side the ray leaves
    /// towards, eps = offsetScale * max(scene scale, |p|_inf): a relative offset that follows
    /// floating-point spacing, so far-from-origin scenes need no retuning.
    double offsetScale = 1e-9;
    /// Arithmetic of the primitives' tests (--precision): float measures what single precision
    /// costs in depth error (docs/benchmarks.md, "Float against double").
    Precision precision = Precision::Double;
};

/// A hit resolved to a point, its normals and material.
struct SurfacePoint {
    Vec3 p;
    Vec3 n;         ///< outward normal (solids), geometric normal facing the ray (surfaces)
    Vec3 facing;    ///< n turned to face the incoming ray
    bool entering;  ///< the ray enters the solid here
    const Material* material;
};

class Tracer {
  public:
    Tracer(const Scene& scene, const Accelerator& accel, const ShadingOptions& opt)
        : scene_(scene), accel_(accel), opt_(opt), scale_(scene.scale()) {}

    /// Nearest hit with t in (tmin, tmax]. One new ray id for the mailboxes.
    template <class Obs>
    bool nearest(const Ray& ray, double tmin, double tmax, TraceContext& ctx, Obs& obs,
                 Hit& hit) const {
        ctx.beginRay();
        // An empty interval holds no hit in any scheme: the primary rays the eye buffer sends
        // from +inf (no box in their direction), most pixels of a small object's image, skip
        // the scheme's clip and frame mapping.
        if (!(tmin < tmax)) return false;
        return accel_.intersect(ray, tmin, tmax, ctx, obs, hit);
    }

    /// Whether the shadow ray toward scene light `light` is blocked before tmax. One new ray id.
    template <class Obs>
    bool occluded(const Ray& ray, double tmax, uint32_t light, TraceContext& ctx, Obs& obs) const {
        ctx.beginRay();
        return accel_.occluded(ray, tmax, light, ctx, obs);
    }

    SurfacePoint surface(const Ray& ray, const Hit& hit) const {
        SurfacePoint s;
        const Primitive& prim = scene_.prims[hit.prim];
        s.p = ray.at(hit.t);
        s.n = prim.normal(s.p, hit.part);
        if (hit.flip) s.n = -s.n;
        s.entering = glm::dot(s.n, ray.d) < 0.0;
        if (prim.isSurface() && !s.entering) {  // surfaces face the ray
            s.n = -s.n;
            s.entering = true;
        }
        s.facing = s.entering ? s.n : -s.n;
        s.material = &scene_.materials[size_t(prim.material)];
        return s;
    }

    double offset(const Vec3& p) const {
        double m = std::max({scale_, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        return opt_.offsetScale * m;
    }

    /// Colour of pixel (x, y) and its primary hit: its primary ray from where the eye buffer
    /// (Accelerator::eyeBuffer) says it can first meet something, and the rays below it. What
    /// render() computes for each pixel, and what tracePixel() records.
    template <class Obs>
    Vec3 pixel(const PrimaryRays& primary, const LightBuffer& eye, int x, int y, TraceContext& ctx,
               Obs& obs, Hit& hit) const {
        const Ray ray = primary.pixel(x, y);
        ++ctx.counters.primaryRays;
        double near = eye.nearFrom(ray.d, 0);
        // A float test may put a hit on the nearest box's face a little before it.
        if (ctx.precision == Precision::Float && near > 0.0)
            near = std::max(0.0, near - floatSlack(ray, near));
        return radiance(ray, 0, ctx, obs, &hit, near);
    }

    /// Colour seen along `ray`; depth counts reflection/refraction bounces already taken.
    /// `tmin`: the ray meets nothing before it (for a primary ray, the eye's buffer says so).
    /// `kind`: why the ray was cast, told to the observer with every ray it casts.
    template <class Obs>
    Vec3 radiance(const Ray& ray, int depth, TraceContext& ctx, Obs& obs, Hit* first = nullptr,
                  double tmin = 0.0, RayKind kind = RayKind::Primary) const {
        Hit hit;
        obs.rayBegin(kind, depth, -1, ray, tmin, kInf);
        if (!nearest(ray, tmin, kInf, ctx, obs, hit)) {
            if constexpr (Obs::kActive) obs.rayEnd({kind, hit, Vec3(0.0), Vec3(0.0), false});
            if (first) *first = hit;
            return scene_.background;
        }
        if (first) *first = hit;
        SurfacePoint s = surface(ray, hit);
        if constexpr (Obs::kActive) obs.rayEnd({kind, hit, s.p, s.n, false});
        const Material& m = *s.material;
        Vec3 dir = ray.d;
        Vec3 color = m.ambient * m.color;
        double eps = offset(s.p);
        Vec3 above = s.p + eps * s.facing;

        // Direct light, with one shadow ray per light the surface faces.
        for (uint32_t li = 0; li < scene_.lights.size(); ++li) {
            const Light& light = scene_.lights[li];
            Vec3 L = light.position - s.p;
            double dist = glm::length(L);
            if (!(dist > 0.0)) continue;
            Vec3 l = L / dist;
            double ndl = glm::dot(s.facing, l);
            if (ndl <= 0.0) continue;
            if (opt_.shadows) {
                ++ctx.counters.shadowRays;
                Ray shadow{above, glm::normalize(light.position - above)};
                const double tmax = glm::length(light.position - above);
                obs.rayBegin(RayKind::Shadow, depth, int(li), shadow, 0.0, tmax);
                const bool blocked = occluded(shadow, tmax, li, ctx, obs);
                if constexpr (Obs::kActive)
                    obs.rayEnd({RayKind::Shadow, Hit{}, Vec3(0.0), Vec3(0.0), blocked});
                if (blocked) continue;
            }
            color += light.color * (m.diffuse * ndl) * m.color;
            if (m.specular > 0.0) {
                Vec3 h = glm::reflect(-l, s.facing);
                double spec = std::max(0.0, glm::dot(h, -dir));
                color += light.color * (m.specular * std::pow(spec, m.shininess));
            }
        }
        if (depth >= opt_.bounces) return color;

        Vec3 refl = glm::reflect(dir, s.facing);
        if (opt_.reflections && m.reflect > 0.0)
            color += m.reflect * radiance(Ray{above, refl}, depth + 1, ctx, obs, nullptr, 0.0,
                                          RayKind::Reflection);
        if (opt_.refractions && m.transmit > 0.0) {
            double eta = s.entering ? 1.0 / m.ior : m.ior;
            Vec3 t = glm::refract(dir, s.facing, eta);
            // Under total internal reflection the transmitted ray is the mirror ray; it is still
            // the refraction term's ray.
            if (glm::dot(t, t) == 0.0)
                color += m.transmit * radiance(Ray{above, refl}, depth + 1, ctx, obs, nullptr, 0.0,
                                               RayKind::Refraction);
            else
                color +=
                    m.transmit * radiance(Ray{s.p - eps * s.facing, glm::normalize(t)}, depth + 1,
                                          ctx, obs, nullptr, 0.0, RayKind::Refraction);
        }
        return color;
    }

  private:
    const Scene& scene_;
    const Accelerator& accel_;
    ShadingOptions opt_;
    double scale_;
};

}  // namespace lancer
