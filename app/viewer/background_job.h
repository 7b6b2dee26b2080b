// One result built on a worker thread at a time, for what would take the UI thread longer than
// a frame to build (the overlays' batches): what is on screen stays until the result is taken.
#pragma once

#include <chrono>
#include <functional>
#include <future>
#include <optional>
#include <thread>

namespace lancer::viewer {

template <class T>
class BackgroundJob {
  public:
    BackgroundJob() = default;
    ~BackgroundJob() {
        if (worker_.joinable()) worker_.join();
    }
    BackgroundJob(const BackgroundJob&) = delete;
    BackgroundJob& operator=(const BackgroundJob&) = delete;

    /// Run `build` on a worker thread; `wake` (if set) is called from it once the result is
    /// set. The result before must have been taken (pending() false).
    void start(std::function<T()> build, std::function<void()> wake = {}) {
        // The worker before has set its result: joined at once.
        if (worker_.joinable()) worker_.join();
        std::promise<T> done;
        job_ = done.get_future();
        worker_ = std::jthread(
            [done = std::move(done), build = std::move(build), wake = std::move(wake)]() mutable {
                try {
                    done.set_value(build());
                } catch (...) {  // rethrown by poll(), as a build on the caller's thread would
                    done.set_exception(std::current_exception());
                }
                if (wake) wake();
            });
    }
    /// A result is being built or waits to be taken.
    bool pending() const { return job_.valid(); }
    /// The result once the worker has set it (its exception rethrown), taken; nothing before.
    std::optional<T> poll() {
        if (!job_.valid() || job_.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
            return std::nullopt;
        return job_.get();
    }

  private:
    std::future<T> job_;
    std::jthread worker_;  ///< last: joined before the rest is destroyed
};

}  // namespace lancer::viewer
