// Spans: the intervals of a ray's line inside a solid (Roth 1982), and their booleans.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer {

inline constexpr uint32_t kNoPrim = 0xffffffffu;

/// One end of a span: where the ray crosses the surface of primitive `prim`.
/// `part` tells which face (box face, cone side or cap); `flip` is set when a difference turned
/// the surface inside out, so its outward normal must be reversed.
struct Boundary {
    double t = 0.0;
    uint32_t prim = kNoPrim;
    uint8_t part = 0;
    bool flip = false;
    bool operator==(const Boundary&) const = default;
};

/// [in, out] along the ray. Solids give in.t < out.t; a surface hit is a span of zero length.
struct Span {
    Boundary in, out;
    bool operator==(const Span&) const = default;
    std::string toString() const;
};

using SpanList = std::vector<Span>;

std::string toString(const SpanList& spans);

/// Booleans on sorted, disjoint span lists. Union keeps zero-length (surface) spans and merges
/// touching spans; intersection and difference drop results of zero length.
void spanUnion(const SpanList& a, const SpanList& b, SpanList& out);
void spanIntersection(const SpanList& a, const SpanList& b, SpanList& out);
void spanDifference(const SpanList& a, const SpanList& b, SpanList& out);

/// The first span boundary with t in [lo, hi] and t > after, or nullptr.
const Boundary* firstBoundary(const SpanList& spans, double after, double lo, double hi);

}  // namespace lancer
