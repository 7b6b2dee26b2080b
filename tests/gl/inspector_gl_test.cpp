// The inspector drawn into an OSMesa context: a leaf's edges land where its corners project
// under the inspector's camera, the level range and the slice slab hide what they should, and
// the traced surfaces hide the lines behind them.
#include "tests/gl/offscreen_gl.h"
// (after the GL headers)
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <thread>

#include "app/viewer/camera_control.h"
#include "app/viewer/gl/transforms.h"
#include "app/viewer/inspector/inspector.h"

namespace lancer::viewer::inspector {
namespace {

using testing::OffscreenGl;

constexpr int kW = 640, kH = 360;

std::shared_ptr<const SceneBuild> regularBalls() {
    BuildRequest r;
    r.spec = "builtin:balls:2";
    r.params.scheme = SchemeKind::Regular;
    r.params.regular.maxLevel = 12;
    r.params.regular.maxObjects = 2;
    BuildResult b = buildStructure(r);
    if (!b.sceneBuild) throw std::runtime_error(b.error);
    return b.sceneBuild;
}

/// The inspector drawn alone (frustum, boxes and surfaces off unless asked).
struct Fixture {
    OffscreenGl gl{kW, kH};
    std::shared_ptr<const SceneBuild> st = regularBalls();
    std::unique_ptr<Inspector> insp;
    PixelRect v = Inspector::viewport(kW, kH);

