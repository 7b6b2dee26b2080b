// Per-thread state of ray tracing: mailboxes, span scratch buffers and counters.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/model/span.h"

namespace lancer {

/// Counters every scheme reports; summed over threads for `--stats`, per pixel for heatmaps.
struct RayCounters {
    uint64_t rays = 0;  ///< all rays traced (primary, shadow, reflected, refracted)
    uint64_t primaryRays = 0;
    uint64_t shadowRays = 0;
    uint64_t primTests = 0;         ///< ray-primitive intersection computations done
    uint64_t mailboxHits = 0;       ///< computations saved by a mailbox
    uint64_t regionVisits = 0;      ///< regions entered
    uint64_t pointerSteps = 0;      ///< region changes by corner pointer (irregular scheme)
    uint64_t walkErrors = 0;        ///< walks that could not advance and were ended
    uint64_t lightBufferSkips = 0;  ///< shadow rays the light buffer found unblocked, no walk

    RayCounters& operator+=(const RayCounters& o);
    RayCounters operator-(const RayCounters& o) const;
    bool operator==(const RayCounters&) const = default;
    /// "rays 3 (1 primary, 2 shadow), prim tests 9, mailbox hits 2, regions 3, ..." (no newline).
    std::string toString() const;
};

std::ostream& operator<<(std::ostream& os, const RayCounters& c);

/// The report's "boîte aux lettres": the spans of the last ray tested against a primitive, the
/// ray's id being TraceContext::stamp. Each thread owns its own arrays, so no mailbox is ever
/// shared between threads.
struct Mailbox {
    uint8_t count = 0;
    Span spans[2];
};

/// Span boundaries of the primitives the current ray has tested that lie ahead of its walk: the
/// regular walk evaluates a leaf's tree only when the nearest of them falls inside the leaf.
struct PendingBoundaries {
    std::vector<double> t;  ///< unordered; those behind the walk are dropped lazily
    double next = kInf;     ///< the least of t

    void clear() {
        t.clear();
        next = kInf;
    }
    void add(double x) {
        t.push_back(x);
        if (x < next) next = x;
    }
    /// Drop the boundaries before `t0` and find the least of the rest.
    void advance(double t0) {
        size_t k = 0;
        next = kInf;
        for (double x : t)
            if (x >= t0) {
                t[k++] = x;
                if (x < next) next = x;
            }
        t.resize(k);
    }
};

/// One per thread. Ray ids start at 1 and are unique within the context, so mailboxes never
/// need clearing between rays.
struct TraceContext {
    std::vector<uint64_t> stamp;  ///< per primitive: the ray id its mailbox holds spans for
    std::vector<Mailbox> mail;
    PendingBoundaries pending;      ///< of the ray the regular walk is on
    std::vector<SpanList> scratch;  ///< two buffers per tree level, reused without allocation
    SpanList result;                ///< spans of the tree evaluated last
    uint64_t rayId = 0;
    bool useMailboxes = true;
    RayCounters counters;

    TraceContext() = default;
    TraceContext(size_t primitives, int treeDepth) { reset(primitives, treeDepth); }
    void reset(size_t primitives, int treeDepth);
    /// Start a new ray: a fresh id for the mailboxes.
    void beginRay() {
        ++rayId;
        ++counters.rays;
    }
    /// A fresh mailbox id for the same ray (a walk over another stretch of it).
    void newStamp() { ++rayId; }
};

}  // namespace lancer
