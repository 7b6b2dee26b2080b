// Tells ThreadSanitizer what oneTBB's waits already guarantee: ThreadSanitizer does not see
// inside oneTBB (tests/tsan.supp), so a task's writes would look unordered with what the waiting
// thread does after the wait. Each task releases the fence when it ends (by an exception too), and
// the thread that waited acquires it: one atomic add per task.
#pragma once

#include <atomic>
#include <cstddef>

namespace lancer {

class TaskFence {
  public:
    /// Held by a task for its whole run: its end releases the fence.
    class Done {
      public:
        explicit Done(TaskFence& f) : f_(f) {}
        Done(const Done&) = delete;
        Done& operator=(const Done&) = delete;
        ~Done() { f_.count_.fetch_add(1, std::memory_order_release); }

      private:
        TaskFence& f_;
    };
    /// After the wait: every task's writes happen before what follows.
    void acquire() const { (void)count_.load(std::memory_order_acquire); }

  private:
    std::atomic<size_t> count_{0};
};

}  // namespace lancer