    Fixture() {
        insp = std::make_unique<Inspector>();
        InspectorOptions& o = insp->options();
        o.show = true;
        o.frustum = false;
        o.surfaces = false;
        o.cap = 1 << 30;
    }
    std::vector<uint8_t> draw(int64_t selected = -1) {
        insp->changed();
        insp->update(st, {st->scene->camera, 64, 48}, kW, kH, selected);
        gl.clear(0.0f, 0.0f, 0.0f);
        insp->draw(kW, kH);
        return gl.read();
    }
    /// Where a world point lands in the framebuffer.
    glm::dvec2 toFb(const Vec3& p) const {
        std::optional<glm::dvec2> q =
            gl::ImageProjector(insp->camera(), v.x1 - v.x0, v.y1 - v.y0).toImage(p);
        return q ? *q + glm::dvec2(v.x0, v.y0) : glm::dvec2(-1e9);
    }
};

const uint8_t* pixel(const std::vector<uint8_t>& img, int x, int y) {
    return img.data() + (size_t(y) * kW + size_t(x)) * 4;
}

/// A line of some colour (not the background) within a pixel of (x, y).
bool lit(const std::vector<uint8_t>& img, glm::dvec2 p) {
    const int cx = int(std::floor(p.x)), cy = int(std::floor(p.y));
    for (int y = cy - 1; y <= cy + 1; ++y)
        for (int x = cx - 1; x <= cx + 1; ++x) {
            if (x < 0 || y < 0 || x >= kW || y >= kH) continue;
            const uint8_t* q = pixel(img, x, y);
            if (std::abs(int(q[0]) - 26) + std::abs(int(q[1]) - 26) + std::abs(int(q[2]) - 31) > 40)
                return true;
        }
    return false;
}

double segmentDistance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    const glm::dvec2 ab = b - a;
    const double l = glm::dot(ab, ab);
    const double t = l > 0.0 ? std::clamp(glm::dot(p - a, ab) / l, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

/// Midpoints of the edges of `corners`, in the framebuffer, inside the viewport with a margin.
std::vector<glm::dvec2> edgeMidpoints(const Fixture& f, const Corners& c) {
    std::vector<glm::dvec2> out;
    for (const auto& e : cornerEdges()) {
        const glm::dvec2 p = f.toFb(0.5 * (c[size_t(e[0])] + c[size_t(e[1])]));
        if (p.x > f.v.x0 + 3 && p.x < f.v.x1 - 3 && p.y > 3 && p.y < kH - 3) out.push_back(p);
    }
    return out;
}

/// Whether p lies within `margin` pixels of a line the model drew.
bool nearDrawnLine(const Fixture& f, glm::dvec2 p, double margin) {
    const auto& lines = f.insp->model().lines.lines;
    for (size_t i = 0; i + 1 < lines.size(); i += 2)
        if (segmentDistance(p, f.toFb(Vec3(lines[i].position)),
                            f.toFb(Vec3(lines[i + 1].position))) < margin)
            return true;
    return false;
}

TEST(InspectorGl, LeafDrawnWhereItsCornersProject) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    // One leaf drawn: the cap keeps the first in view.
    f.insp->options().cap = 1;
    std::vector<uint8_t> img = f.draw();
    ASSERT_EQ(f.insp->model().regions.size(), 1u);
    const RegionView& r = f.insp->model().regions[0];
    const std::vector<glm::dvec2> mids = edgeMidpoints(f, r.corners);
    ASSERT_GE(mids.size(), 8u);
    for (const glm::dvec2& p : mids) EXPECT_TRUE(lit(img, p)) << p.x << " " << p.y;
    // Off its edges, nothing: points a third of the way between two face diagonals' ends.
    int dark = 0;
    for (int a = 0; a < 8; ++a)
        for (int b = a + 1; b < 8; ++b) {
            const glm::dvec2 p =
                f.toFb(r.corners[size_t(a)] + (r.corners[size_t(b)] - r.corners[size_t(a)]) / 3.0);
            if (p.x < f.v.x0 + 3 || p.x > f.v.x1 - 3 || p.y < 3 || p.y > kH - 3) continue;
            if (nearDrawnLine(f, p, 3.0)) continue;
            EXPECT_FALSE(lit(img, p)) << p.x << " " << p.y;
            ++dark;
        }
    EXPECT_GT(dark, 3);
    // The left half of the window is not the inspector's.
    EXPECT_EQ(pixel(img, 10, 10)[0], 0);
}

/// Whether a line the model drew ends within `tol` of world point `p`.
bool lineEndsAt(const InspectorModel& m, const Vec3& p, double tol) {
    for (const gl::BatchVertex& v : m.lines.lines)
        if (glm::length(Vec3(v.position) - p) < tol) return true;
    return false;
}

TEST(InspectorGl, TheMainCameraRebuildsTheModelOnlyForItsFrustum) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    f.draw();
    // Without the frustum nothing drawn shows the main camera: turning it (a drag over the
    // image, `--orbit`) keeps the model as it was rather than building it again each frame.
    const gl::BatchVertex* before = f.insp->model().lines.lines.data();
    ASSERT_NE(before, nullptr);
    Camera turned = f.st->scene->camera;
    orbit(turned, 0.5, 0.0);
    f.insp->update(f.st, {turned, 64, 48}, kW, kH, -1);
    EXPECT_EQ(f.insp->model().lines.lines.data(), before);
    // With it, the frustum follows the main camera (its lines start at the eye), built apart:
    // the model is not built again.
    f.insp->options().frustum = true;
    f.insp->changed();
    f.insp->update(f.st, {turned, 64, 48}, kW, kH, -1);
    const double tol = 1e-4 * glm::length(turned.from - turned.at);
    InspectorModel frustum;
    frustum.lines = f.insp->frustum();
    EXPECT_TRUE(lineEndsAt(frustum, turned.from, tol));
    const uint64_t builds = f.insp->modelBuilds();
    orbit(turned, 0.5, 0.0);
    f.insp->update(f.st, {turned, 64, 48}, kW, kH, -1);
    frustum.lines = f.insp->frustum();
    EXPECT_TRUE(lineEndsAt(frustum, turned.from, tol));
    EXPECT_EQ(f.insp->modelBuilds(), builds) << "a turn of the main camera builds the frustum only";
    EXPECT_FALSE(lineEndsAt(f.insp->model(), turned.from, tol));
}

/// Draw `insp` into `f`'s framebuffer until it is settled (at most 100 draws), calling
/// `check(n)` after the n-th draw; returns the draws.
int drawUntilSettled(Fixture& f, Inspector& insp, const std::function<void(int)>& check) {
    int draws = 0;
    do {
        f.gl.clear(0.0f, 0.0f, 0.0f);
        insp.draw(kW, kH);
        check(++draws);
    } while (!insp.settled() && draws < 100);
    return draws;
}

TEST(InspectorGl, BuiltInTheBackgroundAndDrawnInPartsTheModelEndsAsTheDirectOne) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    const std::vector<uint8_t> direct = f.draw();
    const InspectorModel want = f.insp->model();
    ASSERT_FALSE(want.regions.empty());
    // The same inspector, its model built on a worker: not there at the update that asks for
    // it (the frame does not wait), then equal to the direct build.
    Inspector bg;
    bg.buildInBackground({});
    const size_t part = want.lines.lineCount() / 5 + 1;
    bg.drawInParts(part, 0.0);  // one part a draw
    bg.options() = f.insp->options();
    bg.changed();
    bg.update(f.st, {f.st->scene->camera, 64, 48}, kW, kH, -1);
    EXPECT_EQ(bg.modelBuilds(), 1u);
    EXPECT_FALSE(bg.settled()) << "not settled while the model is built";
    const auto start = std::chrono::steady_clock::now();
    while (bg.model().regions.empty() &&
           std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        bg.update(f.st, {f.st->scene->camera, 64, 48}, kW, kH, -1);
    }
    ASSERT_FALSE(bg.model().regions.empty());
    EXPECT_FALSE(bg.settled()) << "built, its picture not yet drawn";
    EXPECT_EQ(bg.modelBuilds(), 1u);
    ASSERT_EQ(bg.model().regions.size(), want.regions.size());
    for (size_t i = 0; i < want.regions.size(); ++i)
        EXPECT_EQ(bg.model().regions[i].id, want.regions[i].id);
    ASSERT_EQ(bg.model().lines.lines.size(), want.lines.lines.size());
    for (size_t i = 0; i < want.lines.lines.size(); ++i)
        ASSERT_EQ(bg.model().lines.lines[i].position, want.lines.lines[i].position) << i;
    // Its picture in parts, one a draw, the lines drawn so far always the first ones: whole
    // after five draws, the direct picture.
    const int draws = drawUntilSettled(f, bg, [&](int n) {
        EXPECT_EQ(bg.picturedLines(), std::min(size_t(n) * part, want.lines.lineCount()));
    });
    EXPECT_EQ(draws, 5);
    EXPECT_EQ(f.gl.read(), direct);
}

