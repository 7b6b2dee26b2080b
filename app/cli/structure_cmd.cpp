#include <chrono>
#include <iostream>

#include "app/cli/commands.h"
#include "engine/accel/structure_dump.h"
#include "engine/render/image.h"
#include "engine/scene/loader.h"

namespace lancer::cli {

int runStructure(const CommonOptions& o, const StructureOptions& s) {
    try {
        Scene scene = loadScene(o.scene);
        auto accel = buildAccelerator(scene, o.build);
        StructureDumpOptions d;
        resolveSize(o, scene, d.width, d.height);
        d.all = s.all;
        StructureView view(scene, *accel);
        try {
            writeFileAtomic(s.output, [&](std::ostream& f) { writeStructureJson(view, d, f); });
        } catch (const std::runtime_error& e) {
            throw std::runtime_error(std::string("-o ") + e.what());
        }
        if (!s.quiet) {
            std::cout << "structure of " << o.scene << " (" << schemeName(o.build.scheme) << ", "
                      << view.regionCount() << " regions"
                      << (dumpIsSummary(view, d) ? ", summarised: --all lists them" : "") << ") -> "
                      << s.output << "\n";
        }
        return 0;
    } catch (const std::exception& e) {
        std::cerr << "error: " << e.what() << "\n";
        return 2;
    }
}

}  // namespace lancer::cli
