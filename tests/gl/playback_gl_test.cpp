// The ray playback's drawing (app/viewer/playback/ray_drawing.h) in OSMesa: the region
// highlighted at step k, and the minimized boxes of the primitives tested there, are drawn where
// their 8 corners project with the camera, and nowhere else, for both schemes.
#include <gtest/gtest.h>

#include "app/viewer/gl/batch.h"
#include "app/viewer/gl/transforms.h"
#include "app/viewer/playback/ray_drawing.h"
#include "engine/scene/loader.h"
#include "offscreen_gl.h"

namespace lancer::viewer {
namespace {

double distanceToSegment(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

class PlaybackGl : public ::testing::TestWithParam<SchemeKind> {};

gl::Rgba8 pixelAt(const std::vector<uint8_t>& px, int w, int x, int y) {
    const uint8_t* p = &px[(size_t(y) * size_t(w) + size_t(x)) * 4];
    return gl::Rgba8(p[0]) | gl::Rgba8(p[1]) << 8 | gl::Rgba8(p[2]) << 16 | gl::Rgba8(p[3]) << 24;
}

/// Projected edges, in image pixels.
using ImageEdges = std::vector<std::pair<glm::dvec2, glm::dvec2>>;

/// The pixels of colour `want`, and how many of them lie farther than 1.5 px from every edge.
std::pair<int, int> litAndStray(const std::vector<uint8_t>& px, int w, int h, gl::Rgba8 want,
                                const ImageEdges& edges) {
    int lit = 0, stray = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (pixelAt(px, w, x, y) != want) continue;
            ++lit;
            double d = 1e30;
            for (const auto& [a, b] : edges)
                d = std::min(d, distanceToSegment({x + 0.5, y + 0.5}, a, b));
            if (d > 1.5) ++stray;
        }
    return {lit, stray};
}

/// Points along the edges inside the image, and how many of them have no pixel within one of a
/// colour of `accept` (compared on RGB).
std::pair<int, int> edgePointsMissed(const std::vector<uint8_t>& px, int w, int h,
                                     const ImageEdges& edges,
                                     std::initializer_list<gl::Rgba8> accept) {
    int onEdges = 0, missed = 0;
    for (const auto& [a, b] : edges)
        for (double s = 0.05; s < 1.0; s += 0.1) {
            const glm::dvec2 q = a + s * (b - a);
            if (q.x < 2 || q.y < 2 || q.x > w - 2 || q.y > h - 2) continue;
            ++onEdges;
            bool hit = false;
            for (int dy = -1; dy <= 1 && !hit; ++dy)
                for (int dx = -1; dx <= 1 && !hit; ++dx) {
                    const gl::Rgba8 got = pixelAt(px, w, int(q.x) + dx, int(q.y) + dy);
                    for (gl::Rgba8 c : accept) hit = hit || (got & 0xffffff) == (c & 0xffffff);
                }
            if (!hit) ++missed;
        }
    return {onEdges, missed};
}

TEST_P(PlaybackGl, RegionAtStepKIsDrawnWhereItsCornersProject) {
    const int w = 160, h = 120;
    testing::OffscreenGl ctx(w, h);
    ASSERT_TRUE(ctx.ok());
    Scene scene = loadScene("builtin:default");
    BuildParams params;
    params.scheme = GetParam();
    auto accel = buildAccelerator(scene, params);
    const StructureView view(scene, *accel);
    ShadingOptions sh;

    // A pixel whose primary ray walks a region lying wholly in front of the eye, after its
    // first step when it has several (GL clips what crosses the eye's plane; the
    // CPU projection below does not).
    const gl::ImageProjector proj(scene.camera, w, h);
    const Box3 bounds = view.worldBounds();
    const double eps = 1e-3 * glm::length(bounds.hi - bounds.lo);
    playback::RayPlayback play;
    std::optional<std::array<Vec3, 8>> corners;
    for (int y = 8; y < h && !corners; y += 16)
        for (int x = 8; x < w && !corners; x += 16) {
            RayTree t = tracePixel(scene, *accel, sh, scene.camera, x, y, w, h);
            if (t.rays[0].regionSteps().empty()) continue;
            play.setTree({x, y, w, h}, std::move(t));
            for (int k = play.stepCount() > 1 ? 1 : 0; k < play.stepCount() && !corners; ++k) {
                play.seek(k);
                std::optional<std::array<Vec3, 8>> c = playback::currentCorners(play, view);
                bool inFront = c.has_value();
                for (int i = 0; inFront && i < 8; ++i) inFront = proj.depth((*c)[size_t(i)]) >= eps;
                if (inFront) corners = c;
            }
        }
    ASSERT_TRUE(corners) << "no region wholly in front of the eye";

    // Only the region's edges, so every pixel of its colour must lie on one of them.
    gl::Batch region;
    std::array<glm::vec3, 8> cf;
    for (int i = 0; i < 8; ++i) cf[size_t(i)] = glm::vec3((*corners)[size_t(i)]);
    region.box(cf, gl::rgba8(playback::kRegionColor));
    // The same edges as rayBatch draws them (its first box).
    const gl::Batch full = playback::rayBatch(play, view);
    ASSERT_GE(full.lines.size(), region.lines.size());
    bool found = false;
    for (size_t i = 0; i + region.lines.size() <= full.lines.size() && !found; i += 2) {
        bool same = true;
        for (size_t j = 0; j < region.lines.size() && same; ++j)
            same = full.lines[i + j].position == region.lines[j].position &&
                   full.lines[i + j].color == region.lines[j].color;
        found = same;
    }
    EXPECT_TRUE(found) << "rayBatch does not draw the region's 12 edges";

    gl::BatchRenderer renderer;
    ctx.clear(0.0f, 0.0f, 0.0f);
    renderer.drawNow(region, playback::imageClipMatrix(scene.camera, w, h, play, view));
    const std::vector<uint8_t> px = ctx.read();

    // The edges projected on the CPU.
    ImageEdges edges;
    for (int c = 0; c < 8; ++c)
        for (int bit : {1, 2, 4})
            if (!(c & bit)) {
                std::optional<glm::dvec2> a = proj.toImage((*corners)[size_t(c)]);
                std::optional<glm::dvec2> b = proj.toImage((*corners)[size_t(c | bit)]);
                if (a && b) edges.emplace_back(*a, *b);
            }
    ASSERT_FALSE(edges.empty());
    const gl::Rgba8 want = gl::rgba8(playback::kRegionColor);
    const auto [lit, stray] = litAndStray(px, w, h, want, edges);
    EXPECT_GT(lit, 10);
    EXPECT_EQ(stray, 0) << "of " << lit << " pixels of the region's colour";

    // And every projected edge point inside the image is lit (within a pixel).
    const auto [onEdges, missed] = edgePointsMissed(px, w, h, edges, {want});
    EXPECT_GT(onEdges, 5);
    EXPECT_EQ(missed, 0) << "of " << onEdges << " points on the projected edges";
}

TEST_P(PlaybackGl, TestedPrimitivesBoxesAreDrawnWhereTheirCornersProject) {
    const int w = 160, h = 120;
    testing::OffscreenGl ctx(w, h);
    ASSERT_TRUE(ctx.ok());
    Scene scene = loadScene("builtin:default");
    BuildParams params;
    params.scheme = GetParam();
    auto accel = buildAccelerator(scene, params);
    const StructureView view(scene, *accel);
    ShadingOptions sh;
    const gl::ImageProjector proj(scene.camera, w, h);
    const Box3 bounds = view.worldBounds();
    const double eps = 1e-3 * glm::length(bounds.hi - bounds.lo);
    auto inFront = [&](const Box3& b) {
        for (int c = 0; c < 8; ++c) {
            const Vec3 p(c & 1 ? b.hi.x : b.lo.x, c & 2 ? b.hi.y : b.lo.y, c & 4 ? b.hi.z : b.lo.z);
            if (proj.depth(p) < eps) return false;
        }
        return true;
    };

    // A step that tests primitives (not only mailbox reads) whose boxes all lie in front of the
    // eye, after the first step when the ray has several.
    playback::RayPlayback play;
    std::vector<playback::TestedBox> boxes;
    for (int y = 8; y < h && boxes.empty(); y += 16)
        for (int x = 8; x < w && boxes.empty(); x += 16) {
            RayTree t = tracePixel(scene, *accel, sh, scene.camera, x, y, w, h);
            if (t.rays[0].regionSteps().empty()) continue;
            play.setTree({x, y, w, h}, std::move(t));
            for (int k = play.stepCount() - 1; k >= 0 && boxes.empty(); --k) {
                play.seek(k);
                std::vector<playback::TestedBox> b = playback::testedBoxes(play, scene);
                const bool tested =
                    std::any_of(b.begin(), b.end(), [](const auto& t) { return !t.mailbox; });
                const bool front =
                    std::all_of(b.begin(), b.end(), [&](const auto& t) { return inFront(t.box); });
                if (tested && front) boxes = b;
            }
        }
    ASSERT_FALSE(boxes.empty()) << "no step testing primitives in front of the eye";
    for (const playback::TestedBox& b : boxes) {
        ASSERT_LT(b.prim, scene.minBox.size());
        EXPECT_EQ(b.box.lo, scene.minBox[b.prim].lo);
        EXPECT_EQ(b.box.hi, scene.minBox[b.prim].hi);
    }

    // rayBatch draws them (in their colours), and drawn alone they land on their edges.
    const gl::Batch only = playback::testedBoxesBatch(play, view);
    ASSERT_EQ(only.lines.size(), boxes.size() * 24);
    const gl::Batch full = playback::rayBatch(play, view);
    size_t inFull = 0;
    for (const gl::BatchVertex& v : full.lines)
        inFull += v.color == gl::rgba8(playback::kTestedColor) ||
                  v.color == gl::rgba8(playback::kMailboxColor);
    EXPECT_EQ(inFull, only.lines.size());

    gl::BatchRenderer renderer;
    ctx.clear(0.0f, 0.0f, 0.0f);
    renderer.drawNow(only, playback::imageClipMatrix(scene.camera, w, h, play, view));
    const std::vector<uint8_t> px = ctx.read();

    // Each box's edges projected on the CPU, tested ones apart.
    ImageEdges tested, all;
    for (const playback::TestedBox& b : boxes)
        for (int c = 0; c < 8; ++c)
            for (int bit : {1, 2, 4})
                if (!(c & bit)) {
                    auto corner = [&](int i) {
                        return Vec3(i & 1 ? b.box.hi.x : b.box.lo.x,
                                    i & 2 ? b.box.hi.y : b.box.lo.y,
                                    i & 4 ? b.box.hi.z : b.box.lo.z);
                    };
                    std::optional<glm::dvec2> p = proj.toImage(corner(c));
                    std::optional<glm::dvec2> q = proj.toImage(corner(c | bit));
                    if (!p || !q) continue;
                    all.emplace_back(*p, *q);
                    if (!b.mailbox) tested.emplace_back(*p, *q);
                }
    ASSERT_FALSE(tested.empty());
    const gl::Rgba8 testedColor = gl::rgba8(playback::kTestedColor);
    const gl::Rgba8 mailColor = gl::rgba8(playback::kMailboxColor);
    const auto [lit, stray] = litAndStray(px, w, h, testedColor, tested);
    EXPECT_GT(lit, 10);
    EXPECT_EQ(stray, 0) << "of " << lit << " pixels of the tested colour";
    // Every point of a tested box's projected edges inside the image is lit by a box (a
    // mailbox box drawn later may cover it).
    const auto [onEdges, missed] = edgePointsMissed(px, w, h, tested, {testedColor, mailColor});
    EXPECT_GT(onEdges, 5);
    EXPECT_EQ(missed, 0) << "of " << onEdges << " points on the projected edges";
}

INSTANTIATE_TEST_SUITE_P(Schemes, PlaybackGl,
                         ::testing::Values(SchemeKind::Regular, SchemeKind::Irregular),
                         [](const auto& info) { return std::string(schemeName(info.param)); });

}  // namespace
}  // namespace lancer::viewer