/// `parts` shows `f`'s model, drawn in parts of `lines` for `ms` a draw under `budget`,
/// keeping `reserveMs` of it; its framebuffer made at the view's size first if `sized`.
void startInParts(Inspector& parts, Fixture& f, size_t lines, double ms, FrameBudget& budget,
                  double reserveMs, bool sized = true) {
    parts.options() = f.insp->options();
    parts.drawInParts(lines, ms);
    if (!sized) {
        parts.setFrameBudget(&budget, reserveMs);
        parts.update(f.st, {f.st->scene->camera, 64, 48}, kW, kH, -1);
        return;
    }
    // Its framebuffer at the view's size first, in a draw with room for it (the tests here are
    // about the picture's pieces; a framebuffer of a new size is a step of its own before
    // them), on a clock that measures the picture's copy at its figure until measured.
    double setupNow = 0.0;
    FrameBudget setup(1e9, [&] { return setupNow += 5.0; });
    parts.setFrameBudget(&setup, 0.0);
    parts.update(f.st, {f.st->scene->camera, 64, 48}, kW, kH, -1);
    setup.begin();
    parts.draw(kW, kH);
    parts.setFrameBudget(&budget, reserveMs);
    parts.changed();
    parts.update(f.st, {f.st->scene->camera, 64, 48}, kW, kH, -1);
}

