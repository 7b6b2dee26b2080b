// Tells ThreadSanitizer what oneTBB's task hand-offs already guarantee. ThreadSanitizer does not
// see inside oneTBB (tests/tsan.supp), so it finds no order between what a thread wrote before it
// started tasks and the tasks' reads of it, nor between the tasks' writes and what that thread
// does after the wait: each such access would be a race report.
//
// A task body wrapped by TaskFence::task() states both orders where ThreadSanitizer sees them:
// the wrapper releases what its maker wrote, and so does each copy oneTBB makes of it (after
// acquiring what its source released), so a call acquires everything written before the tasks
// started; it finds that on its own object, before it reads anything oneTBB handed over. Each
// call releases its writes into the fence when it ends (by an exception too), and the thread
// that waited acquires them. One atomic load and one atomic add per call.
#pragma once

#include <atomic>
#include <cstddef>
#include <utility>

// A wrapped body's call is a frame of its own under ThreadSanitizer: inlined into oneTBB's code,
// a race in the body would be reported in oneTBB's frame, which tests/tsan.supp suppresses.
#if defined(__SANITIZE_THREAD__)
#define LANCER_TASK_FRAME __attribute__((noinline))
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define LANCER_TASK_FRAME __attribute__((noinline))
#endif
#endif
#ifndef LANCER_TASK_FRAME
#define LANCER_TASK_FRAME
#endif

namespace lancer {

class TaskFence {
  public:
    TaskFence() = default;
    /// Ends after the wait (an exception's too): the tasks' writes happen before what follows.
    ~TaskFence() { acquire(); }
    TaskFence(const TaskFence&) = delete;
    TaskFence& operator=(const TaskFence&) = delete;

    /// A task body of this fence, to hand to oneTBB (parallel_for, task_group::run): made when
    /// the tasks' inputs are written.
    template <class Body>
    class Task {
      public:
        Task(const Body& body, const TaskFence& fence) : body_(body), fence_(&fence) {
            start_.store(true, std::memory_order_release);
        }
        /// oneTBB's copy: the source's acquired, then released again from here.
        Task(const Task& o)
            : body_((o.start_.load(std::memory_order_acquire), o.body_)), fence_(o.fence_) {
            start_.store(true, std::memory_order_release);
        }
        Task& operator=(const Task&) = delete;

        template <class... Args>
        LANCER_TASK_FRAME void operator()(Args&&... args) const {
            (void)start_.load(std::memory_order_acquire);
            const Done done{*fence_};
            body_(std::forward<Args>(args)...);
        }

      private:
        struct Done {
            const TaskFence& f;
            ~Done() { f.done_.fetch_add(1, std::memory_order_release); }
        };
        Body body_;
        const TaskFence* fence_;
        std::atomic<bool> start_{false};  // set last: its release covers the members above
    };

    /// `body` as a task body of this fence.
    template <class Body>
    Task<Body> task(const Body& body) const {
        return Task<Body>(body, *this);
    }
    /// After the wait: every call's writes happen before what follows.
    void acquire() const { (void)done_.load(std::memory_order_acquire); }

  private:
    mutable std::atomic<size_t> done_{0};
};

}  // namespace lancer
