#include "app/bench/scale.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <sstream>

#include "app/bench/embree_peer.h"
#include "app/bench/image_error.h"
#include "app/bench/report.h"
#include "engine/accel/build_guard.h"
#include "engine/render/renderer.h"
#include "engine/scene/builtin_scenes.h"
#include "engine/scene/loader.h"
#include "engine/util/format.h"

namespace lancer::bench {

namespace {

using nlohmann::json;
using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// The warm-up render of the schemes: one pixel in kWarmStride^2 (it starts the thread pool).
constexpr int kWarmStride = 32;
/// Brute force's timed probes (after a one-pixel warm-up): about this many pixels first, then,
/// when that is estimated to be quick, about kProbePixels, so that the render's fixed costs weigh
/// little in the estimate of the whole image and a scene of 600,000 spheres is not probed for
/// minutes.
constexpr double kFirstProbePixels = 64.0, kProbePixels = 1024.0;

/// The steps of a child, in order.
enum ChildStep : int { kLoading, kBuilding, kRendering };
const char* const kStepNames[] = {"loading", "building", "rendering"};

/// What a child has done so far, in a page shared with the parent (mapped before the fork): a
/// child killed at the deadline sends nothing, and this says which step ran long. The parent
/// reads it after the child is reaped.
struct ChildProgress {
    int step = kLoading;                   ///< the step under way
    size_t primitives = 0;                 ///< the scene's, once loaded
    double loadMs = -1.0, buildMs = -1.0;  ///< wall times of the steps ended (-1: not ended)
};

/// The child's progress page (null in the parent, or when it could not be mapped).
ChildProgress* gProgress = nullptr;

/// In the child: `ended` took `ms` of wall time, the next step begins.
void stepEnded(ChildStep ended, double ms) {
    if (!gProgress) return;
    if (ended == kLoading) gProgress->loadMs = ms;
    if (ended == kBuilding) gProgress->buildMs = ms;
    gProgress->step = ended + 1;
}

/// What a child process sent back, and how it ended.
struct ChildResult {
    json figures = json::object();  ///< "error" or "refused" when it did not measure
    std::vector<float> depth;
    std::vector<uint32_t> hitPrim;
    size_t peakRssBytes = 0;
    double cpuS = 0.0;       ///< user and system time of the child, every thread
    bool killed = false;     ///< past the deadline
    ChildProgress progress;  ///< how far it got (for a killed child, the step that ran long)
    std::string crash;       ///< how it ended when it did not exit cleanly
    /// The child measured (no error, refusal, kill or crash).
    bool measured() const {
        return !killed && crash.empty() && !figures.contains("error") &&
               !figures.contains("refused") && !figures.contains("skipped");
    }
};

void writeAll(int fd, const void* data, size_t n) {
    const char* p = static_cast<const char*>(data);
    while (n > 0) {
        ssize_t w = ::write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            return;
        }
        p += w;
        n -= size_t(w);
    }
}

/// Run `work` in a child process limited to `addressSpace` bytes of virtual memory and killed
/// after `killAfterS` seconds; it fills the JSON figures and, optionally, the image whose primary
/// hits are compared. The parent stays single-threaded, so forking without exec is safe.
ChildResult runChild(const std::function<json(Image&)>& work, double killAfterS,
                     size_t addressSpace) {
    ChildResult r;
    int fds[2];
    if (::pipe(fds) != 0) {
        r.crash = std::string("pipe: ") + std::strerror(errno);
        return r;
    }
    void* page = ::mmap(nullptr, sizeof(ChildProgress), PROT_READ | PROT_WRITE,
                        MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    ChildProgress* progress = page == MAP_FAILED ? nullptr : new (page) ChildProgress{};
    struct Unmap {
        ChildProgress* p;
        ~Unmap() {
            if (p) ::munmap(p, sizeof(ChildProgress));
        }
    } unmap{progress};
    std::cout.flush();
    std::cerr.flush();
    const pid_t pid = ::fork();
    if (pid < 0) {
        r.crash = std::string("fork: ") + std::strerror(errno);
        ::close(fds[0]);
        ::close(fds[1]);
        return r;
    }
    if (pid == 0) {
        ::close(fds[0]);
        gProgress = progress;
        rlimit lim{addressSpace, addressSpace};
        ::setrlimit(RLIMIT_AS, &lim);
        json j;
        Image img;
        try {
            j = work(img);
        } catch (const std::bad_alloc&) {
            j = {{"error",
                  "out of memory (address space limited to " + formatBytes(addressSpace) + ")"}};
        } catch (const std::exception& e) {
            j = {{"error", e.what()}};
        }
        const std::string text = j.dump();
        const uint64_t len = text.size(), pixels = img.depth.size();
        writeAll(fds[1], &len, sizeof len);
        writeAll(fds[1], text.data(), text.size());
        writeAll(fds[1], &pixels, sizeof pixels);
        writeAll(fds[1], img.depth.data(), pixels * sizeof(float));
        writeAll(fds[1], img.hitPrim.data(), pixels * sizeof(uint32_t));
        ::close(fds[1]);
        ::_exit(0);
    }
    ::close(fds[1]);
    std::string buf;
    const auto deadline = Clock::now() + std::chrono::duration<double>(killAfterS);
    char chunk[1 << 16];
    for (;;) {
        const double left =
            std::chrono::duration<double, std::milli>(deadline - Clock::now()).count();
        if (left <= 0.0) {
            ::kill(pid, SIGKILL);
            r.killed = true;
            break;
        }
        pollfd p{fds[0], POLLIN, 0};
        const int ready = ::poll(&p, 1, int(std::min(left, 1000.0)) + 1);
        if (ready < 0 && errno != EINTR) break;
        if (ready <= 0) continue;
        const ssize_t n = ::read(fds[0], chunk, sizeof chunk);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        buf.append(chunk, size_t(n));
    }
    ::close(fds[0]);
    int status = 0;
    rusage ru{};
    while (::wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
    }
    r.peakRssBytes = size_t(ru.ru_maxrss) * 1024;  // kilobytes on Linux
    r.cpuS = double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
             1e-6 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    if (progress) r.progress = *progress;
    if (r.killed) return r;
    if (WIFSIGNALED(status)) {
        r.crash = std::string("killed by signal ") + strsignal(WTERMSIG(status));
        return r;
    }
    // Unpack: length, JSON, pixel count, depths, primitives.
    size_t at = 0;
    auto take = [&](void* out, size_t n) {
        if (at + n > buf.size()) return false;
        std::memcpy(out, buf.data() + at, n);
        at += n;
        return true;
    };
    uint64_t len = 0, pixels = 0;
    if (!take(&len, sizeof len) || at + len > buf.size()) {
        r.crash = "exited with status " + std::to_string(WEXITSTATUS(status)) + " without figures";
        return r;
    }
    r.figures = json::parse(buf.substr(at, len));
    at += len;
    if (take(&pixels, sizeof pixels)) {
        r.depth.resize(pixels);
        r.hitPrim.resize(pixels);
        if (!take(r.depth.data(), pixels * sizeof(float)) ||
            !take(r.hitPrim.data(), pixels * sizeof(uint32_t))) {
            r.depth.clear();
            r.hitPrim.clear();
        }
    }
    return r;
}

/// Load the scene, time it, and fill the figures every child reports.
Scene loadTimed(const std::string& spec, const ScaleOptions& opt, RenderOptions& ro, json& j) {
    const auto start = Clock::now();
    Scene scene = loadScene(spec);
    const double loadMs = msSince(start);
    j["load_ms"] = loadMs;
    j["primitives"] = scene.prims.size();
    if (gProgress) gProgress->primitives = scene.prims.size();
    stepEnded(kLoading, loadMs);
    ro.width = opt.sceneSize ? scene.width : opt.width;
    ro.height = opt.sceneSize ? scene.height : opt.height;
    ro.threads = opt.threads;
    ro.shading.bounces = opt.bounces;
    j["width"] = ro.width;
    j["height"] = ro.height;
    return scene;
}

/// CPU time of the process so far, every thread, in milliseconds: on a loaded machine the wall
/// time of a step also counts the time other processes ran, its CPU time does not.
double cpuMs() {
    rusage ru{};
    ::getrusage(RUSAGE_SELF, &ru);
    return 1e3 * double(ru.ru_utime.tv_sec + ru.ru_stime.tv_sec) +
           1e-3 * double(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
}

void putStats(json& j, const RenderStats& s, double cpu) {
    j["render_ms"] = s.renderMs;
    j["render_cpu_ms"] = cpu;
    j["rays"] = s.counters.rays;
    j["prim_tests"] = s.counters.primTests;
    j["region_visits"] = s.counters.regionVisits;
    j["walk_errors"] = s.counters.walkErrors;
}

/// Brute force: the whole image when its estimate (from the probe lattice) is below the limit,
/// else the finest power-of-two lattice whose render is estimated below a quarter of it, or the
/// probe's.
json bruteWork(const std::string& spec, const ScaleOptions& opt, Image& img) {
    json j;
    RenderOptions ro;
    Scene scene = loadTimed(spec, opt, ro, j);
    double cpu = cpuMs();
    auto brute = buildAccelerator(scene, BuildParams{});
    j["build_ms"] = brute->info().buildMs;
    j["build_cpu_ms"] = cpuMs() - cpu;
    stepEnded(kBuilding, brute->info().buildMs);
    j["structure_bytes"] = brute->info().memoryBytes;
    img.resize(ro.width, ro.height);
    const size_t all = size_t(ro.width) * size_t(ro.height);
    render(scene, *brute, ro, img, PassLattice{std::max(ro.width, ro.height), 0});
    double probeCpu = 0.0, estimateMs = 0.0, estimateCpu = 0.0;
    auto probeAt = [&](double pixels, RenderStats& stats) {
        const int stride = std::max(1, int(std::sqrt(double(all) / pixels)));
        const PassLattice probe{stride, 0};
        img = Image(ro.width, ro.height);
        cpu = cpuMs();
        stats = render(scene, *brute, ro, img, probe);
        probeCpu = cpuMs() - cpu;
        const double scale = double(all) / double(probe.pixels(ro.width, ro.height));
        estimateMs = stats.renderMs * scale;
        estimateCpu = probeCpu * scale;
        return stride;
    };
    RenderStats probeStats;
    int probeStride = probeAt(kFirstProbePixels, probeStats);
    if (estimateMs * kProbePixels / double(all) <= 1000.0 * opt.bruteLimitS / 8.0)
        probeStride = probeAt(kProbePixels, probeStats);
    j["estimated_ms"] = estimateMs;
    j["estimated_cpu_ms"] = estimateCpu;
    int stride = probeStride;
    for (int s = 1; s < probeStride; s *= 2)
        if (estimateMs / double(s * s) <= 1000.0 * opt.bruteLimitS / (s == 1 ? 1.0 : 4.0)) {
            stride = s;
            break;
        }
    RenderStats stats = probeStats;
    double statsCpu = probeCpu;
    if (stride != probeStride) {
        img = Image(ro.width, ro.height);
        cpu = cpuMs();
        stats = render(scene, *brute, ro, img, PassLattice{stride, 0});
        statsCpu = cpuMs() - cpu;
    }
    j["stride"] = stride;
    if (stride == 1) j["estimated_cpu_ms"] = statsCpu;  // measured, not estimated
    putStats(j, stats, statsCpu);
    return j;
}

/// A scheme at its defaults: build, a warm-up render of a few pixels, the timed render.
json schemeWork(const std::string& spec, SchemeKind kind, const ScaleOptions& opt, Image& img) {
    json j;
    RenderOptions ro;
    Scene scene = loadTimed(spec, opt, ro, j);
    BuildParams params;
    params.scheme = kind;
    params.memoryBudget = opt.memoryBudget;
    std::unique_ptr<Accelerator> accel;
    double cpu = cpuMs();
    try {
        accel = buildAccelerator(scene, params);
    } catch (const std::invalid_argument& e) {
        j["refused"] = e.what();
        return j;
    }
    const AccelInfo& info = accel->info();
    j["build_ms"] = info.buildMs;
    stepEnded(kBuilding, info.buildMs);
    j["build_cpu_ms"] = cpuMs() - cpu;
    j["structure_bytes"] = info.memoryBytes;
    j["regions"] = info.regions;
    j["params"] = toString(accel->params());
    Image warm(ro.width, ro.height);
    render(scene, *accel, ro, warm, PassLattice{kWarmStride, 0});
    img.resize(ro.width, ro.height);
    cpu = cpuMs();
    const RenderStats stats = render(scene, *accel, ro, img);
    putStats(j, stats, cpuMs() - cpu);
    return j;
}

/// Embree's BVH (the second built in the process) and its render of primary and shadow rays (the
/// second too).
json embreeWork(const std::string& spec, const ScaleOptions& opt, Image& img) {
    json j;
    RenderOptions ro;
    Scene scene = loadTimed(spec, opt, ro, j);
    if (!EmbreePeer::supports(scene)) {
        j["skipped"] = "not a union of primitives";
        return j;
    }
    // The first device of the process starts TBB's threads: its build is not the one timed.
    EmbreePeer(scene).buildMs();
    double cpu = cpuMs();
    EmbreePeer peer(scene);
    j["build_ms"] = peer.buildMs();
    j["build_cpu_ms"] = cpuMs() - cpu;
    stepEnded(kBuilding, peer.buildMs());
    img.resize(ro.width, ro.height);
    peer.render(ro, img);
    img = Image(ro.width, ro.height);
    cpu = cpuMs();
    const RenderStats stats = peer.render(ro, img);
    putStats(j, stats, cpuMs() - cpu);
    return j;
}

std::string fixed(double v, int digits) {
    char s[64];
    std::snprintf(s, sizeof s, "%.*f", digits, v);
    return s;
}

std::string mib(double bytes) { return fixed(bytes / double(1 << 20), 1); }

/// Least-squares slope of log y against log x: y grows as x to that power.
double fittedExponent(const std::vector<std::pair<double, double>>& xy) {
    std::vector<std::pair<double, double>> pts;
    for (auto [x, y] : xy)
        if (x > 0.0 && y > 0.0) pts.push_back({std::log(x), std::log(y)});
    if (pts.size() < 2) return NAN;
    double mx = 0.0, my = 0.0;
    for (auto [x, y] : pts) mx += x, my += y;
    mx /= double(pts.size());
    my /= double(pts.size());
    double sxy = 0.0, sxx = 0.0;
    for (auto [x, y] : pts) sxy += (x - mx) * (y - my), sxx += (x - mx) * (x - mx);
    return sxx > 0.0 ? sxy / sxx : NAN;
}

/// The family of a scene for the fits: the built-in's name, else the file's stem without digits.
std::string family(const std::string& spec) {
    if (auto b = parseBuiltinSpec(spec)) return "builtin:" + b->name;
    std::string stem = std::filesystem::path(spec).stem().string();
    while (!stem.empty() && std::isdigit(static_cast<unsigned char>(stem.back()))) stem.pop_back();
    return stem;
}

}  // namespace

int runScale(const ScaleOptions& opt) {
    namespace fs = std::filesystem;
    if (!createOutDir(opt.outDir)) return 2;
    for (const std::string& spec : opt.scenes) {
        // A misspelt scene is an input error before minutes of measuring, not a failure row.
        if (auto b = parseBuiltinSpec(spec); b ? !findBuiltin(b->name) : !fs::exists(spec)) {
            std::cerr << "error: --scenes: " << spec
                      << (b ? ": unknown built-in scene" : ": no such file") << "\n";
            return 2;
        }
    }
    // A child is killed past twice the time limit, so a slow scheme's time is still measured
    // (and brute force, whose renders are estimated within its own limit, has time to load).
    const double killAfterS = opt.killAfterS > 0.0
                                  ? opt.killAfterS
                                  : std::max(2.0 * opt.timeLimitS, opt.bruteLimitS + 60.0);
    const size_t addressSpace = opt.memoryLimit + (size_t(1) << 30);
    const bool withPeer = opt.peer && opt.bounces == 0 && EmbreePeer::available();

    json rows = json::array();
    std::vector<std::string> failures;
    std::ostringstream table;
    table << "| scene | primitives | scheme | build ms | build CPU ms | structure MiB | peak RSS "
             "MiB | render ms | render CPU ms | tests/ray | visits/ray | speedup | hits differing "
             "| render / Embree | build / Embree |\n"
          << "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const std::string& spec : opt.scenes) {
        auto wanted = [&](const char* scheme) {
            return std::find(opt.schemes.begin(), opt.schemes.end(), scheme) != opt.schemes.end();
        };
        ChildResult bruteR;
        if (wanted("brute"))
            bruteR = runChild([&](Image& img) { return bruteWork(spec, opt, img); }, killAfterS,
                              addressSpace);
        else
            bruteR.figures["skipped"] = "not in --schemes";
        const json& bf = bruteR.figures;
        const bool haveBrute = bruteR.measured() && !bruteR.depth.empty();
        const int width = bf.value("width", 0), height = bf.value("height", 0);
        const int stride = bf.value("stride", 0);
        Image ref;
        if (haveBrute) {
            ref = Image(width, height);
            ref.depth = bruteR.depth;
            ref.hitPrim = bruteR.hitPrim;
        }
        std::map<std::string, ChildResult> results;
        results.emplace("brute", std::move(bruteR));
        for (const SchemeInfo& s : kSchemeTable)
            if (s.kind != SchemeKind::Brute && wanted(s.name))
                results.emplace(
                    s.name, runChild([&](Image& img) { return schemeWork(spec, s.kind, opt, img); },
                                     killAfterS, addressSpace));
        if (withPeer)
            results.emplace("embree",
                            runChild([&](Image& img) { return embreeWork(spec, opt, img); },
                                     killAfterS, addressSpace));
        const ChildResult* embree = results.count("embree") && results.at("embree").measured()
                                        ? &results.at("embree")
                                        : nullptr;
        std::vector<std::string> order = schemeNames();  // the table's order, the peer last
        order.push_back("embree");
        for (const std::string& scheme : order) {
            if (!results.count(scheme)) continue;
            const ChildResult& r = results.at(scheme);
            if (r.figures.contains("skipped")) continue;
            const json& f = r.figures;
            json row = f;
            row["scene"] = spec;
            row["scheme"] = scheme;
            row["peak_rss_bytes"] = r.peakRssBytes;
            row["cpu_s"] = r.cpuS;
            const bool isScheme = scheme != "brute" && scheme != "embree";
            std::string problem;
            if (r.killed) {
                // The steps it ended, then the one under way when the deadline came.
                const ChildProgress& p = r.progress;
                std::string ended;
                if (p.loadMs >= 0.0) ended += "loaded in " + fixed(p.loadMs / 1000.0, 1) + " s";
                if (p.buildMs >= 0.0) ended += ", built in " + fixed(p.buildMs / 1000.0, 1) + " s";
                problem = "killed after " +
                          fixed(killAfterS, killAfterS == std::floor(killAfterS) ? 0 : 1) +
                          " s while " + kStepNames[std::clamp(p.step, 0, 2)] + " (" +
                          (ended.empty() ? "" : ended + "; ") + "CPU time " + fixed(r.cpuS, 1) +
                          " s, peak RSS " + formatBytes(r.peakRssBytes) + ")";
                row["killed_while"] = kStepNames[std::clamp(p.step, 0, 2)];
                if (p.primitives > 0) row["primitives"] = p.primitives;
            } else if (!r.crash.empty())
                problem = r.crash;
            else if (f.contains("error"))
                problem = f["error"].get<std::string>();
            else if (f.contains("refused"))
                problem = "refused: " + f["refused"].get<std::string>();
            ImageError err;
            const bool compared = haveBrute && r.measured() && scheme != "brute" &&
                                  r.depth.size() == ref.depth.size();
            if (compared) {
                Image img(width, height);
                img.depth = r.depth;
                img.hitPrim = r.hitPrim;
                err = compareImages(ref, img, PassLattice{stride, 0});
                row["hits_differing"] = err.hitDiff;
                row["pixels_compared"] = err.compared;
            }
            const double loadMs = f.value("load_ms", 0.0), buildMs = f.value("build_ms", 0.0),
                         renderMs = f.value("render_ms", 0.0);
            const double rays = std::max(1.0, f.value("rays", 0.0));
            std::vector<std::string> over;  // the limits a scheme broke
            if (isScheme && problem.empty()) {
                const double totalS = (loadMs + buildMs + renderMs) / 1000.0;
                row["total_s"] = totalS;
                if (totalS > opt.timeLimitS)
                    over.push_back("load, build and render took " + fixed(totalS, 1) +
                                   " s (CPU time of the process: " + fixed(r.cpuS, 1) + " s)");
                if (compared && err.hitDiff > 0)
                    over.push_back(std::to_string(err.hitDiff) + " of " +
                                   std::to_string(err.compared) + " hits differ from brute force");
            }
            if (isScheme && r.peakRssBytes > opt.memoryLimit)
                over.push_back("peak resident memory " + formatBytes(r.peakRssBytes));
            if (!problem.empty()) over.insert(over.begin(), problem);
            if ((isScheme || scheme == "brute") && !over.empty()) {
                std::string all;
                for (const std::string& o : over) all += (all.empty() ? "" : "; ") + o;
                failures.push_back(spec + " " + scheme + ": " + all);
                row["failure"] = all;
            }
            // The table's row.
            std::string cells[15];
            cells[0] = parseBuiltinSpec(spec) ? spec : fs::path(spec).filename().string();
            cells[1] =
                row.contains("primitives") ? std::to_string(row["primitives"].get<size_t>()) : "";
            cells[2] = scheme;
            const double buildCpu = f.value("build_cpu_ms", 0.0),
                         renderCpu = f.value("render_cpu_ms", 0.0);
            if (!problem.empty()) {
                cells[3] = problem;
            } else {
                const bool sampled = scheme == "brute" && stride > 1;
                const std::string part =
                    " (est., 1/" + std::to_string(stride * stride) + " of the pixels)";
                cells[3] = fixed(buildMs, 0);
                cells[4] = fixed(buildCpu, 0);
                cells[5] = f.contains("structure_bytes") ? mib(f["structure_bytes"]) : "";
                cells[6] = mib(double(r.peakRssBytes));
                // Appended, not "~" + string: GCC 12 at -O3 reads that as an overlapping copy
                // (-Wrestrict, a false positive) once this loop is inlined.
                auto estimate = [](const std::string& v) { return std::string("~").append(v); };
                cells[7] = sampled ? estimate(fixed(f.value("estimated_ms", 0.0), 0)).append(part)
                                   : fixed(renderMs, 0);
                cells[8] = sampled ? estimate(fixed(f.value("estimated_cpu_ms", 0.0), 0))
                                   : fixed(renderCpu, 0);
                if (scheme != "embree") {
                    cells[9] = fixed(f.value("prim_tests", 0.0) / rays, 1);
                    cells[10] = fixed(f.value("region_visits", 0.0) / rays, 1);
                }
                // Ratios of CPU times: the machine's load weighs on them less than on wall times.
                const ChildResult& b = results.at("brute");
                if (scheme != "brute" && b.measured() && renderCpu > 0.0) {
                    const double bruteCpu = b.figures.value("estimated_cpu_ms", 0.0);
                    cells[11] = (stride > 1 ? "~" : "") + fixed(bruteCpu / renderCpu, 1) + "x";
                    row["speedup_cpu"] = bruteCpu / renderCpu;
                }
                if (compared)
                    cells[12] = std::to_string(err.hitDiff) +
                                (stride > 1 ? " of " + std::to_string(err.compared) : "");
                if (isScheme && embree) {
                    const double eb = embree->figures.value("build_cpu_ms", 0.0),
                                 er = embree->figures.value("render_cpu_ms", 0.0);
                    if (er > 0.0) {
                        cells[13] = fixed(renderCpu / er, 2);
                        row["render_over_embree_cpu"] = renderCpu / er;
                    }
                    if (eb > 0.0) {
                        cells[14] = fixed(buildCpu / eb, 1);
                        row["build_over_embree_cpu"] = buildCpu / eb;
                    }
                }
            }
            std::cerr << spec << " " << scheme << ": "
                      << (problem.empty()
                              ? "build " + fixed(buildMs, 0) + " ms, render " + fixed(renderMs, 0) +
                                    " ms, peak " + formatBytes(r.peakRssBytes)
                              : problem)
                      << "\n";
            table << "|";
            for (const std::string& c : cells) table << " " << c << " |";
            table << "\n";
            rows.push_back(row);
        }
    }

    // Growth with the primitive count: per family of scenes and scheme, the fitted exponent.
    std::ostringstream growth;
    growth << "| scenes | scheme | sizes | primitives | build CPU | structure | peak RSS | "
              "render CPU | tests/ray | visits/ray |\n"
           << "|---|---|---:|---|---:|---:|---:|---:|---:|---:|\n";
    std::map<std::pair<std::string, std::string>, std::vector<const json*>> groups;
    std::vector<std::pair<std::string, std::string>> order;
    for (const json& row : rows) {
        if (!row.contains("render_ms")) continue;
        auto key = std::make_pair(family(row["scene"]), row["scheme"].get<std::string>());
        if (!groups.count(key)) order.push_back(key);
        groups[key].push_back(&row);
    }
    for (const auto& key : order) {
        const auto& g = groups[key];
        if (g.size() < 3) continue;
        auto fit = [&](const std::function<double(const json&)>& y) {
            std::vector<std::pair<double, double>> xy;
            for (const json* r : g) xy.push_back({(*r)["primitives"].get<double>(), y(*r)});
            const double e = fittedExponent(xy);
            return std::isnan(e) ? std::string() : fixed(e, 2);
        };
        auto perRay = [](const char* what) {
            return [what](const json& r) {
                return r.value(what, 0.0) / std::max(1.0, r.value("rays", 0.0));
            };
        };
        const bool brute = key.second == "brute", peer = key.second == "embree";
        // Brute force's sampled renders are times of part of the image: its estimate scales.
        auto renderTime = [brute](const json& r) {
            return r.value(brute ? "estimated_cpu_ms" : "render_cpu_ms", 0.0);
        };
        growth << "| " << key.first << " | " << key.second << " | " << g.size() << " | "
               << (*g.front())["primitives"].get<size_t>() << " to "
               << (*g.back())["primitives"].get<size_t>() << " | "
               << (brute ? "" : fit([](const json& r) { return r.value("build_cpu_ms", 0.0); }))
               << " | "
               << (peer ? "" : fit([](const json& r) { return r.value("structure_bytes", 0.0); }))
               << " | " << fit([](const json& r) { return r.value("peak_rss_bytes", 0.0); })
               << " | " << fit(renderTime) << " | " << (peer ? "" : fit(perRay("prim_tests")))
               << " | " << (peer ? "" : fit(perRay("region_visits"))) << " |\n";
    }

    std::ostringstream md;
    md << table.str() << "\nGrowth with the primitive count N (each figure grows as N to the "
       << "power given; a least-squares fit over the sizes measured):\n\n"
       << growth.str() << "\n";
    if (failures.empty()) {
        md << "No failures: every scheme built and rendered every scene within "
           << fixed(opt.timeLimitS, 0) << " s and " << formatBytes(opt.memoryLimit)
           << ", with brute force's hits where compared.\n";
    } else {
        md << "Failures (limits: " << fixed(opt.timeLimitS, 0) << " s, "
           << formatBytes(opt.memoryLimit) << ", brute force's hits):\n\n";
        for (const std::string& f : failures) md << "- " << f << "\n";
    }
    json out = {{"width", opt.sceneSize ? json("scene") : json(opt.width)},
                {"height", opt.sceneSize ? json("scene") : json(opt.height)},
                {"threads", opt.threads},
                {"bounces", opt.bounces},
                {"time_limit_s", opt.timeLimitS},
                {"memory_limit_bytes", opt.memoryLimit},
                {"brute_limit_s", opt.bruteLimitS},
                {"rows", rows},
                {"failures", failures}};
    std::ofstream(opt.outDir + "/scale.md") << md.str();
    std::ofstream(opt.outDir + "/scale.json") << out.dump(2) << "\n";
    std::cout << md.str() << "wrote " << opt.outDir << "/scale.md and scale.json\n";
    return failures.empty() ? 0 : 1;
}

}  // namespace lancer::bench