/// One frame of `parts` under `budget`, whose earlier steps took `spentMs` (`now`: the
/// budget's clock).
void budgetFrame(Fixture& f, Inspector& parts, FrameBudget& budget, double& now, double spentMs) {
    budget.begin();
    now += spentMs;
    f.gl.clear(0.0f, 0.0f, 0.0f);
    parts.draw(kW, kH);
}

TEST(InspectorGl, WithTheFramesBudgetSpentThePictureWaitsAndEndsAsTheDirectOne) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    const std::vector<uint8_t> direct = f.draw();
    const size_t lines = f.insp->model().lines.lineCount();
    ASSERT_GT(lines, 10u);
    // Parts of a fifth, as many a draw as the frame's budget allows; `now += 30` stands for
    // the frame's earlier steps (the clock moves 6 ms a reading otherwise).
    double now = 0.0;
    FrameBudget budget(33.0, [&] { return now += 6.0; });
    Inspector parts;
    startInParts(parts, f, lines / 5 + 1, 1e9, budget, 8.0);
    // Spent before it: nothing drawn (the window shows what it had), the picture pending.
    budgetFrame(f, parts, budget, now, 30.0);
    EXPECT_EQ(parts.picturedLines(), 0u);
    EXPECT_TRUE(parts.picturePending());
    EXPECT_FALSE(parts.settled());
    EXPECT_GE(budget.deferred(), 1);
    // Frames with room, every other one spent: a few parts a frame, then the direct picture.
    int frames = 0;
    size_t before = 0;
    do {
        budgetFrame(f, parts, budget, now, frames % 2 == 1 ? 30.0 : 0.0);
        if (frames % 2 == 1) {
            EXPECT_EQ(parts.picturedLines(), before) << "frame " << frames;
        } else {
            EXPECT_GT(parts.picturedLines(), before) << "frame " << frames;
            EXPECT_TRUE(frames > 0 || parts.picturedLines() < lines) << "not whole in one frame";
        }
        before = parts.picturedLines();
        ++frames;
    } while (!parts.settled() && frames < 100);
    EXPECT_TRUE(parts.settled());
    EXPECT_FALSE(parts.picturePending());
    EXPECT_EQ(parts.picturedLines(), lines);
    EXPECT_EQ(f.gl.read(), direct);
}

/// A fixture's model drawn in parts of a 15th of its lines, one a draw, under a budget of 33
/// ms keeping 5, on a clock only the test moves (`now`): every piece and copy measured costs
/// nothing, so the learned costs shrink a quarter at each measure.
struct FrozenClockParts {
    /// `sized`: the picture's framebuffer made at the view's size before the first frame.
    explicit FrozenClockParts(bool sized = true) {
        if (!f.gl.ok()) return;
        direct = f.draw();
        lines = f.insp->model().lines.lineCount();
        startInParts(parts, f, lines / 15 + 1, 0.0, budget, 5.0, sized);
    }
    /// One frame whose earlier steps took `spentMs`.
    void frame(double spentMs) { budgetFrame(f, parts, budget, now, spentMs); }
    Fixture f;
    std::vector<uint8_t> direct;  ///< the picture drawn at once
    size_t lines = 0;             ///< of the model
    double now = 0.0;
    FrameBudget budget{33.0, [this] { return now; }};
    Inspector parts;
};

