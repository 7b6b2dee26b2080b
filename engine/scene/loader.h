// Load a scene from a SCENE argument: a path (.json, .nff, .csg) or builtin:NAME[:SIZE].
#pragma once

#include <string>

#include "engine/scene/scene.h"

namespace lancer {

/// Throws SceneError with the file, line and column of any problem.
Scene loadScene(const std::string& spec);

}  // namespace lancer
