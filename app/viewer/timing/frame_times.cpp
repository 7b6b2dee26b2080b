#include "app/viewer/timing/frame_times.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string_view>

namespace lancer::viewer {

double threadCpuMs() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

double percentile(std::vector<double> sorted, double p) {
    if (sorted.empty()) return 0.0;
    std::sort(sorted.begin(), sorted.end());
    // Nearest rank: the ceil(p/100 * n)-th smallest (1-based), at least the first.
    const double rank = std::ceil(std::clamp(p, 0.0, 100.0) / 100.0 * double(sorted.size()));
    const size_t i = size_t(std::max(rank, 1.0)) - 1;
    return sorted[std::min(i, sorted.size() - 1)];
}

size_t FrameTimes::over(double ms) const {
    return size_t(std::count_if(wall_.begin(), wall_.end(), [ms](double t) { return t > ms; }));
}

std::string FrameTimes::summary(const std::string& name) const {
    if (wall_.empty()) return name + ": no frames";
    char line[200];
    std::snprintf(line, sizeof line,
                  "%zu frames, p50 %.1f ms, p95 %.1f ms, max %.1f ms, %zu over %.0f ms, CPU p50 "
                  "%.1f ms, p95 %.1f ms, max %.1f ms",
                  wall_.size(), percentile(50), percentile(95), percentile(100),
                  over(kFrameBudgetMs), kFrameBudgetMs, cpuPercentile(50), cpuPercentile(95),
                  cpuPercentile(100));
    return name + ": " + line;
}

double FramePhases::totalMs() const {
    double sum = 0.0;
    for (const Phase& p : phases_) sum += p.ms;
    return sum;
}

std::string FramePhases::summary() const {
    std::vector<Phase> merged;
    for (const Phase& p : phases_) {
        auto same = std::find_if(merged.begin(), merged.end(), [&](const Phase& m) {
            return std::string_view(m.name) == p.name;
        });
        if (same != merged.end())
            same->ms += p.ms;
        else
            merged.push_back(p);
    }
    std::string out;
    char ms[32];
    for (const Phase& p : merged) {
        std::snprintf(ms, sizeof ms, " %.1f", p.ms);
        out += (out.empty() ? "" : ", ") + std::string(p.name) + ms;
    }
    return out;
}

}  // namespace lancer::viewer