TEST(InspectorGl, APieceStartsOnlyWhenItsLearnedCostFitsInWhatTheBudgetLeaves) {
    FrozenClockParts t;
    ASSERT_TRUE(t.f.gl.ok());
    ASSERT_GT(t.lines, 30u);
    // 1 ms left beyond the reserve: some budget is left, but not a new picture's first piece
    // (its clear, 2 ms, and a part of lines, 4 ms, until measured): nothing drawn.
    t.frame(27.0);
    EXPECT_EQ(t.parts.picturedLines(), 0u);
    EXPECT_TRUE(t.parts.picturePending());
    EXPECT_GE(t.budget.deferred(), 1);
    // Frames with room and frames with 1 ms left, in turn: a part costs 4 ms until measured,
    // then a quarter less each time (4 x 0.75^5 < 1 after five parts); frames with 1 ms left
    // draw nothing until then, a part after.
    int frames = 0, tightDeferred = 0, tightDrawn = 0;
    do {
        const bool tight = frames % 2 == 1;
        const size_t before = t.parts.picturedLines();
        t.frame(tight ? 27.0 : 0.0);
        if (!tight) {
            EXPECT_GT(t.parts.picturedLines(), before) << "frame " << frames;
        } else if (t.parts.picturedLines() == before) {
            ++tightDeferred;
            EXPECT_EQ(tightDrawn, 0) << "once learned cheap, a part fits in 1 ms";
        } else {
            ++tightDrawn;
        }
        ++frames;
    } while (!t.parts.settled() && frames < 100);
    EXPECT_GE(tightDeferred, 3) << "4, 3 and 2.25 ms do not fit in 1";
    EXPECT_GE(tightDrawn, 1);
    EXPECT_TRUE(t.parts.settled());
    EXPECT_EQ(t.parts.picturedLines(), t.lines);
    EXPECT_EQ(t.f.gl.read(), t.direct);
}

// The picture's copy to the window follows its pieces in every draw: its learned cost is kept
// back beside the reserve given, so a piece that fits in what the reserve leaves still waits
// when the copy after it would not fit.
TEST(InspectorGl, APieceWaitsWhenThePicturesCopyToTheWindowWouldNotFitAfterIt) {
    FrozenClockParts t;
    ASSERT_TRUE(t.f.gl.ok());
    ASSERT_GT(t.lines, 30u);
    EXPECT_DOUBLE_EQ(t.parts.showEstimateMs(), 5.0) << "the copy's figure until measured";
    // 20 ms spent: 8 left beyond the reserve, room for a new picture's first piece (its clear,
    // 2 ms, and a part of lines, 4 ms) but not for the copy after it too (5 ms): nothing drawn.
    t.frame(20.0);
    EXPECT_EQ(t.parts.picturedLines(), 0u);
    EXPECT_TRUE(t.parts.picturePending());
    EXPECT_GE(t.budget.deferred(), 1);
    EXPECT_LT(t.parts.showEstimateMs(), 5.0) << "the copy is measured in each draw";
    // The same frames: the copy, learned cheaper at each draw, would fit beside the first
    // piece from the fifth frame (5 x 0.75^n + 6 <= 8 from n = 4), but the picture waits
    // kPatienceFrames frames at most and then starts whatever the budget; it is completed and
    // ends as the direct one.
    int frames = 0, waited = 1;
    do {
        const size_t before = t.parts.picturedLines();
        const double copyMs = t.parts.showEstimateMs();
        t.frame(20.0);
        if (t.parts.picturedLines() == before && t.parts.picturedLines() == 0) {
            ++waited;
            EXPECT_GT(copyMs + 6.0, 8.0) << "frame " << frames << ": the piece and the copy fit";
        }
        ++frames;
    } while (!t.parts.settled() && frames < 100);
    EXPECT_EQ(waited, int(kPatienceFrames)) << "the deferred picture starts after its patience";
    EXPECT_TRUE(t.parts.settled());
    EXPECT_EQ(t.parts.picturedLines(), t.lines);
    EXPECT_EQ(t.f.gl.read(), t.direct);
}

