// OpenSCAD text(): extruded glyphs against the bounds OpenSCAD 2021.01 itself meshes for the
// same text, holes that rays pass through, refusals naming file:line:column, and every scheme
// against brute force on an extruded word.
#include <gtest/gtest.h>

#include <string>

#include "engine/accel/accelerator.h"
#include "engine/scene/openscad/text2d.h"
#include "engine/scene/openscad_reader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

Scene textCsg(const std::string& text) { return readOpenScad(SourceText("mem.csg", text)); }

/// linear_extrude(1) of text(ARGS) as OpenSCAD exports it (ARGS after text and size).
std::string extrudedText(const std::string& word, const std::string& args = "") {
    return "linear_extrude(height = 1, center = false, convexity = 1, scale = [1, 1], $fn = 0, "
           "$fa = 12, $fs = 2) { text(text = \"" +
           word + "\", size = 10" + (args.empty() ? "" : ", " + args) +
           ", $fn = 0, $fa = 12, $fs = 2); }";
}

Box3 textBounds(const Scene& s) {
    Box3 b;
    for (const Primitive& p : s.prims) {
        b.lo = glm::min(b.lo, p.worldBox.lo);
        b.hi = glm::max(b.hi, p.worldBox.hi);
    }
    return b;
}

/// Bounds (x0, x1, y0, y1) of the STL that `openscad -o t.stl t.scad` makes of
/// `linear_extrude(1) text(WORD, size = 10, ARGS);` (Debian's OpenSCAD 2021.01, fonts-liberation
/// 2.1.5). Lancer's outline points are FreeType's 26.6 pixels / 1000, a step of 0.001 at size
/// 10, where OpenSCAD's mesh keeps finer coordinates: hence the tolerance of a step and a half.
void expectTextBounds(const std::string& word, const std::string& args, double x0, double x1,
                      double y0, double y1) {
    SCOPED_TRACE(word + " " + args);
    const Box3 b = textBounds(textCsg(extrudedText(word, args)));
    constexpr double tol = 1.5e-3;
    EXPECT_NEAR(b.lo.x, x0, tol);
    EXPECT_NEAR(b.hi.x, x1, tol);
    EXPECT_NEAR(b.lo.y, y0, tol);
    EXPECT_NEAR(b.hi.y, y1, tol);
    EXPECT_NEAR(b.lo.z, 0.0, 1e-8);
    EXPECT_NEAR(b.hi.z, 1.0, 1e-8);
}

TEST(OpenScadText, BoundsMatchOpenScadsMeshOfTheSameText) {
    expectTextBounds("L", "", 1.1393, 7.2627, 0.0, 9.55479);
    expectTextBounds("I", "", 1.28169, 2.57689, 0.0, 9.55479);
    expectTextBounds("O", "", 0.657791, 10.138, -0.13559, 9.69719);  // curves, flattened
    expectTextBounds("Lg", "", 1.1393, 14.3719, -2.88199, 9.55479);  // a descender
    expectTextBounds("AV", "", 0.0270996, 17.2422, 0.0, 9.55479);    // kerned by HarfBuzz
    expectTextBounds("LA", "spacing = 2", 1.1393, 24.3226, 0.0, 9.55479);
    expectTextBounds("L", "font = \"\"", 1.1393, 7.2627, 0.0, 9.55479);  // the default font
    expectTextBounds("L", "font = \"Liberation Sans\"", 1.1393, 7.2627, 0.0, 9.55479);
}

TEST(OpenScadText, AlignmentShiftsTheBoundsAsOpenScad) {
    expectTextBounds("L", "halign = \"center\", valign = \"center\"", -2.63232, 3.49106, -4.66562,
                     4.88916);
    expectTextBounds("L", "halign = \"right\", valign = \"top\"", -6.40396, -0.280548, -9.33124,
                     0.223541);
    expectTextBounds("L", "halign = \"left\", valign = \"bottom\"", 1.1393, 7.2627, 0.0, 9.55479);
    expectTextBounds("L", "valign = \"baseline\"", 1.1393, 7.2627, 0.0, 9.55479);
    expectTextBounds("L", "direction = \"ttb\"", -2.63228, 3.4911, -11.0269, -1.47205);
}

/// Whether a ray straight down through (x, y) meets the solid (brute force).
bool textHitAt(const Scene& s, double x, double y) {
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    auto acc = buildAccelerator(s, bp);
    NullObserver obs;
    TraceContext ctx(s.prims.size(), s.tree.depth());
    ctx.useMailboxes = false;
    ctx.beginRay();
    Hit h;
    Ray r;
    r.o = Vec3(x, y, 10.0);
    r.d = Vec3(0.0, 0.0, -1.0);
    return acc->intersect(r, 0.0, kInf, ctx, obs, h);
}

TEST(OpenScadText, GlyphsKeepTheirHoles) {
    // "O": its ring is hit, its counter is not; "A": the triangle above the bar is a hole.
    const Scene o = textCsg(extrudedText("O"));
    EXPECT_FALSE(textHitAt(o, 5.4, 4.8));
    EXPECT_TRUE(textHitAt(o, 1.2, 4.8));
    EXPECT_TRUE(textHitAt(o, 5.4, 0.3));
    EXPECT_FALSE(textHitAt(o, 5.4, 11.0));
    const Scene a = textCsg(extrudedText("A"));
    const Box3 ab = textBounds(a);
    const double cx = ab.center().x;
    EXPECT_FALSE(textHitAt(a, cx, 5.0));  // the counter
    EXPECT_TRUE(textHitAt(a, cx, 3.2));   // the bar
    EXPECT_TRUE(textHitAt(a, cx, 9.3));   // the apex
    // Also "B" with two counters and "8".
    const Scene b = textCsg(extrudedText("B"));
    EXPECT_FALSE(textHitAt(b, 4.0, 2.5));
    EXPECT_FALSE(textHitAt(b, 4.0, 7.0));
    EXPECT_TRUE(textHitAt(b, 1.8, 5.0));
}

