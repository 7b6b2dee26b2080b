#include "app/viewer/timing/frame_budget.h"

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
    ++frame_;
}

double FrameBudget::spentMs() const { return clock_() - start_; }

bool FrameBudget::allows(double reserveMs) {
    if (leftMs(reserveMs) > 0.0) return true;
    ++deferred_;
    return false;
}

}  // namespace lancer::viewer