// A framebuffer of a new size is made before the picture's first piece, its colour and its
// depth storage each in a draw of its own and each only when its learned cost fits (after
// kPatienceFrames draws of waiting whatever the budget), beside the picture on screen; the
// first piece starts in a later draw. Made with the clear and the first piece in one draw,
// balls4's inspector at 1280x720 took 21.6 ms more than that piece's estimate (2026-12-07).
TEST(InspectorGl, AFramebufferOfANewSizeIsMadeInItsOwnDrawsBeforeThePicture) {
    FrozenClockParts t(false);
    ASSERT_TRUE(t.f.gl.ok());
    ASSERT_GT(t.lines, 30u);
    Inspector& parts = t.parts;
    const PixelRect v = parts.area(kW, kH);
    const std::pair<int, int> size(v.x1 - v.x0, v.y1 - v.y0);
    ASSERT_NE(parts.framebufferSize(), size);
    // With room: the two storages in the first draw (each learned at no cost on this clock
    // fits), nothing of the picture; its first piece in the next.
    t.frame(0.0);
    EXPECT_EQ(parts.framebufferSize(), size);
    EXPECT_EQ(parts.picturedLines(), 0u) << "no piece with the framebuffer";
    EXPECT_TRUE(parts.picturePending());
    t.frame(0.0);
    EXPECT_GT(parts.picturedLines(), 0u);

    // A new size in frames with 1 ms left beyond the reserve, less than the picture's copy
    // after it (5 ms until measured): no storage fits, so the colour waits its patience and is
    // let in, the depth waits its own patience in the draws after, and the first piece after
    // that.
    Inspector tight;
    FrameBudget room(33.0, [&] { return t.now; });
    startInParts(tight, t.f, t.lines / 15 + 1, 0.0, room, 5.0, false);
    int sized = -1, drawn = -1, forced = 0;
    for (int draw = 1; draw <= 40 && !tight.settled(); ++draw) {
        budgetFrame(t.f, tight, room, t.now, 27.0);
        for (const FrameBudget::Forced& s : room.forcedSteps())
            forced += std::string(s.step) == "the inspector's framebuffer of a new size";
        if (sized < 0 && tight.framebufferSize() == size) sized = draw;
        if (drawn < 0 && tight.picturedLines() > 0) drawn = draw;
    }
    const int kWait = int(kPatienceFrames) + 1;  // a part let in every kWait draws
    EXPECT_EQ(forced, 2) << "colour and depth, each let in after its patience";
    EXPECT_EQ(sized, 2 * kWait) << "colour at draw " << kWait << ", depth " << kWait << " later";
    EXPECT_GT(drawn, sized) << "the first piece after the framebuffer";
    EXPECT_TRUE(tight.settled());
    EXPECT_EQ(tight.picturedLines(), t.lines);
    EXPECT_EQ(t.f.gl.read(), t.direct);
}

TEST(InspectorGl, WithItsSurfacesThePictureInPartsEqualsTheOneDrawnAtOnce) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    f.insp->options().surfaces = true;
    f.insp->changed();
    f.insp->update(f.st, {f.st->scene->camera, 64, 48}, kW, kH, -1);
    ASSERT_TRUE(f.insp->waitSurfaces(60000));
    const std::vector<uint8_t> direct = f.draw();
    // Drawn in parts, one a draw: the surfaces in bands of a 24th of the rows (rounded up),
    // then the lines in two parts.
    Inspector parts;
    parts.options() = f.insp->options();
    parts.drawInParts(f.insp->model().lines.lineCount() / 2 + 1, 0.0);
    parts.changed();
    parts.update(f.st, {f.st->scene->camera, 64, 48}, kW, kH, -1);
    ASSERT_TRUE(parts.waitSurfaces(60000));
    int surfaceDraws = 0;
    const int draws = drawUntilSettled(f, parts, [&](int n) {
        if (parts.picturedLines() == 0) {
            EXPECT_EQ(surfaceDraws, n - 1) << "surfaces first";
            surfaceDraws = n;
        }
    });
    EXPECT_GE(surfaceDraws, 20) << "narrow bands";
    EXPECT_LE(surfaceDraws, 24);
    EXPECT_EQ(draws, surfaceDraws + 2);
    EXPECT_EQ(f.gl.read(), direct);
}

