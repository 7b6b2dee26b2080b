// One budget for a whole frame, shared by the steps that may leave work for the next frame:
// the overlays' batches copied to GL and their layer drawn in parts, the inspector's picture
// in parts, the panel layer's redraws. Each of these steps, each within its own share, once
// fell together with the others in one frame (34-51 ms of UI CPU on balls4's slabs,
// 2026-12-06). The steps draw from the budget in the frame's order, which is their priority:
// a new view's image parts (taken in any case), then the layer, then the inspector, then the
// panels; a step stops its optional work once the frame's budget, less what it leaves to the
// steps after it, is spent, and goes on in the next frame. A step whose work comes in parts
// learns what a part costs (StepCost) and starts one only when that cost fits in what is left
// (fits()): a part begun with a little budget left once ran over by its whole cost (frames of
// 33-41 ms on balls4's slabs with the inspector, 2026-12-06).
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
    /// A part of optional work estimated at `estimateMs` may start: it fits in what is left
    /// when `reserveMs` are kept for later steps. A step that stops here is counted
    /// (deferred()).
    bool fits(double estimateMs, double reserveMs = 0.0);
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

/// What a step's work costs per unit (a row, a line, a byte), learned from the parts it ran:
/// a running mean of the measured cost per unit, so that a part starts only when its
/// estimate fits in the frame's budget (FrameBudget::fits()) and a part's size follows what
/// the machine takes now.
class StepCost {
  public:
    /// `msPerUnit` until a part is measured.
    explicit StepCost(double msPerUnit) : msPerUnit_(msPerUnit) {}
    /// The estimated cost of `units`, in ms.
    double estimateMs(double units) const { return msPerUnit_ * units; }
    /// How many whole units fit in `ms` (0 if none does).
    double unitsIn(double ms) const;
    /// A part of `units` took `ms`: the running mean moves a quarter of the way to it (one slow
    /// part, e.g. the machine's load, does not stop the step for long; a lasting change is
    /// followed within a few parts).
    void record(double units, double ms);
    /// The current cost per unit, in ms.
    double msPerUnit() const { return msPerUnit_; }

  private:
    double msPerUnit_;
};

}  // namespace lancer::viewer
