#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <thread>

#include "app/cli/commands.h"
#include "engine/render/stats.h"
#include "engine/scene/loader.h"

namespace lancer::cli {

namespace {

/// A progress bar on stderr, shown only on a terminal and only after the first second.
class ProgressBar {
  public:
    ProgressBar(std::atomic<size_t>& done, size_t total) : done_(done), total_(total) {
        if (!isatty(STDERR_FILENO) || total == 0) return;
        thread_ = std::thread([this] { loop(); });
    }
    ~ProgressBar() {
        stop_ = true;
        if (thread_.joinable()) thread_.join();
    }

  private:
    void loop() {
        auto start = std::chrono::steady_clock::now();
        bool shown = false;
        while (!stop_) {
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
            double secs =
                std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (secs < 1.0) continue;
            double f = double(done_.load()) / double(total_);
            int bar = int(f * 40.0);
            std::fprintf(stderr, "\r[%-40s] %5.1f%% %6.1fs", std::string(size_t(bar), '#').c_str(),
                         100.0 * f, secs);
            shown = true;
        }
        if (shown) std::fprintf(stderr, "\r%-70s\r", "");
    }
    std::atomic<size_t>& done_;
    size_t total_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

}  // namespace

int runRender(const CommonOptions& o, const std::string& outPath, bool quiet) {
    if (!imageFormatOf(outPath)) {  // refused before the render, not after
        std::cerr << "error: " << outPath << ": unknown image format (use .png, .jpg or .jpeg)\n";
        return 2;
    }
    try {
        Scene scene = loadSceneWithCamera(o);
        auto accel = buildAccelerator(scene, o.knobs.build, buildProgressOnStderr());
        RenderOptions ro = renderOptions(o, scene);
        Image img(ro.width, ro.height);
        std::atomic<size_t> done{0};
        RenderStats rs;
        {
            ProgressBar bar(done, size_t(ro.width) * size_t(ro.height));
            rs = render(scene, *accel, ro, img, {}, nullptr, &done);
        }
        writeImage(outPath, img);
        if (!o.knobs.depthPath.empty()) writeDepthPfm(o.knobs.depthPath, img);
        if (!o.knobs.statsPath.empty())
            writeFileAtomic(o.knobs.statsPath, statsJson(scene, *accel, ro, rs).dump(2) + "\n");
        if (!quiet) {
            std::cout << "rendered " << o.scene << " (" << ro.width << "x" << ro.height << ", "
                      << schemeName(o.knobs.build.scheme) << ", " << rs.threads << " threads) in "
                      << int(rs.renderMs) << " ms -> " << outPath << "\n";
        }
        if (rs.counters.walkErrors)
            std::cerr << "warning: " << rs.counters.walkErrors
                      << " ray walks could not advance and were ended\n";
        return 0;
    } catch (const SceneError& e) {
        std::cerr << "error: " << e.what() << "\n";
    } catch (const std::invalid_argument& e) {
        std::cerr << "error: " << e.what() << "\n";
    } catch (const std::runtime_error& e) {
        std::cerr << "error: " << e.what() << "\n";
    }
    return 2;
}

}  // namespace lancer::cli
