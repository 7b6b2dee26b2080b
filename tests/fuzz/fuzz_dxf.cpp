// libFuzzer entry point for the DXF reader (import() of a .dxf, engine/scene/openscad/dxf.cpp)
// and the 2D cut its outlines feed: the input is the drawing, read for every layer with
// OpenSCAD's default $fa and $fs, its closed outlines cut into convex pieces as polygon() cuts
// them (skipped past 2,000 edges, where the reader's callers refuse at 20,000). A SceneError is
// a correct refusal; anything else (a crash, a sanitizer report, another exception, a hang) is
// a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "engine/scene/openscad/dxf.h"
#include "engine/scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using namespace lancer;
    try {
        const SourceText src("fuzz.dxf", std::string(reinterpret_cast<const char*>(data), size));
        const openscad::DxfOutlines d =
            openscad::readDxfText(src, "", openscad::Vec2(0.0), 1.0, openscad::Fragments{});
        size_t edges = 0;
        for (const auto& l : d.loops) edges += l.size();
        if (edges <= 2000) openscad::convexPieces(d.loops);
    } catch (const SceneError&) {
    }
    return 0;
}
