// libFuzzer entry point for the whole pipeline (issue 31, item 8): the input is an OpenSCAD .csg,
// as fuzz_csg reads it; what reads is prepared (the CSG-minimized boxes, the dropped
// primitives), each accelerated scheme (regular, irregular, BVH) is built under a 16 MiB memory
// budget, and an 8x8 image of the reader's camera and 64 random rays through the scene are
// traced by each and by brute force. They must agree ray for ray as the differential tests
// compare them (tests/support/differential.h, compareWithBrute: both miss, or both hit the same
// primitive, or a tie, at the same t within 1e-9 relative): a difference aborts, printing the
// ray. A SceneError is a correct refusal, and so is a build refused over its budget or node
// limit (std::invalid_argument); rays that are not finite are left out (a scene of 1e300 units
// frames its camera at infinity); anything else (a crash, a sanitizer report, another exception,
// a hang) is a bug.
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
        const auto bad = test::compareWithBrute(scene, *accel, rays, 0.0, 1e-9, 1);
        if (!bad.empty()) {
            std::fprintf(stderr, "%s differs from brute force:\n%s\n", toString(params).c_str(),
                         bad[0].toString(scene).c_str());
            // The replay driver keeps no crash file of its own, libFuzzer does: the input here.
            if (std::FILE* f = std::fopen("fuzz-pipeline-difference.csg", "wb")) {
                std::fwrite(data, 1, size, f);
                std::fclose(f);
            }
            std::abort();
        }
    }
    return 0;
}
