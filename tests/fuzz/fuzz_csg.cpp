// libFuzzer entry point for the OpenSCAD .csg reader. Any SceneError is a correct refusal;
// anything else (a crash, a sanitizer report, another exception, a hang) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "engine/scene/openscad_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        lancer::readOpenScad(
            lancer::SourceText("fuzz.csg", std::string(reinterpret_cast<const char*>(data), size)));
    } catch (const lancer::SceneError&) {
    }
    return 0;
}
