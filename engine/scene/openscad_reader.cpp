#include "engine/scene/openscad_reader.h"

#include <cmath>
#include <filesystem>

#include "engine/scene/json_reader.h"
#include "engine/scene/openscad/builder.h"
#include "engine/scene/openscad/lexer.h"
#include "engine/scene/openscad/parser.h"

namespace lancer {

std::string openScadCameraPath(const std::string& csgPath) {
    std::string base = csgPath;
    size_t dot = base.rfind('.');
    size_t slash = base.rfind('/');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) base.resize(dot);
    return base + ".camera.json";
}

Scene readOpenScad(const SourceText& src, const SourceText* camera, OpenScadCounts* countsOut,
                   const ReadOptions& options) {
    std::vector<openscad::Node> top = openscad::parse(src, openscad::tokenize(src));
    Scene scene;
    scene.name = src.path();
    OpenScadCounts counts;
    openscad::buildModel(src, top, scene, counts, options);
    scene.modelError = std::max(counts.twistError, counts.facetError);
    scene.openScadMeshError = counts.openScadTwistMeshError;
    scene.prepare();
    // OpenSCAD's default view ($vpr = [55, 0, 25]): the eye at azimuth -65 degrees from +x,
    // 35 degrees above the ground plane, z up.
    const double el = glm::radians(35.0), az = glm::radians(25.0);
    Vec3 eye(std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el));
    scene.frameCamera(-eye, {0, 0, 1});
    bool sidecarLights = false;
    if (camera) {
        LocatedJson doc(*camera);
        JsonAt root{doc, doc.root(), ""};
        root.object();
        applyCameraJson(root, scene, false);
        sidecarLights = root.has("lights");
    }
    if (!sidecarLights) scene.defaultLights();
    if (countsOut) *countsOut = counts;
    return scene;
}

Scene readOpenScadFile(const std::string& path, OpenScadCounts* counts,
                       const ReadOptions& options) {
    SourceText src = SourceText::fromFile(path);
    std::string cam = openScadCameraPath(path);
    std::error_code ec;
    if (std::filesystem::exists(cam, ec)) {
        SourceText camSrc = SourceText::fromFile(cam);
        return readOpenScad(src, &camSrc, counts, options);
    }
    return readOpenScad(src, nullptr, counts, options);
}

}  // namespace lancer
