// Shared test support: random CSG scenes, hard rays, and ray-for-ray comparison of a scheme
// against the brute-force reference.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "engine/accel/accelerator.h"
#include "engine/render/tracer.h"
#include "engine/scene/scene.h"

namespace lancer::test {

struct RandomSceneOptions {
    int primitives = 12;
    bool transforms = true;  ///< rotated, non-uniformly scaled primitives
    bool surfaces = false;   ///< add triangles/polygons/open cones under a top-level union
    Vec3 offset{0.0};        ///< translate everything (far-from-origin scenes)
    double spread = 4.0;     ///< primitives' centres in [-spread, spread]^3
    /// Independent random trees under one union, each over primitives within 1.5 of its centre
    /// (1: one tree over primitives anywhere in the spread).
    int groups = 1;
    /// Tori among the solids (a fifth kind); off, the scenes of a seed stay what they were.
    bool tori = false;
};

/// A random binary CSG tree over random solids (spheres, boxes, cylinders, cones, and with
/// `tori` ring and horn tori), prepared.
Scene randomCsgScene(uint64_t seed, const RandomSceneOptions& opt = {});

/// A random CSG tree over bars (blocks long on one axis), cylinders along an axis and spheres,
/// the whole turned by one rotation of `degrees` (negative: a random angle from 30 to 150): a
/// turned subtree whose frame a scheme can follow (grid_frame.h). Prepared, camera framed.
Scene turnedBars(uint64_t seed, int count = 16, double degrees = -1.0);

/// randomCsgScene with a material that reflects and refracts, a framed camera and the default
/// lights: a pixel's ray tree holds every ray kind (primary, shadow, reflection, refraction).
Scene randomGlassyCsgScene(uint64_t seed, const RandomSceneOptions& opt = {});

/// An orthographic camera on the scene camera's axes, framing the scene's bounds, its eye plane
/// in front of them (so that primary rays see the whole scene).
void makeOrthographic(Scene& scene);

/// Random rays aimed at the scene: through random points of the bounds, from outside and
/// inside, plus axis-parallel rays. Directions are unit length.
std::vector<Ray> randomRays(const Scene& scene, uint64_t seed, int count);

/// Rays aimed exactly at the given points (cell corners, edge midpoints, face centres) from
/// random origins, and axis-parallel rays through them.
std::vector<Ray> raysThroughPoints(const std::vector<Vec3>& points, const Box3& bounds,
                                   uint64_t seed);

struct RayMismatch {
    Ray ray;
    Hit expected, got;
    bool expectedFound = false, gotFound = false;
    std::string toString(const Scene& scene) const;
};

/// Nearest hits of `accel` and of brute force for each ray with t in (tmin, inf). Two hits
/// agree when both miss, or both hit the same primitive at the same t within `relTol`.
/// Returns the mismatches (at most `maxReport`). Both trace with the primitives' tests in
/// `precision`.
std::vector<RayMismatch> compareWithBrute(const Scene& scene, const Accelerator& accel,
                                          const std::vector<Ray>& rays, double tmin = 0.0,
                                          double relTol = 1e-9, size_t maxReport = 20,
                                          Precision precision = Precision::Double);

/// Counters of `accel` tracing every ray with t in (tmin, inf), one context, mailboxes as the
/// structure uses them (compareWithBrute checks the hits, this the walks and the tests).
RayCounters traceCounters(const Scene& scene, const Accelerator& accel,
                          const std::vector<Ray>& rays, double tmin = 0.0);

/// One ray's walk through `accel` with t in (0, inf), as an observer records it (a new ray id).
RecordingObserver recordWalk(const Accelerator& accel, const Ray& ray, TraceContext& ctx);

/// Brute force's nearest hit along `ray` with t in (0, inf); false when it misses.
bool bruteHit(const Scene& scene, const Ray& ray, Hit& hit);

/// Primary rays of every pixel of a w x h image of the scene's camera.
std::vector<Ray> pixelRays(const Scene& scene, int w, int h);

/// Fails the current test, naming `what`, when `accel` and brute force disagree on any ray.
void expectSame(const Scene& scene, const Accelerator& accel, const std::vector<Ray>& rays,
                const std::string& what, double tmin = 0.0);

/// expectSame for every scheme of kSchemeTable at its defaults, on `rays`.
void expectEverySchemeSame(const Scene& scene, const std::vector<Ray>& rays);

/// expectSame on the scene camera's n x n pixel rays, and on secondaryRays(seed) from their hits
/// (t > a hair of the scene's size).
void expectSamePixelsAndSecondaries(const Scene& scene, const Accelerator& accel, int n,
                                    uint64_t seed, const std::string& what);

/// From each brute-force hit of `primary`: a random ray and one toward the first light.
std::vector<Ray> secondaryRays(const Scene& scene, const std::vector<Ray>& primary, uint64_t seed);

}  // namespace lancer::test
