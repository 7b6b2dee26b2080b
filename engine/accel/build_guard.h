// A build's limits while it runs: its memory budget, its cancellation and its progress report.
// The builders estimate their size as they go and ask the guard; a caller (the viewer, the
// command line) controls a running build through BuildControl.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <stop_token>
#include <string>

namespace lancer {

class Accelerator;  // accelerator.h

/// A build ended by a stop request (a newer build superseded it). Not an input error.
class BuildCancelled : public std::runtime_error {
  public:
    BuildCancelled() : std::runtime_error("build cancelled") {}
};

/// The machine's physical memory in bytes (0 when the system does not say).
size_t physicalMemoryBytes();
/// The budget of a build that names none: an eighth of physical memory (at least 256 MiB, and
/// 1 GiB when the system does not say), so a build never takes the machine's memory.
size_t defaultMemoryBudget();
/// Parse a --memory-budget value: bytes, or a number with K, M, G or T (powers of 1024), an
/// optional "iB"/"B" after it. Throws std::invalid_argument naming the option.
size_t parseMemoryBudget(const std::string& text);

/// What a long build reports, about once a second after its first second.
struct BuildProgress {
    const char* stage;  ///< what is being built ("regular BSP", "screen BSP", ...)
    double seconds;     ///< since the build started
    size_t bytes;       ///< estimated size so far
    size_t budget;      ///< the memory budget
    size_t items;       ///< nodes, zones or regions made so far (the stage says which)
};

/// What a caller controls in a running build, besides its parameters.
struct BuildControl {
    std::stop_token stop;  ///< a stop request ends the build with BuildCancelled
    std::function<void(const BuildProgress&)> progress;  ///< long builds report here
    /// A structure built over a copy of the same prepared scene (Scene::preparedId) for another
    /// camera, or null. The build takes from it what does not depend on the camera and was
    /// built with the same parameters (the light buffer; the irregular scheme's lights'
    /// structures) instead of building it again: the viewer's rebuild after a camera move.
    /// The caller keeps it alive during the build; the new structure does not refer to it.
    const Accelerator* previous = nullptr;
};

/// Checks a running build against its control: builders call poll() in their loops (an atomic
/// load, and a clock read every 256 calls), and compare their estimated size with budget().
/// Builders estimate their size by their arrays' capacities and keep it within a third of what
/// they may take: an array that doubles holds its old and new storage at once, so the peak of
/// the next growth stays within the whole (fits()).
class BuildGuard {
  public:
    /// `budget` 0: defaultMemoryBudget(). `held`: bytes of it that something built beside the
    /// structure holds (the light buffer); the structure may take the rest.
    explicit BuildGuard(size_t budget = 0, BuildControl control = {}, size_t held = 0);

    /// The bytes the structure may take: the whole budget but what is held beside it.
    size_t budget() const { return budget_; }
    /// The whole budget (--memory-budget, or the default), as messages name it.
    size_t given() const { return given_; }
    /// The budget as messages name it: "4.0 MiB", and what is held beside the structure.
    std::string describe() const;
    /// Arrays of `bytes` (by capacity) can still grow once within `limit` (default: the budget).
    static bool fits(size_t bytes, size_t limit) { return bytes <= limit / 3; }
    bool fits(size_t bytes) const { return fits(bytes, budget_); }
    /// Throws BuildCancelled once a stop is requested; reports progress when the build is long.
    /// Threads of one build may call it at once: one of them reports.
    void poll(const char* stage, size_t bytes, size_t items) {
        if (control_.stop.stop_requested()) throw BuildCancelled();
        if (control_.progress && (calls_.fetch_add(1, std::memory_order_relaxed) & 255) == 255)
            report(stage, bytes, items);
    }
    /// Throws BuildCancelled once a stop is requested.
    void poll() const {
        if (control_.stop.stop_requested()) throw BuildCancelled();
    }
    const BuildControl& control() const { return control_; }

  private:
    void report(const char* stage, size_t bytes, size_t items);

    size_t given_, budget_;
    BuildControl control_;
    std::chrono::steady_clock::time_point start_, last_;  ///< last_: under reporting_
    std::atomic<unsigned> calls_{0};
    std::mutex reporting_;  ///< one report at a time; a thread finding it taken skips its own
};

}  // namespace lancer
