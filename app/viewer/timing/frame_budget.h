// One budget for a whole frame, shared by the steps that may leave work for the next frame:
// the overlays' batches copied to GL and their layer drawn in parts, the inspector's picture
// in parts, the panel layer's redraws. Each of these steps, each within its own share, once
// fell together with the others in one frame (34-51 ms of UI CPU on balls4's slabs,
// 2026-12-06). The steps draw from the budget in the frame's order, which is their priority:
// a new view's image parts (taken in any case), then the layer, then the inspector, then the
// panels; a step stops its optional work once the frame's budget, less what it leaves to the
// steps after it, is spent, and goes on in the next frame.
#pragma once

#include <functional>

namespace lancer::viewer {

class FrameBudget {
  public:
    /// A clock in milliseconds (threadCpuMs() by default: the UI thread's CPU time, which the
    /// viewer is held to; a test gives its own).
    using Clock = std::function<double()>;

    /// A budget of `ms` per frame on `clock`.
    explicit FrameBudget(double ms, Clock clock = {});

    /// The frame starts: the clock is read, nothing is spent.
    void begin();
    /// Milliseconds spent since begin().
    double spentMs() const;
    /// What is left of the frame's budget when `reserveMs` are kept for later steps (may be
    /// negative: over budget).
    double leftMs(double reserveMs = 0.0) const { return ms_ - reserveMs - spentMs(); }
    /// Optional work of a step may go on: more than `reserveMs` of the budget is left. A step
    /// that stops here is counted (deferred()).
    bool allows(double reserveMs = 0.0);
    /// Steps that stopped for the budget since begin().
    int deferred() const { return deferred_; }
    /// The budget per frame, in ms.
    double budgetMs() const { return ms_; }
    /// Frames begun (begin() calls): a step that may run once a frame tells frames apart.
    unsigned long frame() const { return frame_; }

  private:
    double ms_;
    Clock clock_;
    double start_ = 0.0;
    int deferred_ = 0;
    unsigned long frame_ = 0;
};

}  // namespace lancer::viewer
