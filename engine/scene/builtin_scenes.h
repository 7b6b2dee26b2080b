// Scenes built in code: `builtin:NAME` or `builtin:NAME:SIZE`.
#pragma once

#include <string>
#include <vector>

#include "engine/scene/scene.h"

namespace lancer {

struct BuiltinInfo {
    const char* name;
    int defaultSize, minSize, maxSize;
    const char* description;
};

const std::vector<BuiltinInfo>& builtinScenes();
/// Build `name` at `size` (-1: its default). Throws SceneError for an unknown name or size.
Scene makeBuiltin(const std::string& name, int size = -1);

}  // namespace lancer
