// The traversal's observer: every scheme reports what it does to an object of this shape.
// Rendering passes NullObserver, whose empty inline members cost nothing; `lancer trace`, the
// viewer's ray animation and the tests pass a RecordingObserver.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/model/span.h"

namespace lancer {

struct NullObserver {
    static constexpr bool kActive = false;
    void region(uint32_t id, double t0, double t1) {}
    void pointer(uint32_t from, uint32_t to, int corner) {}
    void primTest(uint32_t prim, const Span* spans, int n) {}
    void mailboxHit(uint32_t prim) {}
    void regionSpans(const SpanList& spans) {}
    void walkError(const char* what) {}
};

/// One event of a walk, in order.
struct WalkEvent {
    enum Kind : uint8_t { Region, Pointer, PrimTest, MailboxHit, Spans, Error } kind;
    uint32_t a = 0, b = 0;      ///< region id / prim id; pointer: from, to
    int corner = -1;            ///< pointer: which corner
    double t0 = 0.0, t1 = 0.0;  ///< region interval
    SpanList spans;             ///< PrimTest: the primitive's spans; Spans: the region's tree
    std::string what;           ///< Error
};

struct RecordingObserver {
    static constexpr bool kActive = true;
    std::vector<WalkEvent> events;
    void region(uint32_t id, double t0, double t1) {
        events.push_back({WalkEvent::Region, id, 0, -1, t0, t1, {}, {}});
    }
    void pointer(uint32_t from, uint32_t to, int corner) {
        events.push_back({WalkEvent::Pointer, from, to, corner, 0, 0, {}, {}});
    }
    void primTest(uint32_t prim, const Span* spans, int n) {
        events.push_back({WalkEvent::PrimTest, prim, 0, -1, 0, 0, SpanList(spans, spans + n), {}});
    }
    void mailboxHit(uint32_t prim) {
        events.push_back({WalkEvent::MailboxHit, prim, 0, -1, 0, 0, {}, {}});
    }
    void regionSpans(const SpanList& s) {
        events.push_back({WalkEvent::Spans, 0, 0, -1, 0, 0, s, {}});
    }
    void walkError(const char* what) {
        events.push_back({WalkEvent::Error, 0, 0, -1, 0, 0, {}, what});
    }
};

}  // namespace lancer
