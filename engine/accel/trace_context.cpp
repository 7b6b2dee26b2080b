#include "engine/accel/trace_context.h"

namespace lancer {

RayCounters& RayCounters::operator+=(const RayCounters& o) {
    rays += o.rays;
    primaryRays += o.primaryRays;
    shadowRays += o.shadowRays;
    primTests += o.primTests;
    mailboxHits += o.mailboxHits;
    regionVisits += o.regionVisits;
    pointerSteps += o.pointerSteps;
    walkErrors += o.walkErrors;
    lightBufferSkips += o.lightBufferSkips;
    return *this;
}

RayCounters RayCounters::operator-(const RayCounters& o) const {
    RayCounters r = *this;
    r.rays -= o.rays;
    r.primaryRays -= o.primaryRays;
    r.shadowRays -= o.shadowRays;
    r.primTests -= o.primTests;
    r.mailboxHits -= o.mailboxHits;
    r.regionVisits -= o.regionVisits;
    r.pointerSteps -= o.pointerSteps;
    r.walkErrors -= o.walkErrors;
    r.lightBufferSkips -= o.lightBufferSkips;
    return r;
}

void TraceContext::reset(size_t primitives, int treeDepth) {
    stamp.assign(primitives, 0);
    mail.assign(primitives, Mailbox{});
    scratch.resize(size_t(2 * treeDepth + 4));
    rayId = 0;
}

}  // namespace lancer
