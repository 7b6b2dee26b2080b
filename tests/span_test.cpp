// Span booleans on hand-made lists, including equal endpoints and surfaces.
#include "engine/model/span.h"

#include <gtest/gtest.h>

namespace lancer {
namespace {

Span sp(double a, double b, uint32_t pa = 0, uint32_t pb = 0) {
    return {{a, pa, 0, false}, {b, pb, 0, false}};
}
std::vector<std::pair<double, double>> ts(const SpanList& l) {
    std::vector<std::pair<double, double>> r;
    for (const Span& s : l) r.emplace_back(s.in.t, s.out.t);
    return r;
}
using P = std::vector<std::pair<double, double>>;

TEST(SpanUnion, MergesOverlapsAndTouches) {
    SpanList out;
    spanUnion({sp(1, 3), sp(5, 6)}, {sp(2, 4), sp(6, 7), sp(9, 10)}, out);
    EXPECT_EQ(ts(out), (P{{1, 4}, {5, 7}, {9, 10}}));
    spanUnion({}, {sp(1, 2)}, out);
    EXPECT_EQ(ts(out), (P{{1, 2}}));
}

TEST(SpanUnion, KeepsSurfacesOutsideSolidsAndHidesThemInside) {
    SpanList out;
    spanUnion({sp(1, 3)}, {sp(2, 2, 9, 9), sp(5, 5, 8, 8)}, out);
    EXPECT_EQ(ts(out), (P{{1, 3}, {5, 5}}));
    EXPECT_EQ(out[1].in.prim, 8u);
}

TEST(SpanIntersection, OverlapOnlyAndDropsZeroLength) {
    SpanList out;
    spanIntersection({sp(1, 4, 1, 1), sp(6, 9, 1, 1)}, {sp(3, 7, 2, 2)}, out);
    EXPECT_EQ(ts(out), (P{{3, 4}, {6, 7}}));
    EXPECT_EQ(out[0].in.prim, 2u);   // entered through B
    EXPECT_EQ(out[0].out.prim, 1u);  // left through A
    // Touching at one point: no volume in common.
    spanIntersection({sp(1, 2)}, {sp(2, 3)}, out);
    EXPECT_TRUE(out.empty());
    // Equal spans.
    spanIntersection({sp(1, 2, 1, 1)}, {sp(1, 2, 2, 2)}, out);
    EXPECT_EQ(ts(out), (P{{1, 2}}));
}

TEST(SpanDifference, CutsFlipsAndCoplanarFaces) {
    SpanList out;
    spanDifference({sp(0, 10, 1, 1)}, {sp(2, 3, 2, 2), sp(5, 6, 2, 2)}, out);
    EXPECT_EQ(ts(out), (P{{0, 2}, {3, 5}, {6, 10}}));
    // Surfaces exposed by the cut belong to B, turned inside out.
    EXPECT_EQ(out[0].out.prim, 2u);
    EXPECT_TRUE(out[0].out.flip);
    EXPECT_TRUE(out[1].in.flip);
    EXPECT_FALSE(out[0].in.flip);
    // B covers A's start exactly (coplanar entry faces): the visible entry is B's exit.
    spanDifference({sp(0, 4, 1, 1)}, {sp(0, 1, 2, 2)}, out);
    EXPECT_EQ(ts(out), (P{{1, 4}}));
    EXPECT_EQ(out[0].in.prim, 2u);
    // B covers A's end exactly (coplanar exit faces).
    spanDifference({sp(0, 4, 1, 1)}, {sp(3, 4, 2, 2)}, out);
    EXPECT_EQ(ts(out), (P{{0, 3}}));
    // B swallows A.
    spanDifference({sp(1, 2)}, {sp(0, 3)}, out);
    EXPECT_TRUE(out.empty());
    // B only touches A: nothing removed.
    spanDifference({sp(1, 2)}, {sp(2, 3), sp(0, 1)}, out);
    EXPECT_EQ(ts(out), (P{{1, 2}}));
    // One B span across two A spans.
    spanDifference({sp(0, 2), sp(3, 5)}, {sp(1, 4)}, out);
    EXPECT_EQ(ts(out), (P{{0, 1}, {4, 5}}));
}

TEST(FirstBoundary, RespectsTminAndRegionInterval) {
    SpanList l{sp(1, 3, 1, 1), sp(5, 5, 2, 2), sp(7, 9, 3, 3)};
    EXPECT_EQ(firstBoundary(l, 0.0, -kInf, kInf)->t, 1.0);
    EXPECT_EQ(firstBoundary(l, 2.0, -kInf, kInf)->t, 3.0);  // origin inside: the exit
    EXPECT_EQ(firstBoundary(l, 3.0, -kInf, kInf)->t, 5.0);  // strictly after tmin
    EXPECT_EQ(firstBoundary(l, 0.0, 4.0, 6.0)->t, 5.0);     // region [4, 6]
    EXPECT_EQ(firstBoundary(l, 0.0, 5.0, 6.0)->t, 5.0);     // closed at the region's start
    EXPECT_EQ(firstBoundary(l, 0.0, 5.5, 6.9), nullptr);
    EXPECT_EQ(firstBoundary(l, 0.0, 7.5, 10.0)->t, 9.0);  // entry before the region: its exit
}

}  // namespace
}  // namespace lancer
