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
// 33-41 ms on balls4's slabs with the inspector, 2026-12-06). No step starves: one whose work
// waited kPatienceFrames frames in a row starts its first part of the next frame whatever the
// budget (fits() with the step's Patience). Without that bound a part that fitted in the
// budget less its reserve but never beside what the frame had spent before it waited for
// ever: on a quiet machine the overlay layer's texture of a new size was deferred in every
// frame of a 10-minute run (balls4's slabs with the inspector at 1280x720, 2026-12-07).
#pragma once

#include <functional>
#include <vector>

namespace lancer::viewer {

/// Frames in a row a step's work may wait for the budget: in the next one its first part
/// starts whatever the budget (FrameBudget::fits() with a Patience).
inline constexpr unsigned kPatienceFrames = 2;

/// What a step whose work the budget defers keeps from frame to frame, so that it never
/// starves: the frames in a row its work waited without a part started. One per step (per
/// kind of part: a texture to make, a layer's part, a panel's redraw), owned by the step.
class Patience {
  public:
    /// A step named `step` (a string literal: --log-timings prints it when the step is let in
    /// over the budget).
    explicit Patience(const char* step = "step") : step_(step) {}
    /// Frames in a row the step's work waited for the budget (none started since).
    unsigned waited() const { return waited_; }
    /// The step's name.
    const char* step() const { return step_; }

  private:
    friend class FrameBudget;
    const char* step_;
    unsigned long startedFrame_ = 0;  ///< the last frame a part of the step started
    unsigned long waitedFrame_ = 0;   ///< the last frame counted in waited_
    unsigned waited_ = 0;
};

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
    /// As fits(), for a step that must not starve: its first part of a frame also starts, over
    /// the budget, when its work waited kPatienceFrames frames in a row before this one (the
    /// step's `patience` keeps that count; a part that starts resets it). A part let in over
    /// the budget is counted (forced()), not deferred.
    bool fits(double estimateMs, double reserveMs, Patience& patience);
    /// Parts let in over the budget since begin() (the never-starving bound).
    int forced() const { return static_cast<int>(forced_.size()); }
    /// A part let in over the budget: the step, its estimate, and what was left of the
    /// budget beyond its reserve (negative: over) when it started.
    struct Forced {
        const char* step;
        double estimateMs;
        double leftMs;
        double reserveMs;
    };
    /// The parts let in over the budget since begin(), in order (--log-timings says why).
    const std::vector<Forced>& forcedSteps() const { return forced_; }
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
    std::vector<Forced> forced_;
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