TEST(OpenScadText, CurveSegmentsAsOpenScadCountsThem) {
    // floor(get_fragments_from_r(size, $fn, $fs, $fa) / 8) + 1, at least 2.
    EXPECT_EQ(openscad::textCurveSegments(10, 0, 12, 2), 4);   // min(360/12, 20 pi / 2) = 30
    EXPECT_EQ(openscad::textCurveSegments(10, 64, 12, 2), 9);  // $fn = 64
    EXPECT_EQ(openscad::textCurveSegments(1, 0, 12, 2), 2);    // 5 fragments
    EXPECT_EQ(openscad::textCurveSegments(10, 1, 12, 2), 2);   // $fn below 3 counts as 3
    // More segments, more vertices on the curves of "O"; the straight "L" keeps its own.
    openscad::TextParams p;
    p.text = "O";
    p.segments = 2;
    const auto coarse = openscad::layoutText(p);
    p.segments = 9;
    const auto fine = openscad::layoutText(p);
    ASSERT_EQ(coarse.glyphs.size(), 1u);
    ASSERT_EQ(fine.glyphs.size(), 1u);
    ASSERT_EQ(coarse.glyphs[0].size(), 2u);  // outer and inner contour
    EXPECT_GT(fine.glyphs[0][0].size(), 3 * coarse.glyphs[0][0].size() / 2);
}

TEST(OpenScadText, MissingFontFallsBackAsFontconfigDoes) {
    const Scene s = textCsg(extrudedText("L", "font = \"No Such Font Family\""));
    EXPECT_FALSE(s.prims.empty());
    openscad::TextParams p;
    p.text = "L";
    p.font = "Liberation Sans:style=Bold";
    const auto bold = openscad::layoutText(p);
    EXPECT_NE(bold.fontFile.find("Bold"), std::string::npos) << bold.fontFile;
    EXPECT_TRUE(textCsg(extrudedText(" ")).prims.empty());  // a space draws nothing
}

void expectTextError(const std::string& text, const std::string& message) {
    try {
        textCsg(text);
        ADD_FAILURE() << "no error for:\n" << text;
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()), message);
    }
}

TEST(OpenScadText, BadArgumentsNameFileLineAndColumn) {
    const std::string ex = "linear_extrude(height = 1) {\n  text(text = \"A\", ";
    expectTextError(ex + "size = 0); }", "mem.csg:2:27: 'size' of text() must be positive");
    expectTextError(ex + "size = -2); }", "mem.csg:2:27: 'size' of text() must be positive");
    expectTextError(ex + "halign = \"middle\"); }",
                    "mem.csg:2:29: unknown halign 'middle' of text() (expected left, center, "
                    "right)");
    expectTextError(ex + "valign = \"mid\"); }",
                    "mem.csg:2:29: unknown valign 'mid' of text() (expected top, center, "
                    "baseline, bottom)");
    expectTextError(
        ex + "direction = \"up\"); }",
        "mem.csg:2:32: unknown direction 'up' of text() (expected ltr, rtl, ttb, btt, )");
    expectTextError(ex + "font = 3); }", "mem.csg:2:27: expected a string for 'font' of text()");
    expectTextError(ex + "colour = 3); }",
                    "mem.csg:2:20: unknown argument 'colour' of text() (expected text, size, font, "
                    "direction, language, script, halign, valign, spacing)");
    // A 2D text beside solids is left out, as OpenSCAD's render does; alone it is refused.
    expectTextError("text(text = \"A\");",
                    "mem.csg:1:1: the model is 2D (its first 2D node is 'text') and has no solid: "
                    "Lancer traces solids; extrude the drawing with linear_extrude or "
                    "rotate_extrude to render it");
}

TEST(OpenScadText, SchemesAgreeWithBruteForceOnAnExtrudedWord) {
    // A word with holes and curves, turned and cut by a box, beside a centred second line.
    const Scene s = textCsg(
        "difference() { multmatrix([[0.8, -0.6, 0, 0], [0.6, 0.8, 0, 0], [0, 0, 1, 0], [0, 0, 0, "
        "1]]) { linear_extrude(height = 3, center = true, scale = [1, 1]) { text(text = "
        "\"Lancer!\", size = 10, spacing = 1, font = \"\", direction = \"ltr\", language = "
        "\"en\", script = \"Latn\", halign = \"center\", valign = \"center\", $fn = 0, $fa = 12, "
        "$fs = 2); } } cube(size = [8, 8, 8]); }\n"
        "translate([0, -14, 0]) linear_extrude(height = 2, scale = [0.8, 0.8]) { text(text = "
        "\"B8@\", size = 6, font = \"Liberation Serif:style=Bold\", halign = \"right\", $fn = "
        "32); }");
    ASSERT_FALSE(s.prims.empty());
    const std::vector<Ray> rays = test::randomRays(s, 11, 3000);
    test::expectEverySchemeSame(s, rays);
}

}  // namespace
}  // namespace lancer
