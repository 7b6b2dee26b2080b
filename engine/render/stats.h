// The `--stats` JSON (docs/design.md section 6).
#pragma once

#include <nlohmann/json.hpp>

#include "engine/accel/accelerator.h"
#include "engine/render/renderer.h"

namespace lancer {

nlohmann::json statsJson(const Scene& scene, const Accelerator& accel, const RenderOptions& opt,
                         const RenderStats& rs);

}  // namespace lancer
