#include "engine/scene/loader.h"

#include "engine/scene/builtin_scenes.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/nff_reader.h"
#include "engine/scene/openscad_reader.h"
#include "engine/scene/source_text.h"

namespace lancer {

namespace {
std::string extension(const std::string& path) {
    size_t dot = path.rfind('.');
    size_t slash = path.rfind('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string e = path.substr(dot);
    for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}
}  // namespace

void checkSceneFile(const std::string& spec) {
    if (parseBuiltinSpec(spec)) return;
    if (std::string why = fileProblem(spec); !why.empty()) throw SceneError(spec + ": " + why);
}

Scene loadScene(const std::string& spec, const ReadOptions& options) {
    if (std::optional<BuiltinSpec> builtin = parseBuiltinSpec(spec)) return makeBuiltin(*builtin);
    checkSceneFile(spec);
    std::string ext = extension(spec);
    if (ext == ".json") return readJsonScene(SourceText::fromFile(spec));
    if (ext == ".nff") return readNff(SourceText::fromFile(spec));
    if (ext == ".csg") return readOpenScadFile(spec, nullptr, options);
    throw SceneError(spec + ": unknown scene format '" + ext +
                     "' (expected .json, .nff, .csg, or builtin:NAME[:SIZE])");
}

void applyCameraFile(Scene& scene, const std::string& path) {
    SourceText src = SourceText::fromFile(path);
    LocatedJson doc(src);
    JsonAt root{doc, doc.root(), ""};
    if (!root.value.is_object())
        root.fail("expected a JSON object with \"from\", \"at\", \"up\", \"fov\"");
    // As in a sidecar, which starts from a perspective camera.
    scene.camera.projection = Projection::Perspective;
    applyCameraJson(root, scene, false);
}

}  // namespace lancer
