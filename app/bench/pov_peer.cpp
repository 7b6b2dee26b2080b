#include "app/bench/pov_peer.h"

#include <stb_image.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/bench/machine.h"
#include "app/bench/pov_export.h"

namespace lancer::bench {

namespace {

namespace fs = std::filesystem;

/// The seconds in brackets on the line of `log` that starts (after blanks) with `key`:
/// "  Trace Time:       0 hours  0 minutes  0 seconds (0.384 seconds)" -> 0.384; -1 if none.
double secondsAfter(const std::string& log, const std::string& key) {
    std::istringstream in(log);
    std::string line;
    while (std::getline(in, line)) {
        const size_t k = line.find(key);
        if (k == std::string::npos || line.find_first_not_of(' ') != k) continue;
        const size_t open = line.find('(', k);
        if (open == std::string::npos) return -1.0;
        return std::atof(line.c_str() + open + 1);
    }
    return -1.0;
}

/// The first number after `key` on its line of `log` ("Rays:   20460   Saved: ..."); 0 if none.
uint64_t countAfter(const std::string& log, const std::string& key) {
    const size_t k = log.find(key);
    if (k == std::string::npos) return 0;
    return std::strtoull(log.c_str() + k + key.size(), nullptr, 10);
}

/// The last lines of a log that say what went wrong.
std::string tail(const std::string& log) {
    std::string t = log.size() > 300 ? log.substr(log.size() - 300) : log;
    for (char& c : t)
        if (c == '\n' || c == '\r') c = ' ';
    return t;
}

}  // namespace

std::string PovPeer::executable() { return peerExecutable("LANCER_POVRAY", "povray"); }

bool PovPeer::available() { return canRun(executable()); }

std::string PovPeer::version() {
    if (!available()) return {};
    bool ok = false;
    // povray prints its version on stderr, after a complaint about a missing user ini file.
    const std::string out = captureCommand(shellQuote(executable()) + " --version 2>&1", ok, true);
    std::istringstream in(out);
    std::string line;
    while (std::getline(in, line))
        if (line.compare(0, 7, "POV-Ray") == 0) return line;
    return "POV-Ray";
}

PovPeer::PovPeer(const Scene& scene, const RenderOptions& opt, const std::string& outDir,
                 const std::string& name)
    : dir_(outDir + "/povray"),
      name_(name),
      width_(opt.width),
      height_(opt.height),
      threads_(effectiveThreads(opt.threads)) {
    fs::create_directories(dir_);
    const Camera& cam = opt.camera ? *opt.camera : scene.camera;
    depthRange_ = depthRangeOf(scene, cam);
    PovOptions po;
    po.bounces = opt.shading.bounces;
    {
        std::ofstream f(dir_ + "/" + name_ + ".pov");
        writePov(f, scene, cam, po);
    }
    po.depth = true;
    po.depthRange = depthRange_;
    std::ofstream f(dir_ + "/" + name_ + ".depth.pov");
    writePov(f, scene, cam, po);
}

PovRun PovPeer::render(const Image* ref) const {
    PovRun r;
    // POV-Ray reads and writes files under its working directory only (Debian's povray.conf).
    auto run = [&](const std::string& base, const char* format, std::string& log) {
        const std::string cmd = "cd " + shellQuote(dir_) + " && " + shellQuote(executable()) + " " +
                                shellQuote("+I" + base + ".pov") + " " +
                                shellQuote("+O" + base + ".png") + " +W" + std::to_string(width_) +
                                " +H" + std::to_string(height_) + " +WT" +
                                std::to_string(threads_) + " -D -P " + format +
                                " File_Gamma=1.0 >" + shellQuote(base + ".log") + " 2>&1";
        const auto start = std::chrono::steady_clock::now();
        bool ok = false;
        captureCommand(cmd, ok, true);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        log = readWholeFile(dir_ + "/" + base + ".log");
        if (!ok || log.find("POV-Ray finished") == std::string::npos)
            r.failure = "povray on povray/" + base + ".pov: " + tail(log);
        return ms;
    };
    std::string log;
    r.wallMs = run(name_, "+FN8", log);
    if (!r.failure.empty()) return r;
    const double parse = secondsAfter(log, "Parse Time:"),
                 bounding = secondsAfter(log, "Bounding Time:"),
                 trace = secondsAfter(log, "Trace Time:");
    if (trace < 0.0) {
        r.failure = "no trace time in povray/" + name_ + ".log";
        return r;
    }
    r.parseMs = 1000.0 * (std::max(0.0, parse) + std::max(0.0, bounding));
    r.traceMs = 1000.0 * trace;
    r.rays = countAfter(log, "Rays:") + countAfter(log, "Shadow Ray Tests:");
    if (!ref) return r;
    std::string depthLog;
    run(name_ + ".depth", "+FN16", depthLog);
    if (!r.failure.empty()) return r;
    std::string why;
    if (!comparePovDepth(dir_ + "/" + name_ + ".depth.png", depthRange_, *ref, r.error, why)) {
        r.failure = why;
        return r;
    }
    r.compared = true;
    char note[160];
    std::snprintf(note, sizeof note, "silhouette and distance to %.2g, from its depth image",
                  depthRange_ / 65535.0);
    r.errorNote = note;
    return r;
}

bool comparePovDepth(const std::string& png, double range, const Image& ref, ImageError& e,
                     std::string& why) {
    int w = 0, h = 0, n = 0;
    stbi_us* px = stbi_load_16(png.c_str(), &w, &h, &n, 3);
    if (!px) {
        why = png + ": " + (stbi_failure_reason() ? stbi_failure_reason() : "cannot be read");
        return false;
    }
    if (w != ref.width || h != ref.height) {
        stbi_image_free(px);
        why = png + ": " + std::to_string(w) + "x" + std::to_string(h) + ", not " +
              std::to_string(ref.width) + "x" + std::to_string(ref.height);
        return false;
    }
    e = ImageError{};
    const double step = range / 65535.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const size_t i = ref.index(x, y);
            const unsigned v = px[3 * i];
            const bool hit = v > 0, refHit = std::isfinite(ref.depth[i]);
            ++e.compared;
            if (hit != refHit) {
                ++e.hitDiff;
                continue;
            }
            if (!hit) continue;
            const double d = (1.0 - double(v) / 65535.0) * range;
            const double dd = std::abs(d - double(ref.depth[i]));
            e.maxDepthDiff = std::max(e.maxDepthDiff, dd);
            if (dd > step + 1e-6 * d) ++e.hitDiff;
        }
    stbi_image_free(px);
    return true;
}

}  // namespace lancer::bench
