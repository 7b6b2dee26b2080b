// `lancer export SCENE --pov FILE.pov --scad FILE.scad`: the scene for POV-Ray 3.7, with the same
// camera (app/bench/pov_export.h), and as an OpenSCAD model (app/bench/scad_export.h).
#include <iostream>

#include "app/bench/pov_export.h"
#include "app/bench/scad_export.h"
#include "app/cli/commands.h"
#include "engine/render/image.h"

namespace lancer::cli {

int runExport(const CommonOptions& o, const ExportOptions& e) {
    if (e.pov.empty() && e.scad.empty()) {
        std::cerr << "error: export: give --pov FILE.pov, --scad FILE.scad, or both\n";
        return 2;
    }
    try {
        Scene scene = loadSceneWithCamera(o);
        const RenderOptions ro = renderOptions(o, scene);
        if (!e.pov.empty()) {
            bench::PovOptions po;
            po.bounces = ro.shading.bounces;
            po.depth = e.depth;
            writeFileAtomic(e.pov, [&](std::ostream& out) {
                bench::writePov(out, scene, ro.camera ? *ro.camera : scene.camera, po);
            });
            if (!e.quiet)
                std::cout << "wrote " << e.pov << "; render it as Lancer would with:\n  povray +I"
                          << e.pov << " +W" << ro.width << " +H" << ro.height << " -D"
                          << (e.depth ? " +FN16 File_Gamma=1.0" : " +FN8 File_Gamma=1.0") << "\n";
        }
        if (!e.scad.empty()) {
            writeFileAtomic(e.scad, [&](std::ostream& out) { bench::writeScad(out, scene, e.fn); });
            if (!e.quiet)
                std::cout << "wrote " << e.scad
                          << "; mesh it as OpenSCAD would with:\n  openscad -o "
                          << "mesh.stl " << e.scad << "\n";
        }
        return 0;
    } catch (const SceneError& ex) {
        std::cerr << "error: " << ex.what() << "\n";
    } catch (const std::invalid_argument& ex) {
        std::cerr << "error: " << o.scene << ": " << ex.what() << "\n";
    } catch (const std::runtime_error& ex) {
        std::cerr << "error: " << ex.what() << "\n";
    }
    return 2;
}

}  // namespace lancer::cli
