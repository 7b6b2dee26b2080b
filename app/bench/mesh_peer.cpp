#include "app/bench/mesh_peer.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/bench/bench_rows.h"
#include "app/bench/machine.h"
#include "app/bench/scad_export.h"
#include "engine/scene/mesh_file.h"

namespace lancer::bench {

namespace {

namespace fs = std::filesystem;

void addTriangle(Scene& s, const Vec3& a, const Vec3& b, const Vec3& c) {
    Triangle t;
    t.p[0] = a;
    t.p[1] = b;
    t.p[2] = c;
    const Vec3 n = glm::cross(b - a, c - a);
    if (!(glm::length(n) > 0.0)) return;  // a degenerate facet covers no pixel
    t.n[0] = t.n[1] = t.n[2] = glm::normalize(n);
    s.prims.push_back(makePrimitive(t, Transform{}, 0));
}

}  // namespace

std::string MeshPeer::executable() { return peerExecutable("LANCER_OPENSCAD", "openscad"); }

bool MeshPeer::available() { return canRun(executable()); }

std::string MeshPeer::version() {
    if (!available()) return {};
    bool ok = false;
    std::string out = captureCommand(shellQuote(executable()) + " --version 2>&1", ok, true);
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    return out.empty() ? "OpenSCAD" : out;
}

MeshPeer::MeshPeer(const Scene& scene, const std::string& outDir, const std::string& name)
    : scene_(&scene), dir_(outDir + "/openscad"), name_(name) {
    fs::create_directories(dir_);
    std::ostringstream text;
    writeScad(text, scene);
    std::ofstream(dir_ + "/" + name_ + ".scad") << text.str();
}

MeshRun MeshPeer::mesh(int fn, double timeoutSeconds) const {
    MeshRun r;
    r.stl = dir_ + "/" + name_ + "-fn" + std::to_string(fn) + ".stl";
    std::error_code ec;
    fs::remove(r.stl, ec);
    const std::string log = dir_ + "/" + name_ + "-fn" + std::to_string(fn) + ".log";
    // coreutils' timeout stops a CGAL render that would run for minutes (it grows as $fn^2).
    const std::string cmd = "timeout " + std::to_string(int(std::ceil(timeoutSeconds))) + " " +
                            shellQuote(executable()) + " -q -D " +
                            shellQuote("$fn=" + std::to_string(fn)) + " -o " + shellQuote(r.stl) +
                            " " + shellQuote(dir_ + "/" + name_ + ".scad") + " >" +
                            shellQuote(log) + " 2>&1";
    const auto t0 = std::chrono::steady_clock::now();
    bool ok = false;
    captureCommand(cmd, ok);
    r.meshMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (!ok || !fs::exists(r.stl) || fs::file_size(r.stl, ec) == 0) {
        r.failure =
            r.meshMs >= 1000.0 * timeoutSeconds
                ? "OpenSCAD took longer than " + num(timeoutSeconds) + " s"
                : "openscad failed (see openscad/" + fs::path(log).filename().string() + ")";
    }
    return r;
}

Scene readStl(const std::string& path, const Scene& like) {
    const TriangleMesh m = readMeshFile(path);
    Scene s;
    s.name = path;
    s.materials = like.materials;
    s.lights = like.lights;
    s.camera = like.camera;
    s.background = like.background;
    s.width = like.width;
    s.height = like.height;
    for (const auto& t : m.triangles)
        addTriangle(s, m.points[t[0]], m.points[t[1]], m.points[t[2]]);
    if (s.prims.empty()) throw SceneError(path + ": no triangles");
    std::vector<int> leaves;
    leaves.reserve(s.prims.size());
    for (uint32_t i = 0; i < s.prims.size(); ++i) leaves.push_back(s.tree.leaf(i));
    s.tree.root = s.tree.balanced(Op::Union, leaves);
    s.prepare();
    return s;
}

}  // namespace lancer::bench
