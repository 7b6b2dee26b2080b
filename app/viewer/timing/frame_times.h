// --log-timings' frame-time summary: the UI thread's work per frame (a frame's start to its
// swap), kept for the whole run and told as percentiles at its end, apart for the frames in
// which the camera turned and those in which it stood still. Each frame is kept twice: its
// wall time (what the user waits) and the UI thread's CPU time in it (what the frame costs,
// apart from what other processes take from it on a loaded machine).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace lancer::viewer {

/// The frame budget the viewer is held to (30 frames a second).
inline constexpr double kFrameBudgetMs = 33.0;

/// The calling thread's CPU time so far, in milliseconds (CLOCK_THREAD_CPUTIME_ID).
double threadCpuMs();

/// The p-th percentile of `ms` by nearest rank (p in [0, 100]; 0 for none): the smallest
/// value that at least p percent of them do not exceed.
double percentile(std::vector<double> ms, double p);

/// Frame times in milliseconds, in the order they came.
class FrameTimes {
  public:
    /// One frame: its wall time and the UI thread's CPU time in it.
    void add(double wallMs, double cpuMs) {
        wall_.push_back(wallMs);
        cpu_.push_back(cpuMs);
    }
    /// How many frames were added.
    size_t count() const { return wall_.size(); }
    /// The p-th percentile of the frames' wall times (lancer::viewer::percentile).
    double percentile(double p) const { return viewer::percentile(wall_, p); }
    /// The p-th percentile of the UI thread's CPU time per frame.
    double cpuPercentile(double p) const { return viewer::percentile(cpu_, p); }
    /// How many frames took longer than `ms` of wall time.
    size_t over(double ms) const;
    /// "NAME: N frames, p50 A ms, p95 B ms, max C ms, K over 33 ms, CPU p50 a ms, p95 b ms,
    /// max c ms" ("NAME: no frames").
    std::string summary(const std::string& name) const;

  private:
    std::vector<double> wall_, cpu_;
};

}  // namespace lancer::viewer
