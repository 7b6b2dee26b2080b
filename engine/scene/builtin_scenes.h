// Scenes built in code: `builtin:NAME` or `builtin:NAME:SIZE`.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/scene.h"

namespace lancer {

struct BuiltinInfo {
    const char* name;
    int defaultSize, minSize, maxSize;
    const char* description;
};

/// A SCENE argument `builtin:NAME[:SIZE]` taken apart.
struct BuiltinSpec {
    std::string name;         ///< NAME (not checked against the list)
    std::optional<int> size;  ///< SIZE; absent: the scene's default
};

const std::vector<BuiltinInfo>& builtinScenes();
/// The entry of builtinScenes() called `name`; nullptr when there is none.
const BuiltinInfo* findBuiltin(std::string_view name);

/// True when `spec` names a built-in scene ("builtin:...") rather than a file.
bool isBuiltinSpec(std::string_view spec);
/// `builtin:NAME[:SIZE]` taken apart; nullopt for anything else (a file path). Throws SceneError
/// naming `spec` when SIZE is not an integer.
std::optional<BuiltinSpec> parseBuiltinSpec(const std::string& spec);
/// The SCENE argument of a built-in: "builtin:NAME", or "builtin:NAME:SIZE" with a size.
std::string builtinSpec(const std::string& name, std::optional<int> size = std::nullopt);

/// Build a built-in scene. Throws SceneError for an unknown name or a size outside its range.
Scene makeBuiltin(const BuiltinSpec& spec);
/// Build `name` at `size` (negative: its default). Throws SceneError for an unknown name or size.
Scene makeBuiltin(const std::string& name, int size = -1);

}  // namespace lancer