TEST(InspectorGl, LevelRangeHidesTheOtherLevels) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    f.draw();
    const int top = f.insp->model().maxLevel;
    ASSERT_GE(top, 4);
    f.insp->options().levelLo = top - 3;
    f.insp->options().levelHi = top - 2;
    std::vector<uint8_t> img = f.draw();
    StructureView view(*f.st->scene, *f.st->accel);
    int shown = 0, hidden = 0;
    for (uint32_t id = 0; id < view.regionCount(); ++id) {
        const bool kept = inLevelRange(view.leafLevel(id), top - 3, top - 2);
        for (const glm::dvec2& p : edgeMidpoints(f, view.regionCorners(id))) {
            if (kept) {
                EXPECT_TRUE(lit(img, p)) << view.toString(id);
                ++shown;
            } else if (!nearDrawnLine(f, p, 3.0)) {
                EXPECT_FALSE(lit(img, p)) << view.toString(id);
                ++hidden;
            }
        }
    }
    EXPECT_GT(shown, 20);
    EXPECT_GT(hidden, 20);
}

TEST(InspectorGl, SliceSlabKeepsOnlyTheCrossingCells) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    f.draw();
    StructureView view(*f.st->scene, *f.st->accel);
    const Box3 b = view.worldBounds();
    Slab& s = f.insp->options().slab;
    s.on = true;
    s.axis = 0;
    s.lo = b.lo.x + 0.42 * b.extent().x;
    s.hi = b.lo.x + 0.47 * b.extent().x;
    std::vector<uint8_t> img = f.draw();
    int shown = 0, hidden = 0;
    for (uint32_t id = 0; id < view.regionCount(); ++id) {
        const Corners c = view.regionCorners(id);
        const bool crosses = s.keeps(c);
        for (const glm::dvec2& p : edgeMidpoints(f, c)) {
            if (crosses) {
                EXPECT_TRUE(lit(img, p)) << view.toString(id);
                ++shown;
            } else if (!nearDrawnLine(f, p, 3.0)) {
                EXPECT_FALSE(lit(img, p)) << view.toString(id);
                ++hidden;
            }
        }
    }
    EXPECT_GT(shown, 20);
    EXPECT_GT(hidden, 20);
}

TEST(InspectorGl, SelectionDrawnInGreenOverEverything) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    f.insp->options().surfaces = true;
    f.draw();
    ASSERT_TRUE(f.insp->waitSurfaces(20000));
    // A leaf picked at the viewport's centre, then drawn as the selection.
    const int64_t id = f.insp->pick(0.5 * (f.v.x1 - f.v.x0), 0.5 * (f.v.y1 - f.v.y0));
    ASSERT_GE(id, 0);
    std::vector<uint8_t> img = f.draw(id);
    ASSERT_TRUE(f.insp->surfacesShown());
    StructureView view(*f.st->scene, *f.st->accel);
    const glm::vec3 green = kSelectionColor * 255.0f;
    int checked = 0;
    for (const glm::dvec2& p : edgeMidpoints(f, view.regionCorners(uint32_t(id)))) {
        bool found = false;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const uint8_t* q = pixel(img, int(p.x) + dx, int(p.y) + dy);
                found |= std::abs(q[0] - green.x) < 10 && std::abs(q[1] - green.y) < 10 &&
                         std::abs(q[2] - green.z) < 10;
            }
        EXPECT_TRUE(found) << p.x << " " << p.y;
        ++checked;
    }
    EXPECT_GE(checked, 6);
}

