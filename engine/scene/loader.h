// Load a scene from a SCENE argument: a path (.json, .nff, .csg) or builtin:NAME[:SIZE].
#pragma once

#include <string>

#include "engine/scene/scene.h"

namespace lancer {

/// Throws SceneError with the file, line and column of any problem. `options` reach the readers
/// that read them (.csg: --facets).
Scene loadScene(const std::string& spec, const ReadOptions& options = {});
/// Throws SceneError naming `spec` when it is a path that is missing ("no such file") or a
/// directory; a built-in name passes (its own errors come when it is made).
void checkSceneFile(const std::string& spec);
/// Replace the camera of a loaded scene with the one in `path`, a JSON object with the
/// .camera.json sidecar's keys (docs/design.md section 6; what the viewer's Copy JSON writes): keys
/// not given keep the scene's values, except a missing "projection", which means perspective;
/// "width" and "height" set the scene's own size, "lights" and "background" replace its own.
/// Throws SceneError naming the file, line and column.
void applyCameraFile(Scene& scene, const std::string& path);

}  // namespace lancer
