// libFuzzer entry point for the STL and OFF readers and the mesh solid they feed: the first byte
// picks the format (even: OFF, odd: STL), the rest is the file; what it reads is made a solid
// (checks and convex pieces) under small limits. A SceneError or MeshError is a correct
// refusal; anything else (a crash, a sanitizer report, another exception, a hang) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "engine/scene/mesh_file.h"
#include "engine/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    if (size == 0) return 0;
    lancer::MeshLimits limits;
    limits.maxTriangles = 2000;
    limits.maxPieces = 20000;
    limits.maxFragments = 200000;
    limits.maxPairTests = 200000;
    try {
        const lancer::SourceText src(
            "fuzz.mesh", std::string(reinterpret_cast<const char*>(data) + 1, size - 1));
        lancer::meshSolid(lancer::readMeshText(src, data[0] % 2 == 0, limits.maxTriangles), limits);
    } catch (const lancer::SceneError&) {
    } catch (const lancer::MeshError&) {
    }
    return 0;
}
