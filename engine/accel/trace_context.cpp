#include "engine/accel/trace_context.h"

#include <algorithm>
#include <ostream>

#include "engine/util/huge_pages.h"

namespace lancer {

RayCounters& RayCounters::operator+=(const RayCounters& o) {
    for (const Field& f : fields()) this->*f.member += o.*f.member;
    return *this;
}

RayCounters RayCounters::operator-(const RayCounters& o) const {
    RayCounters r = *this;
    for (const Field& f : fields()) r.*f.member -= o.*f.member;
    return r;
}

std::string RayCounters::toString() const {
    // "rays 3 (1 primary, 2 shadow), prim tests 9, ...": the kinds of ray inside rays' brackets.
    std::string s;
    bool inRays = false;
    for (const Field& f : fields()) {
        if (f.partOfRays) {
            s += inRays ? ", " : " (";
            inRays = true;
            s += std::to_string(this->*f.member) + " " + f.label;
            continue;
        }
        if (inRays) s += ")";
        inRays = false;
        if (!s.empty()) s += ", ";
        s += std::string(f.label) + " " + std::to_string(this->*f.member);
    }
    if (inRays) s += ")";
    return s;
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
