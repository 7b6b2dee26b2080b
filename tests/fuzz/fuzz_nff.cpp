// libFuzzer entry point for the NFF reader. Any SceneError is a correct refusal; anything else
// (a crash, a sanitizer report, another exception, a hang) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "engine/scene/nff_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        lancer::readNff(
            lancer::SourceText("fuzz.nff", std::string(reinterpret_cast<const char*>(data), size)));
    } catch (const lancer::SceneError&) {
    }
    return 0;
}
