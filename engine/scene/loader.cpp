#include "engine/scene/loader.h"

#include "engine/scene/builtin_scenes.h"
#include "engine/scene/json_reader.h"
#include "engine/scene/nff_reader.h"
#include "engine/scene/openscad_reader.h"

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

Scene loadScene(const std::string& spec) {
    if (std::optional<BuiltinSpec> builtin = parseBuiltinSpec(spec)) return makeBuiltin(*builtin);
    std::string ext = extension(spec);
    if (ext == ".json") return readJsonScene(SourceText::fromFile(spec));
    if (ext == ".nff") return readNff(SourceText::fromFile(spec));
    if (ext == ".csg") return readOpenScadFile(spec);
    throw SceneError(spec + ": unknown scene format '" + ext +
                     "' (expected .json, .nff, .csg, or builtin:NAME[:SIZE])");
}

}  // namespace lancer
