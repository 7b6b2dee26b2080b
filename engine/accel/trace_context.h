// Per-thread state of ray tracing: mailboxes, span scratch buffers and counters.
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/model/shapes.h"
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

    /// One counter: its key in `--stats` and the trace JSON, its words in toString, its member.
    struct Field {
        const char* key;                ///< "prim_tests"
        const char* label;              ///< "prim tests"
        uint64_t RayCounters::*member;  ///< &RayCounters::primTests
        bool partOfRays;                ///< written in parentheses after `rays` (a kind of ray)
    };
    /// Every counter, once: +=, -, toString and the JSON writers (toJson, statsJson) loop over
    /// it, so a counter added to the struct and here is summed, printed and written everywhere.
    static constexpr std::array<Field, 9> fields() {
        return {
            {{"rays", "rays", &RayCounters::rays, false},
             {"primary_rays", "primary", &RayCounters::primaryRays, true},
             {"shadow_rays", "shadow", &RayCounters::shadowRays, true},
             {"prim_tests", "prim tests", &RayCounters::primTests, false},
             {"mailbox_hits", "mailbox hits", &RayCounters::mailboxHits, false},
             {"region_visits", "regions", &RayCounters::regionVisits, false},
             {"pointer_steps", "pointer steps", &RayCounters::pointerSteps, false},
             {"walk_errors", "walk errors", &RayCounters::walkErrors, false},
             {"light_buffer_skips", "light buffer skips", &RayCounters::lightBufferSkips, false}}};
    }

    RayCounters& operator+=(const RayCounters& o);
    RayCounters operator-(const RayCounters& o) const;
    bool operator==(const RayCounters&) const = default;
    /// "rays 3 (1 primary, 2 shadow), prim tests 9, mailbox hits 2, regions 3, ..." (no newline).
    std::string toString() const;
};

// A member left out of fields() makes the struct larger than the list: the compiler says so.
static_assert(sizeof(RayCounters) == RayCounters::fields().size() * sizeof(uint64_t),
              "every RayCounters member is listed in RayCounters::fields()");

std::ostream& operator<<(std::ostream& os, const RayCounters& c);

/// The report's "boîte aux lettres": the spans of a primitive for the current ray id
/// (TraceContext::rayId). Each thread owns its own, so no mailbox is ever shared between threads.
struct Mailbox {
    uint8_t count = 0;
    Span spans[2];
};

/// Span boundaries of the primitives the current ray has tested that lie ahead of its walk: the
/// regular walk evaluates a leaf's tree only when the nearest of them falls inside the leaf.
struct PendingBoundaries {
    std::vector<double> t;  ///< unordered; those behind the walk are dropped lazily
    double next = kInf;     ///< the least of t
    /// The last region hitInLeaf was given has every primitive it lists in a mailbox of this
    /// walk (false after a lazy evaluation, which fetches only what the tree needs).
    bool tested = true;

    void clear() {
        t.clear();
        next = kInf;
        tested = true;
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

/// One per thread. Ray ids start at 1 and are unique within the context until they wrap (after
/// 2^32 ids, when every tag is cleared once), so mailboxes never need clearing between rays.
///
/// A primitive's mailbox is found through its tag: the ray id it was filled for and where it is
/// held. Only the current ray id's mailboxes are held, in the order they were filled; a new id
/// drops them. A scene's primitives thus cost 8 bytes each per thread (a mailbox per primitive,
/// 80 bytes with its stamp, took 48 MB per thread on a 598k-sphere scene: 0.3 s of page faults
/// per render of 2 threads), and the mailboxes a ray fills lie together in a few cache lines.
struct TraceContext {
    struct Tag {
        uint32_t stamp = 0;  ///< the ray id its mailbox was filled for; 0: none
        uint32_t slot = 0;   ///< the mailbox's index in `held`
    };
    std::vector<Tag> tags;          ///< per primitive
    std::vector<Mailbox> held;      ///< [0] empty; then the current ray id's mailboxes, as filled
    PendingBoundaries pending;      ///< of the ray a leaf walk (hitInLeaf) is on
    std::vector<SpanList> scratch;  ///< two buffers per tree level, reused without allocation
    SpanList result;                ///< spans of the tree evaluated last
    SpanList leafSpans;             ///< the spans of a region's primitives (hitInLeaf's union)
    /// Zones the irregular scheme's projective walks located last, one per structure (the
    /// eye's, then its lights'; ProjectiveZones::hintSlot): rays come in pixel order, so the
    /// next one's zone is most often the same, checked by its rectangle before the screen BSP
    /// is descended.
    std::array<uint32_t, 9> zoneHint{};
    uint32_t rayId = 0;
    bool useMailboxes = true;
    Precision precision = Precision::Double;  ///< of the primitives' tests (--precision)
    RayCounters counters;

    TraceContext() = default;
    TraceContext(size_t primitives, int treeDepth) { reset(primitives, treeDepth); }
    void reset(size_t primitives, int treeDepth);
    /// Start a new ray: a fresh id for the mailboxes.
    void beginRay() {
        newStamp();
        ++counters.rays;
    }
    /// A fresh mailbox id for the same ray (a walk over another stretch of it).
    void newStamp() {
        held.resize(1);  // held[0], the empty mailbox, stays
        if (++rayId == 0) wrap();
    }
    /// hitInLeaf's state for a walk from its first region: a fresh mailbox id (a primitive an
    /// earlier walk of the same ray id tested, its boundaries not kept, is tested again) and no
    /// pending boundaries.
    void beginLeafWalk() {
        newStamp();
        pending.clear();
    }
    /// The mailbox primitive `p` holds for the current ray id, or null when none was filled.
    Mailbox* heldMailbox(uint32_t p) {
        const Tag t = tags[p];
        return t.stamp == rayId ? &held[t.slot] : nullptr;
    }
    /// A mailbox for primitive `p` for the current ray id, to fill: valid until the next one is
    /// taken (they are held in one growing array).
    Mailbox& takeMailbox(uint32_t p) {
        tags[p] = {rayId, uint32_t(held.size())};
        return held.emplace_back();
    }
    /// Primitive `p` tested for the current ray id and missed: its tag names the empty mailbox
    /// (held[0]), so a miss, most tests, writes no mailbox of its own.
    void heldEmpty(uint32_t p) { tags[p] = {rayId, 0}; }

  private:
    /// The ray ids ran out: every tag cleared, ids start again at 1.
    void wrap();
};

}  // namespace lancer
