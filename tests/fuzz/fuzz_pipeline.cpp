// libFuzzer entry point for the whole pipeline (issue 31, item 8): the input is an OpenSCAD .csg,
// as fuzz_csg reads it; what reads is prepared (the CSG-minimized boxes, the dropped
// primitives), each accelerated scheme (regular, irregular, BVH) is built under a 16 MiB memory
// budget, and an 8x8 image of the reader's camera and 64 random rays through the scene are
// traced by each and by brute force. They must agree ray for ray as the differential tests
// compare them (tests/support/differential.h, compareWithBrute: both miss, or both hit the same
// primitive, or a tie, at the same t within 1e-9 relative): a difference aborts, printing the
// ray. A SceneError is a correct refusal, and so is a build refused over its budget or node
// limit (std::invalid_argument); rays that are not finite are left out (a scene of 1e300 units
// frames its camera at infinity), and ill-conditioned scenes (below) are built and not
// compared; anything else (a crash, a sanitizer report, another exception,
// a hang) is a bug.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "engine/accel/accelerator.h"
#include "engine/scene/openscad_reader.h"
#include "tests/support/differential.h"

namespace {

/// Scenes of more primitives are skipped: brute force tests every primitive per ray, and the
/// reader's own limits (fuzzed by fuzz_csg) admit 200,000 polytopes.
constexpr size_t kMaxPrimitives = 600;
constexpr size_t kBudget = size_t(16) << 20;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lancer;
    Scene scene;
    try {
        scene = readOpenScad(
            SourceText("fuzz.csg", std::string(reinterpret_cast<const char*>(data), size)));
    } catch (const SceneError&) {
        return 0;
    }
    if (scene.prims.size() > kMaxPrimitives) return 0;
    // Some questions ask more than the primitive tests hold, and their answers are rounding:
    // a scene 1e8 times the size of its thinnest primitive (from 1e12 away a cylinder's roots
    // err by about 1e-12 of the distance, a unit beside a unit-sized primitive), and a
    // primitive whose transform's condition number (||M|| ||M^-1||, Frobenius) is over 1e6 (a
    // cone sheared by 9999 or squashed to 1e-13: its roots, found through that map, err by
    // more than its thickness). The hit then falls outside the box that the schemes clip it by
    // (brute force does not clip), or two such surfaces tie within the error. The corpus keeps
    // such inputs (far-spike, far-shear, sheared-cone, sheared-tie, flat-cone, huge-translate);
    // they are read and built, not compared.
    double smallest = kInf, condition = 1.0;
    for (uint32_t p : scene.livePrimitives()) {
        const Box3& b = scene.minBox[p];
        if (!b.isEmpty()) {
            const Vec3 e = b.extent();
            smallest = std::min({smallest, e.x, e.y, e.z});
        }
        const Primitive& prim = scene.prims[p];
        if (!prim.hasXf) continue;
        double m = 0.0, inv = 0.0;
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) {
                m += prim.xf.m[c][r] * prim.xf.m[c][r];
                inv += prim.xf.inv[c][r] * prim.xf.inv[c][r];
            }
        condition = std::max(condition, std::sqrt(m * inv));
    }
    const bool conditioned = !(scene.scale() > 1e8 * smallest) && condition <= 1e6;
    uint64_t seed = 1469598103934665603ull;  // FNV-1a of the input: its rays are its own
    for (size_t i = 0; i < size; ++i) seed = (seed ^ data[i]) * 1099511628211ull;
    std::vector<Ray> rays = test::pixelRays(scene, 8, 8);
    const std::vector<Ray> more = test::randomRays(scene, seed, 64);
    rays.insert(rays.end(), more.begin(), more.end());
    // A scene of 1e300 units frames its camera, and aims its random rays, from infinity: such
    // rays (not finite) are no question to ask a scheme.
    std::erase_if(rays, [](const Ray& r) {
        for (int k = 0; k < 3; ++k)
            if (!std::isfinite(r.o[k]) || !std::isfinite(r.d[k])) return true;
        return false;
    });
    bool differs = false;  // every scheme is compared before an abort, each difference printed
    for (SchemeKind kind : {SchemeKind::Regular, SchemeKind::Irregular, SchemeKind::Bvh}) {
        BuildParams params;
        params.scheme = kind;
        params.memoryBudget = kBudget;
        std::unique_ptr<Accelerator> accel;
        try {
            accel = buildAccelerator(scene, params);
        } catch (const std::invalid_argument&) {
            continue;  // refused by its budget or node limit, naming it
        }
        if (!conditioned) continue;
        const auto bad = test::compareWithBrute(scene, *accel, rays, 0.0, 1e-9, 1);
        if (!bad.empty()) {
            std::fprintf(stderr, "%s differs from brute force:\n%s\n", toString(params).c_str(),
                         bad[0].toString(scene).c_str());
            differs = true;
        }
    }
    if (differs) {
        // The replay driver keeps no crash file of its own, libFuzzer does: the input here.
        if (std::FILE* f = std::fopen("fuzz-pipeline-difference.csg", "wb")) {
            std::fwrite(data, 1, size, f);
            std::fclose(f);
        }
        std::abort();
    }
    return 0;
}