TEST(InspectorGl, SurfacesHideTheLinesBehindThem) {
    Fixture f;
    ASSERT_TRUE(f.gl.ok());
    InspectorOptions& o = f.insp->options();
    o.regions = false;
    o.boxes = true;
    o.surfaces = true;
    // The largest sphere of balls (the root of the flake) and its minimized box, seen closely:
    // the box's edges in front of the sphere show, those behind it (inside its silhouette) do
    // not.
    const Scene& scene = *f.st->scene;
    int big = -1;
    for (uint32_t i = 0; i < scene.minBox.size(); ++i) {
        const Vec3 e = scene.minBox[i].extent();
        if (scene.minBox[i].isEmpty() || std::abs(e.z - e.x) > 1e-6 * e.x) continue;  // not a ball
        if (big < 0 || e.x > scene.minBox[size_t(big)].extent().x) big = int(i);
    }
    ASSERT_GE(big, 0);
    const Box3 box = scene.minBox[size_t(big)];
    f.draw();
    f.insp->setCamera(frameBox(box, Vec3(-0.6, 1.0, -0.5), 40.0));
    f.draw();
    ASSERT_TRUE(f.insp->waitSurfaces(20000));
    std::vector<uint8_t> img = f.draw();
    ASSERT_TRUE(f.insp->surfacesShown());
    const Vec3 centre = box.center();
    const double radius = 0.5 * box.extent().x;
    const glm::dvec2 c2 = f.toFb(centre);
    // The silhouette's radius on screen, from a point on the sphere seen side-on.
    Vec3 fwd, right, up;
    f.insp->camera().basis(fwd, right, up);
    const double r2 = glm::length(f.toFb(centre + radius * right) - c2);
    const gl::ImageProjector proj(f.insp->camera(), f.v.x1 - f.v.x0, f.v.y1 - f.v.y0);
    const glm::vec3 boxColor = kBoxColor * 255.0f;
    auto isBoxColor = [&](glm::dvec2 p) {
        const uint8_t* q = pixel(img, int(p.x), int(p.y));
        return std::abs(q[0] - boxColor.x) < 12 && std::abs(q[1] - boxColor.y) < 12 &&
               std::abs(q[2] - boxColor.z) < 12;
    };
    // Other boxes' edges may pass over the sphere in front of it.
    auto nearOtherBox = [&](glm::dvec2 q) {
        for (uint32_t i = 0; i < scene.minBox.size(); ++i) {
            if (int(i) == big || scene.minBox[i].isEmpty()) continue;
            const Corners o = boxCorners(scene.minBox[i]);
            for (const auto& e : cornerEdges())
                if (segmentDistance(q, f.toFb(o[size_t(e[0])]), f.toFb(o[size_t(e[1])])) < 3.0)
                    return true;
        }
        return false;
    };
    int front = 0, behind = 0;
    const Corners c = boxCorners(box);
    for (const auto& e : cornerEdges())
        for (double t : {0.35, 0.5, 0.65}) {
            const Vec3 p = c[size_t(e[0])] + t * (c[size_t(e[1])] - c[size_t(e[0])]);
            const glm::dvec2 q = f.toFb(p);
            if (glm::length(q - c2) > 0.75 * r2) continue;  // not over the sphere
            if (proj.depth(p) < proj.depth(centre) - 0.5 * radius) {
                EXPECT_TRUE(isBoxColor(q)) << "front " << q.x << " " << q.y;
                ++front;
            } else if (proj.depth(p) > proj.depth(centre) + 0.5 * radius && !nearOtherBox(q)) {
                EXPECT_FALSE(isBoxColor(q)) << "behind " << q.x << " " << q.y;
                ++behind;
            }
        }
    EXPECT_GT(behind, 0);
    EXPECT_GT(front, 0);
    // The sphere itself shows at its centre.
    EXPECT_TRUE(lit(img, c2));
}

}  // namespace
}  // namespace lancer::viewer::inspector
