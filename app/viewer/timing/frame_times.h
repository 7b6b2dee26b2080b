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

/// Where one frame's UI CPU time went: the frame is cut at named marks, each phase's CPU time
/// being the time from the mark before it. --log-timings prints it for the frames over budget,
/// so a slow frame says which step made it slow.
class FramePhases {
  public:
    /// Start a frame: the phases are cleared, the clock read.
    void begin() { beginAt(threadCpuMs()); }
    /// Start a frame at CPU time `nowMs` (threadCpuMs(); tests give their own).
    void beginAt(double nowMs) {
        phases_.clear();
        last_ = nowMs;
    }
    /// The phase `name` (a string literal) ends now.
    void mark(const char* name) { markAt(name, threadCpuMs()); }
    /// The phase `name` ends at CPU time `nowMs` (threadCpuMs(); tests give their own).
    void markAt(const char* name, double nowMs) {
        phases_.push_back({name, nowMs - last_});
        last_ = nowMs;
    }
    /// The sum of the phases, in ms.
    double totalMs() const;
    /// "A 1.2, B 30.4, C 0.1" (ms, in the order marked; a phase marked twice is summed at its
    /// first place).
    std::string summary() const;

  private:
    struct Phase {
        const char* name;
        double ms;
    };
    std::vector<Phase> phases_;
    double last_ = 0.0;
};

}  // namespace lancer::viewer
