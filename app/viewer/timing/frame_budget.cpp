#include "app/viewer/timing/frame_budget.h"

#include <cmath>
#include <limits>
#include <utility>

#include "app/viewer/timing/frame_times.h"

namespace lancer::viewer {

FrameBudget::FrameBudget(double ms, Clock clock)
    : ms_(ms), clock_(clock ? std::move(clock) : Clock(threadCpuMs)) {
    begin();
}

void FrameBudget::begin() {
    start_ = clock_();
    deferred_ = 0;
    forced_.clear();
    ++frame_;
}

double FrameBudget::spentMs() const { return clock_() - start_; }

bool FrameBudget::allows(double reserveMs) {
    if (leftMs(reserveMs) > 0.0) return true;
    ++deferred_;
    return false;
}

bool FrameBudget::fits(double estimateMs, double reserveMs) {
    if (leftMs(reserveMs) >= estimateMs) return true;
    ++deferred_;
    return false;
}

bool FrameBudget::fits(double estimateMs, double reserveMs, Patience& patience) {
    // Only a step's first part of a frame counts: one that started a part in this frame has
    // made progress, and a frame is counted once however often the step asks in it.
    const bool firstAsk = patience.startedFrame_ != frame_ && patience.waitedFrame_ != frame_;
    const bool fitsNow = leftMs(reserveMs) >= estimateMs;
    if (fitsNow || (firstAsk && patience.waited_ >= kPatienceFrames)) {
        if (!fitsNow) forced_.push_back({patience.step_, estimateMs, leftMs(reserveMs), reserveMs});
        patience.startedFrame_ = frame_;
        patience.waited_ = 0;
        return true;
    }
    ++deferred_;
    if (firstAsk) {
        patience.waitedFrame_ = frame_;
        ++patience.waited_;
    }
    return false;
}

double StepCost::unitsIn(double ms) const {
    if (ms <= 0.0) return 0.0;
    if (msPerUnit_ <= 0.0) return std::numeric_limits<double>::infinity();
    return std::floor(ms / msPerUnit_);
}

void StepCost::record(double units, double ms) {
    if (units <= 0.0 || !(ms >= 0.0)) return;
    msPerUnit_ += 0.25 * (ms / units - msPerUnit_);
}

}  // namespace lancer::viewer
