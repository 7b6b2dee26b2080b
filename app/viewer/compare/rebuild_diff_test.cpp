// The rebuild A/B as data: the diverging colour map of a difference, old minus new per pixel,
// rows not rendered yet, which old image is kept (never a partial one), and the parameter changes
// it is labelled with.
#include "app/viewer/compare/rebuild_diff.h"

#include <gtest/gtest.h>

#include <cmath>

#include "app/cli/param_table.h"

namespace lancer::viewer::compare {
namespace {

// Equal counters give the neutral colour; fewer tests in the new structure (old - new > 0) the
// "better" hue, blue; more the "worse" hue, red; the scale clamps, on a linear and a log scale.
TEST(DiffColormap, NeutralWhenEqualBlueWhenFewerRedWhenMoreAndTheScaleClamps) {
    const glm::vec3 neutral = divergingStops()[4];
    EXPECT_EQ(divergingColor(diffValue(0.0f, 50.0f, false)), neutral);
    EXPECT_EQ(divergingColor(diffValue(0.0f, 50.0f, true)), neutral);
    EXPECT_GT(neutral.x, 0.9f);
    EXPECT_NEAR(neutral.x, neutral.z, 0.01f) << "the middle is a grey: no hue";
    for (bool log : {false, true}) {
        const glm::vec3 better = divergingColor(diffValue(20.0f, 50.0f, log));  // new does less
        const glm::vec3 worse = divergingColor(diffValue(-20.0f, 50.0f, log));  // new does more
        EXPECT_GT(better.z, better.x + 0.1f) << "fewer tests: blue";
        EXPECT_GT(worse.x, worse.z + 0.1f) << "more tests: red";
        // Larger differences are further from white, up to the scale, then clamped.
        const glm::vec3 more = divergingColor(diffValue(40.0f, 50.0f, log));
        EXPECT_LT(more.x, better.x);
        EXPECT_EQ(diffValue(50.0f, 50.0f, log), 1.0f);
        EXPECT_EQ(diffValue(5000.0f, 50.0f, log), 1.0f);
        EXPECT_EQ(diffValue(-5000.0f, 50.0f, log), -1.0f);
        EXPECT_EQ(divergingColor(diffValue(5000.0f, 50.0f, log)), divergingStops().back());
        EXPECT_EQ(divergingColor(diffValue(-5000.0f, 50.0f, log)), divergingStops().front());
        EXPECT_FLOAT_EQ(diffValue(-20.0f, 50.0f, log), -diffValue(20.0f, 50.0f, log));
    }
    EXPECT_FLOAT_EQ(diffValue(25.0f, 50.0f, false), 0.5f);
    EXPECT_FLOAT_EQ(diffValue(std::expm1(0.5f * std::log1p(99.0f)), 99.0f, true), 0.5f);
    EXPECT_EQ(diffValue(3.0f, 0.0f, false), 1.0f) << "a scale of 0 is taken as 1";
    // The stops are symmetric in lightness around the neutral one: the same size of change
    // reads the same either way.
    const auto& s = divergingStops();
    for (size_t i = 0; i < 4; ++i) {
        auto light = [](const glm::vec3& c) { return 0.3f * c.x + 0.59f * c.y + 0.11f * c.z; };
        EXPECT_NEAR(light(s[i]), light(s[8 - i]), 0.12f) << "stop " << i;
    }
}

Image counters(int w, int h, uint32_t tests, uint32_t visits, float us) {
    Image img(w, h);
    for (size_t i = 0; i < img.primTests.size(); ++i) {
        img.primTests[i] = tests + uint32_t(i);
        img.regionVisits[i] = visits;
        img.timeUs[i] = us;
    }
    return img;
}

RenderKey keyOf(int w, int h) {
    RenderKey k;
    k.spec = "builtin:balls:1";
    k.width = w;
    k.height = h;
    return k;
}

TEST(RebuildDiff, TheDiffIsOldMinusNewOnTheRowsTheNewImageHasDone) {
    const int w = 4, h = 3;
    BuildParams pa, pb;
    pa.scheme = pb.scheme = SchemeKind::Regular;
    pa.regular.maxLevel = 8;
    pb.regular.maxLevel = 12;
    const Image a = counters(w, h, 100, 7, 5.0f);
    Image b = counters(w, h, 60, 9, 2.5f);
    b.primTests[5] = 400;  // one pixel where the new structure does more
    RebuildDiff d;
    d.rebuilt(a, true, keyOf(w, h), pa, {});
    ASSERT_NE(d.old(), nullptr);
    const std::vector<float> tests = diffChannel(*d.old(), b, ViewMode::PrimTests, 0, -1, h);
    ASSERT_EQ(tests.size(), size_t(w * h));
    for (size_t i = 0; i < tests.size(); ++i)
        EXPECT_EQ(tests[i], float(a.primTests[i]) - float(b.primTests[i])) << i;
    EXPECT_LT(tests[5], 0.0f);
    EXPECT_EQ(diffChannel(*d.old(), b, ViewMode::RegionVisits, 0, -1, h)[0], -2.0f);
    EXPECT_EQ(diffChannel(*d.old(), b, ViewMode::TimeUs, 0, -1, h)[0], 2.5f);
    // Rows the new image has not reached compare nothing; a range of rows is those rows.
    const std::vector<float> partial = diffChannel(*d.old(), b, ViewMode::PrimTests, 1, 3, 2);
    ASSERT_EQ(partial.size(), size_t(2 * w));
    for (int x = 0; x < w; ++x) {
        EXPECT_EQ(partial[size_t(x)], tests[size_t(w + x)]);
        EXPECT_EQ(partial[size_t(w + x)], kNoDiff);
    }
    EXPECT_EQ(counterChannel(*d.old(), ViewMode::PrimTests, 2, 3)[0], float(a.primTests[8]));
    // The scale of a difference: its magnitudes' 99th percentile, the rows not done left out.
    std::vector<float> mags(100, -50.0f);
    mags.resize(150, kNoDiff);
    EXPECT_EQ(diffAutoScale(mags), 50.0f);
    // Totals over the rows compared.
    const CounterSums sa = sumRows(*d.old(), 2), sb = sumRows(b, 2);
    EXPECT_EQ(sa.pixels, size_t(2 * w));
    uint64_t expect = 0;
    for (int i = 0; i < 2 * w; ++i) expect += a.primTests[size_t(i)];
    EXPECT_EQ(sa.primTests, expect);
    EXPECT_EQ(sb.regionVisits, uint64_t(9 * 2 * w));
    const AbStatus s = d.status(keyOf(w, h), 2);
    EXPECT_TRUE(s.comparable);
    EXPECT_EQ(s.rows, 2);
    EXPECT_NE(s.note.find("still rendering"), std::string::npos) << s.note;
    EXPECT_TRUE(d.status(keyOf(w, h), h).note.empty());
    EXPECT_EQ(paramChanges(pa, pb), "max-level 8 -> 12");
    EXPECT_EQ(paramChanges(pa, pa), "same parameters");
}

TEST(RebuildDiff, APartialOldImageIsNeverComparedAndAnotherViewDoesNotCompare) {
    const int w = 4, h = 3;
    const Image a = counters(w, h, 100, 7, 5.0f);
    RebuildDiff d;
    EXPECT_NE(d.status(keyOf(w, h), h).note.find("no rebuild yet"), std::string::npos);
    d.rebuilt(a, false, keyOf(w, h), {}, {});
    EXPECT_EQ(d.old(), nullptr) << "a partial image is not kept";
    AbStatus s = d.status(keyOf(w, h), h);
    EXPECT_FALSE(s.comparable);
    EXPECT_NE(s.note.find("no complete old image to compare"), std::string::npos) << s.note;
    // A complete image is kept; a later rebuild before the next image is complete keeps it (the
    // last complete image, which the A/B labels with its parameters).
    BuildParams p8;
    p8.regular.maxLevel = 8;
    d.rebuilt(a, true, keyOf(w, h), p8, {});
    d.rebuilt(counters(w, h, 1, 1, 1.0f), false, keyOf(w, h), {}, {});
    ASSERT_NE(d.old(), nullptr);
    EXPECT_EQ(d.old()->params.regular.maxLevel, 8);
    EXPECT_EQ(d.old()->primTests, a.primTests);
    EXPECT_TRUE(d.status(keyOf(w, h), h).comparable);
    // Another camera, size or shading: the pixels are other rays.
    RenderKey moved = keyOf(w, h);
    moved.camera.from.x += 1.0;
    EXPECT_FALSE(d.status(moved, h).comparable);
    RenderKey shaded = keyOf(w, h);
    shaded.shading.bounces = 0;
    EXPECT_FALSE(d.status(shaded, h).comparable);
    RenderKey single = keyOf(w, h);
    single.shading.precision = Precision::Float;  // the same rays, other hits
    EXPECT_FALSE(d.status(single, h).comparable);
    EXPECT_FALSE(d.status(keyOf(w + 1, h), h).comparable);
    d.clear();
    EXPECT_EQ(d.old(), nullptr);
}

TEST(RebuildDiff, AbViewsAndAssignmentsReadBack) {
    for (int i = 0; i < kAbViewCount; ++i) EXPECT_EQ(abViewOf(abViewKey(AbView(i))), AbView(i));
    EXPECT_FALSE(abViewOf("both"));
    for (int i = 0; i < kViewModeCount; ++i)
        EXPECT_EQ(viewModeOf(viewModeWord(ViewMode(i))), ViewMode(i));
    cli::Knobs k;
    cli::applyAssignments("max-level=16,max-objects=2,mailboxes=0,step=push", k);
    EXPECT_EQ(k.build.regular.maxLevel, 16);
    EXPECT_EQ(k.build.regular.maxObjects, 2);
    EXPECT_FALSE(k.build.mailboxes);
    EXPECT_EQ(k.build.regular.step, StepMethod::Push);
    const cli::Knobs before = k;
    for (const char* bad : {"max-level", "max-level=99", "depth=x.pfm", "width=10", "colour=1", ""})
        EXPECT_THROW(cli::applyAssignments(bad, k), std::invalid_argument) << bad;
    EXPECT_EQ(k.build.regular.maxLevel, before.build.regular.maxLevel) << "unchanged on error";
}

}  // namespace
}  // namespace lancer::viewer::compare
