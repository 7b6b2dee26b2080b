#include "engine/model/span.h"

#include <cstdio>

namespace lancer {

std::string Span::toString() const {
    char buf[160];
    std::snprintf(buf, sizeof buf, "[%.17g (p%u.%u%s), %.17g (p%u.%u%s)]", in.t, in.prim,
                  unsigned(in.part), in.flip ? " flip" : "", out.t, out.prim, unsigned(out.part),
                  out.flip ? " flip" : "");
    return buf;
}

std::string toString(const SpanList& spans) {
    std::string s = "{";
    for (size_t i = 0; i < spans.size(); ++i) s += (i ? ", " : "") + spans[i].toString();
    return s + "}";
}

void spanUnion(const SpanList& a, const SpanList& b, SpanList& out) {
    out.clear();
    size_t i = 0, j = 0;
    while (i < a.size() || j < b.size()) {
        // Take the span that starts first (ties: a first, which keeps the result deterministic).
        const Span& s =
            (j >= b.size() || (i < a.size() && a[i].in.t <= b[j].in.t)) ? a[i++] : b[j++];
        if (!out.empty() && s.in.t <= out.back().out.t) {
            if (s.out.t > out.back().out.t) out.back().out = s.out;
        } else {
            out.push_back(s);
        }
    }
}

void spanIntersection(const SpanList& a, const SpanList& b, SpanList& out) {
    out.clear();
    size_t i = 0, j = 0;
    while (i < a.size() && j < b.size()) {
        const Span& x = a[i];
        const Span& y = b[j];
        const Boundary& in = x.in.t >= y.in.t ? x.in : y.in;
        const Boundary& o = x.out.t <= y.out.t ? x.out : y.out;
        if (in.t < o.t) out.push_back({in, o});
        if (x.out.t <= y.out.t)
            ++i;
        else
            ++j;
    }
}

void spanDifference(const SpanList& a, const SpanList& b, SpanList& out) {
    out.clear();
    size_t j = 0;
    for (const Span& x : a) {
        Boundary cur = x.in;  // start of the part of x not yet removed
        // Skip b spans that end before x starts.
        while (j < b.size() && b[j].out.t <= cur.t) ++j;
        size_t k = j;
        bool alive = true;
        while (k < b.size() && b[k].in.t < x.out.t) {
            const Span& y = b[k];
            if (y.in.t > cur.t) {
                Boundary end = y.in;
                end.flip = !end.flip;
                out.push_back({cur, end});
            }
            if (y.out.t >= x.out.t) {
                alive = false;
                break;
            }
            if (y.out.t > cur.t) {
                cur = y.out;
                cur.flip = !cur.flip;
            }
            ++k;
        }
        if (alive && cur.t < x.out.t) out.push_back({cur, x.out});
    }
}

const Boundary* firstBoundary(const SpanList& spans, double after, double lo, double hi) {
    for (const Span& s : spans) {
        if (s.in.t > hi) return nullptr;
        if (s.in.t >= lo && s.in.t > after) return &s.in;
        if (s.out.t >= lo && s.out.t > after) return s.out.t <= hi ? &s.out : nullptr;
    }
    return nullptr;
}

}  // namespace lancer
