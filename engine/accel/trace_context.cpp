#include "engine/accel/trace_context.h"

#include <algorithm>
#include <ostream>

#include "engine/util/huge_pages.h"

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

std::string RayCounters::toString() const {
    return "rays " + std::to_string(rays) + " (" + std::to_string(primaryRays) + " primary, " +
           std::to_string(shadowRays) + " shadow), prim tests " + std::to_string(primTests) +
           ", mailbox hits " + std::to_string(mailboxHits) + ", regions " +
           std::to_string(regionVisits) + ", pointer steps " + std::to_string(pointerSteps) +
           ", walk errors " + std::to_string(walkErrors) + ", light buffer skips " +
           std::to_string(lightBufferSkips);
}

std::ostream& operator<<(std::ostream& os, const RayCounters& c) { return os << c.toString(); }

void TraceContext::reset(size_t primitives, int treeDepth) {
    // Read at random by every walk: huge pages spare most TLB misses.
    if (tags.capacity() < primitives) {
        tags.clear();
        reserveHuge(tags, primitives);
    }
    tags.assign(primitives, Tag{});
    held.reserve(64);
    held.assign(1, Mailbox{});
    scratch.resize(size_t(2 * treeDepth + 4));
    rayId = 0;
}

void TraceContext::wrap() {
    std::fill(tags.begin(), tags.end(), Tag{});
    rayId = 1;
}

}  // namespace lancer
