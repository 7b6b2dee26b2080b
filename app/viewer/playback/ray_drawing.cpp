#include "app/viewer/playback/ray_drawing.h"

#include <algorithm>
#include <cmath>

#include "app/viewer/gl/transforms.h"
#include "engine/accel/regular/regular_grid.h"

namespace lancer::viewer::playback {

namespace {

glm::vec3 f(const Vec3& v) { return glm::vec3(v); }

/// Colour of a ray by kind (faint when it is not the ray played).
glm::vec3 kindColor(RayKind k) {
    switch (k) {
        case RayKind::Primary:
            return {1.0f, 1.0f, 1.0f};
        case RayKind::Shadow:
            return {0.95f, 0.95f, 0.3f};
        case RayKind::Reflection:
            return {0.4f, 0.7f, 1.0f};
        case RayKind::Refraction:
            return {0.5f, 1.0f, 0.8f};
    }
    return {1.0f, 1.0f, 1.0f};
}

/// A small 3D cross at p.
void cross(gl::Batch& b, const Vec3& p, double r, gl::Rgba8 c) {
    for (int a = 0; a < 3; ++a) {
        Vec3 d(0.0);
        d[a] = r;
        b.line(f(p - d), f(p + d), c);
    }
}

/// The largest t at which the ray is still within reach of the corners (a region or structure
/// reaching infinity is clipped to the structure's bounds, so its corners are finite).
double farT(const TracedRay& r, const std::array<Vec3, 8>& corners) {
    const double dd = glm::dot(r.direction, r.direction);
    double t = 0.0;
    for (const Vec3& c : corners) t = std::max(t, glm::dot(c - r.origin, r.direction) / dd);
    return t;
}

/// Where a ray's drawing ends: its hit, its tmax, or where it leaves the structure.
double endT(const TracedRay& r, const StructureView& view) {
    double t = r.tmax;
    if (r.hit.valid()) t = std::min(t, r.hit.t);
    if (!std::isfinite(t)) t = farT(r, view.structureCorners());
    return std::max(t, r.tmin);
}

}  // namespace

std::optional<std::array<Vec3, 8>> currentCorners(const RayPlayback& play,
                                                  const StructureView& view) {
    const walk::Region* e = play.region();
    if (!e || e->region >= view.regionCount()) return std::nullopt;
    return view.regionCorners(e->region);
}

gl::Batch testedBoxesBatch(const RayPlayback& play, const StructureView& view) {
    gl::Batch b;
    for (const TestedBox& t : testedBoxes(play, view.scene()))
        b.box(f(t.box.lo), f(t.box.hi), gl::rgba8(t.mailbox ? kMailboxColor : kTestedColor));
    return b;
}

gl::Batch rayBatch(const RayPlayback& play, const StructureView& view) {
    gl::Batch b;
    if (play.empty()) return b;
    const Box3 bounds = view.worldBounds();
    const double size = std::max(glm::length(bounds.hi - bounds.lo), 1e-9);
    const double mark = 0.015 * size;

    // The pixel's rays, each from its origin, faint; the one played brighter.
    for (size_t k = 0; k < play.tree().rays.size(); ++k) {
        const TracedRay& r = play.tree().rays[k];
        const bool current = int(k) == play.state().ray;
        const glm::vec3 c = kindColor(r.kind) * (current ? 0.9f : 0.5f);
        b.line(f(r.origin + r.tmin * r.direction), f(r.origin + endT(r, view) * r.direction),
               gl::rgba8(c, current ? 0.9f : 0.5f));
    }

    const TracedRay& ray = play.ray();
    if (ray.hit.valid()) {
        const Vec3 p = ray.origin + ray.hit.t * ray.direction;
        cross(b, p, mark, gl::rgba8(kSegmentColor));
        b.line(f(p), f(p + 6.0 * mark * glm::normalize(ray.normal)), gl::rgba8(kNormalColor));
    }

    const std::optional<std::array<Vec3, 8>> corners = currentCorners(play, view);
    if (!corners) return b;
    std::array<glm::vec3, 8> cf;
    for (int i = 0; i < 8; ++i) cf[size_t(i)] = f((*corners)[size_t(i)]);
    b.box(cf, gl::rgba8(kRegionColor));
    const gl::Batch tested = testedBoxesBatch(play, view);
    b.lines.insert(b.lines.end(), tested.lines.begin(), tested.lines.end());

    // The ray's stretch inside the region.
    const walk::Region& region = *play.region();
    const double t1 = std::isfinite(region.t1) ? region.t1 : farT(ray, *corners);
    b.line(f(ray.origin + region.t0 * ray.direction), f(ray.origin + t1 * ray.direction),
           gl::rgba8(kSegmentColor));

    // The step's scheme events: why the next region is the next.
    const PlaybackState& s = play.state();
    for (size_t i = s.eventBegin; i < s.eventEnd; ++i) {
        const WalkEvent& ev = ray.events[i];
        if (const auto* exit = ev.get<walk::Exit>()) {
            cross(b, exit->point, mark, gl::rgba8(kPointerColor));
            // A projective slab follows no pointer: its next region is the next slab of the
            // pixel's zone, the next step's region.
            const RegionKind kind = view.region(region.region).kind;
            const std::vector<size_t>& steps = play.steps();
            if ((kind == RegionKind::ProjectiveSlab || kind == RegionKind::NearRegion) &&
                s.step >= 0 && size_t(s.step) + 1 < steps.size()) {
                const std::array<Vec3, 8> next = view.regionCorners(
                    ray.events[steps[size_t(s.step) + 1]].as<walk::Region>().region);
                Vec3 centre(0.0);
                for (const Vec3& p : next) centre += p / 8.0;
                b.line(f(exit->point), f(centre), gl::rgba8(kPointerColor, 0.8f));
            }
        } else if (const auto* ptr = ev.get<walk::Pointer>();
                   ptr && ptr->corner >= 0 && ptr->corner < 8) {
            // The corner whose pointer the walk followed, and the step to the next region.
            const Vec3 c = (*corners)[size_t(ptr->corner)];
            cross(b, c, 2.0 * mark, gl::rgba8(kPointerColor));
            if (ptr->to < view.regionCount()) {
                const std::array<Vec3, 8> next = view.regionCorners(ptr->to);
                Vec3 centre(0.0);
                for (const Vec3& p : next) centre += p / 8.0;
                b.line(f(c), f(centre), gl::rgba8(kPointerColor, 0.8f));
            }
        } else if (const auto* push = ev.get<walk::Push>()) {
            cross(b, push->point, mark, gl::rgba8(kCellColor));
        } else if (ev.kind() == WalkEvent::Lookup || ev.kind() == WalkEvent::IndexStep) {
            // The directory cell looked up (or stepped into), as a box of the grid's planes.
            const auto* lookup = ev.get<walk::Lookup>();
            const std::array<uint32_t, 3>& cell =
                lookup ? lookup->cell : ev.as<walk::IndexStep>().cell;
            if (const RegularGrid* g = view.regular()) {
                bool inside = true;
                for (int a = 0; a < 3; ++a) inside = inside && cell[size_t(a)] < g->cells(a);
                if (inside) {
                    const uint32_t hi[3] = {cell[0] + 1, cell[1] + 1, cell[2] + 1};
                    const std::array<Vec3, 8> c = view.gridCorners(cell.data(), hi);
                    std::array<glm::vec3, 8> fc;
                    for (size_t i = 0; i < 8; ++i) fc[i] = f(c[i]);
                    b.box(fc, gl::rgba8(kCellColor));
                }
            }
            if (lookup) cross(b, lookup->point, mark, gl::rgba8(kCellColor));
        }
    }
    return b;
}

glm::mat4 imageClipMatrix(const Camera& camera, int width, int height, const RayPlayback& play,
                          const StructureView& view) {
    const Box3 b = view.worldBounds();
    const double size = std::max(glm::length(b.hi - b.lo), 1e-9);
    const gl::ImageProjector proj(camera, width, height);
    double far = 0.0;
    for (const Vec3& c : view.structureCorners()) far = std::max(far, proj.depth(c));
    for (const TracedRay& r : play.tree().rays) far = std::max(far, proj.depth(r.origin));
    // Lines crossing the eye's plane are clipped by GL at the near plane, close to the eye.
    const bool ortho = camera.projection == Projection::Orthographic;
    return gl::worldToClip(camera, width, height, ortho ? -4.0 * size : 1e-4 * size,
                           far + 4.0 * size);
}

}  // namespace lancer::viewer::playback
