// The overlays over the image (app/viewer/overlay/), drawn into an OSMesa context: the screen
// BSP's cut lines on the projected box edges, the selection highlighted where its corners
// project, the level range, a rebuild at another max-level, and the --show list.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>

#include "app/viewer/gl/transforms.h"
#include "app/viewer/image_view.h"
#include "app/viewer/overlay/overlays.h"
#include "engine/accel/irregular/irregular.h"
#include "engine/accel/regular/regular_grid.h"
#include "tests/gl/line_cover.h"
#include "tests/gl/offscreen_gl.h"

namespace lancer::viewer::overlay {
namespace {

using viewer::testing::OffscreenGl;

constexpr int kW = 100, kH = 100;

/// The union of the scene's primitives, prepared, seen from +z by an orthographic camera of 10
/// pixels a unit centred on the origin, in a kW x kH image.
void unionSeenFromAbove(Scene& scene) {
    std::vector<int> leaves;
    for (uint32_t i = 0; i < scene.prims.size(); ++i) leaves.push_back(scene.tree.leaf(i));
    scene.tree.root = scene.tree.balanced(Op::Union, leaves);
    scene.camera.from = {0.0, 0.0, 10.0};
    scene.camera.at = {0.0, 0.0, 0.0};
    scene.camera.up = {0.0, 1.0, 0.0};
    scene.camera.projection = Projection::Orthographic;
    scene.camera.orthoHeight = 10.0;
    scene.width = kW;
    scene.height = kH;
    scene.prepare();
}

/// Two blocks (the irregular BSP cut while a zone holds any primitive: maxObjects 0) seen from +z
/// by an orthographic camera, 10 pixels a unit, whose x and y faces project half a pixel off the
/// pixel grid, onto pixel centres: x = -2.95 is column 20, and so on (columns 20, 40, 60, 80; rows
/// 29, 39, 59, 69).
std::shared_ptr<SceneBuild> twoBoxes(SchemeKind scheme, int maxLevel = 24) {
    auto scene = std::make_shared<Scene>();
    scene->prims.push_back(makePrimitive(Block{{-2.95, -1.95, -1.0}, {-0.95, 1.05, 1.0}}, {}));
    scene->prims.push_back(makePrimitive(Block{{1.05, -0.95, -0.5}, {3.05, 2.05, 0.5}}, {}));
    if (scheme == SchemeKind::Regular) {
        // The regular scheme stops at one primitive a cell: small blocks around make its BSP
        // cut to several levels.
        for (const Vec3& c : {Vec3(-4.0, 3.0, 0.0), Vec3(0.2, -4.0, 0.3), Vec3(4.1, -3.2, -0.2),
                              Vec3(0.1, 3.6, 0.0), Vec3(-4.2, -3.9, 0.1)})
            scene->prims.push_back(makePrimitive(Block{c - 0.4, c + 0.4}, {}));
    }
    unionSeenFromAbove(*scene);
    BuildParams p;
    p.scheme = scheme;
    p.regular.maxLevel = maxLevel;
    p.regular.maxObjects = 1;
    p.irregular.maxObjects = 0;
    auto s = std::make_shared<SceneBuild>();
    s->spec = "two boxes";
    s->scene = scene;
    s->accel = buildAccelerator(*scene, p);
    return s;
}

/// The twelve edges of every leaf of levels [lo, hi], coloured by their absolute level (the
/// fixed palette the key shows): what the merged wireframe must cover, point for point.
gl::Batch leafEdges(const StructureView& sv, int lo = 0, int hi = 64) {
    gl::Batch b;
    for (uint32_t i = 0; i < sv.regionCount(); ++i) {
        const int level = sv.leafLevel(i);
        if (level < lo || level > hi) continue;
        const std::array<Vec3, 8> c = sv.regionCorners(i);
        std::array<glm::vec3, 8> f;
        for (size_t k = 0; k < 8; ++k) f[k] = glm::vec3(c[k]);
        b.box(f, gl::rgba8(levelColor(level)));
    }
    return b;
}

/// The same for the directory grid's blocks of levels [lo, hi], coloured by kind: the sub-tables
/// or the single entries.
gl::Batch blockEdges(const StructureView& sv, int lo, int hi, bool subTables) {
    const Box3 box = sv.worldBounds();
    gl::Batch b;
    for (const DirectoryBlock& blk : sv.directoryBlocks()) {
        if (blk.level < lo || blk.level > hi || blk.subTable != subTables) continue;
        glm::vec3 a, z;
        for (int k = 0; k < 3; ++k) {
            const double cell = (box.hi[k] - box.lo[k]) / double(1u << sv.directoryLog2(k));
            a[k] = float(box.lo[k] + cell * blk.lo[k]);
            z[k] = float(box.lo[k] + cell * blk.hi[k]);
        }
        b.box(
            a, z,
            gl::rgba8(blk.subTable ? glm::vec3(1.0f, 0.55f, 0.1f) : glm::vec3(0.55f, 0.65f, 0.8f)));
    }
    return b;
}

bool lit(const std::vector<uint8_t>& px, int x, int y) {
    const uint8_t* p = &px[(size_t(y) * kW + size_t(x)) * 4];
    return p[0] > 20 || p[1] > 20 || p[2] > 20;
}

TEST(Overlays, BspCutLinesFallOnTheProjectedBoxEdges) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Irregular);
    Overlays ov;
    ov.options.bsp = true;
    ov.look.lineOpacity = 1.0f;
    const Camera& cam = s->scene->camera;
    ov.update(s, cam, kW, kH);
    ASSERT_NE(ov.view(), nullptr);
    const ZoneFrameView* fr = overlayFrame(*ov.view(), true);
    ASSERT_NE(fr, nullptr);
    EXPECT_TRUE(fr->mapsToImage()) << "an orthographic camera frame maps to pixels";
    // Every cut of the description lies on a projected face of a box.
    const std::set<double> xs = {20.5, 40.5, 60.5, 80.5}, ys = {29.5, 39.5, 59.5, 69.5};
    size_t inside = 0;
    for (const BspCut& c : fr->cuts()) {
        const glm::dvec2 a = fr->toPixel(c.a, kW, kH), b = fr->toPixel(c.b, kW, kH);
        if (c.axis == 0) {
            EXPECT_NEAR(a.x, b.x, 1e-9);
            bool onEdge = false;
            for (double x : xs) onEdge |= std::abs(a.x - x) < 1e-6;
            // Cuts on the padded bounds' rim lie outside the image: they separate nothing seen.
            if (a.x > 0.0 && a.x < kW) {
                EXPECT_TRUE(onEdge) << "cut x = " << a.x;
                ++inside;
            }
        } else {
            bool onEdge = false;
            for (double y : ys) onEdge |= std::abs(a.y - y) < 1e-6;
            if (a.y > 0.0 && a.y < kH) {
                EXPECT_TRUE(onEdge) << "cut y = " << a.y;
                ++inside;
            }
        }
    }
    EXPECT_GE(inside, 4u) << "the boxes' sides must be cut";
    // And the drawing: every lit pixel is on one of those columns or rows, and the columns
    // between the two boxes' sides are lit.
    gl.clear(0, 0, 0);
    ov.draw(cam, kW, kH);
    const std::vector<uint8_t> px = gl.read();
    size_t litCount = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            if (lit(px, x, y)) {
                ++litCount;
                EXPECT_TRUE(xs.count(x + 0.5) || ys.count(y + 0.5))
                    << "pixel " << x << "," << y << " lit off every box edge";
            }
    EXPECT_GT(litCount, size_t(kH)) << "cut lines must be drawn";
    int litColumns = 0;
    for (double x : xs) litColumns += lit(px, int(x), 50);
    EXPECT_GE(litColumns, 2) << "vertical cuts cross row 50 between the boxes";

    // The replay: no cut drawn at 0, and the first cut only at 1.
    ov.look.replayCuts = 0;
    gl.clear(0, 0, 0);
    ov.draw(cam, kW, kH);
    const std::vector<uint8_t> none = gl.read();
    size_t litNone = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) litNone += lit(none, x, y);
    EXPECT_EQ(litNone, 0u);
}

TEST(Overlays, TheSelectionIsHighlightedWhereItsCornersProject) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Regular);
    const Camera& cam = s->scene->camera;
    Overlays ov;
    ov.update(s, cam, kW, kH);
    // Pick the pixel at the centre of the second box: its leaf holds primitive 1.
    const gl::ImageProjector proj(cam, kW, kH);
    const glm::dvec2 centre = *proj.toImage({2.05, 0.55, 0.5});
    ASSERT_TRUE(ov.pickAt(cam, kW, kH, centre.x, centre.y, 9.5f));
    const uint32_t id = ov.selection()->region;
    const RegionInfo r = ov.view()->region(id);
    ASSERT_EQ(r.kind, RegionKind::Leaf);
    EXPECT_TRUE(std::find(r.prims.begin(), r.prims.end(), 1u) != r.prims.end());
    // Drawn: the leaf's outline on the pixels its corners project to (one pixel of slack
    // across an edge on the pixel grid), tinted inside, nothing far outside.
    gl.clear(0, 0, 0);
    ov.draw(cam, kW, kH);
    const std::vector<uint8_t> px = gl.read();
    const std::array<Vec3, 8> c = ov.view()->regionCorners(id);
    glm::dvec2 lo(1e9), hi(-1e9);
    for (const Vec3& p : c) {
        const glm::dvec2 q = *proj.toImage(p);
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
    }
    auto cyanNear = [&](double x, double y) {
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int xi = std::clamp(int(std::floor(x)) + dx, 0, kW - 1),
                          yi = std::clamp(int(std::floor(y)) + dy, 0, kH - 1);
                const uint8_t* p = &px[(size_t(yi) * kW + size_t(xi)) * 4];
                if (p[1] > 200 && p[2] > 200 && p[0] < 120) return true;
            }
        return false;
    };
    const glm::dvec2 mid = 0.5 * (lo + hi);
    EXPECT_TRUE(cyanNear(lo.x, mid.y)) << "left edge at x " << lo.x;
    EXPECT_TRUE(cyanNear(hi.x, mid.y)) << "right edge at x " << hi.x;
    EXPECT_TRUE(cyanNear(mid.x, lo.y)) << "top edge at y " << lo.y;
    EXPECT_TRUE(cyanNear(mid.x, hi.y)) << "bottom edge at y " << hi.y;
    const uint8_t* in = &px[(size_t(mid.y) * kW + size_t(mid.x)) * 4];
    EXPECT_GT(in[2], 20) << "the inside is tinted";
    EXPECT_LT(in[2], 120) << "translucently";
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x)
            if (x + 0.5 < lo.x - 2 || x + 0.5 > hi.x + 2 || y + 0.5 < lo.y - 2 ||
                y + 0.5 > hi.y + 2) {
                ASSERT_FALSE(lit(px, x, y)) << x << "," << y << " outside the selection";
            }
    // A region id the structure does not have selects nothing.
    EXPECT_FALSE(ov.select(uint32_t(ov.view()->regionCount())));
    EXPECT_FALSE(ov.selection().has_value());
}

/// Pixels lit by drawing `ov` on black.
std::vector<uint8_t> drawn(const OffscreenGl& gl, Overlays& ov, const Camera& cam) {
    gl.clear(0, 0, 0);
    ov.draw(cam, kW, kH);
    return gl.read();
}

/// Bars 8 long turned by 30 degrees about z, seen from +z by the orthographic camera of
/// twoBoxes: the regular grid follows their frame, so its leaves project as turned rectangles.
std::shared_ptr<SceneBuild> turnedBarsFromAbove() {
    auto scene = std::make_shared<Scene>();
    const Transform turn = Transform::rotate(30.0, {0, 0, 1});
    for (const Vec3& c : {Vec3(0.0, -1.5, 0.0), Vec3(0.0, 1.5, 0.0), Vec3(0.5, 0.0, 0.3)})
        scene->prims.push_back(
            makePrimitive(Block{c - Vec3(4.0, 0.2, 0.2), c + Vec3(4.0, 0.2, 0.2)}, turn));
    // Small blocks between them, so the BSP cuts to several levels.
    for (const Vec3& c : {Vec3(-3.0, 0.8, 0.0), Vec3(2.5, -0.7, 0.1), Vec3(1.0, 2.6, -0.1)})
        scene->prims.push_back(makePrimitive(Block{c - Vec3(0.3), c + Vec3(0.3)}, turn));
    unionSeenFromAbove(*scene);
    BuildParams p;
    p.scheme = SchemeKind::Regular;
    p.regular.maxLevel = 6;
    p.regular.maxObjects = 1;
    auto s = std::make_shared<SceneBuild>();
    s->spec = "turned bars";
    s->scene = scene;
    s->accel = buildAccelerator(*scene, p);
    return s;
}

/// Distance from the point p to the segment [a, b].
double segmentDistance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    const glm::dvec2 d = b - a;
    const double len2 = glm::dot(d, d);
    const double t = len2 > 0.0 ? std::clamp(glm::dot(p - a, d) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * d));
}

// A grid in a turned frame is drawn turned: every lit pixel lies within a pixel and a half of a
// leaf's projected edge, and every edge's middle is lit.
TEST(Overlays, TurnedLeavesAreDrawnOnTheirProjectedEdges) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = turnedBarsFromAbove();
    ASSERT_TRUE(std::get<RegularGrid>(s->accel->impl()).frame().turned);
    const Camera& cam = s->scene->camera;
    Overlays ov;
    ov.options.leaves = true;
    ov.update(s, cam, kW, kH);
    const StructureView& sv = *ov.view();
    ASSERT_GT(sv.regionCount(), 8u);
    EXPECT_TRUE(viewer::testing::sameLineCover(leafEdges(sv), ov.geometry().wires));
    const gl::ImageProjector proj(cam, kW, kH);
    std::vector<std::pair<glm::dvec2, glm::dvec2>> edges;  // the x and y edges, in the image
    for (uint32_t i = 0; i < sv.regionCount(); ++i) {
        const std::array<Vec3, 8> c = sv.regionCorners(i);
        for (int k = 0; k < 8; ++k)
            for (int bit : {1, 2})
                if (!(k & bit)) edges.push_back({*proj.toImage(c[k]), *proj.toImage(c[k | bit])});
    }
    const std::vector<uint8_t> px = drawn(gl, ov, cam);
    size_t litCount = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            if (!lit(px, x, y)) continue;
            ++litCount;
            double best = 1e9;
            for (const auto& [a, b] : edges)
                best = std::min(best, segmentDistance({x + 0.5, y + 0.5}, a, b));
            ASSERT_LT(best, 1.5) << "pixel " << x << "," << y << " lit off every leaf edge";
        }
    EXPECT_GT(litCount, 0u);
    for (const auto& [a, b] : edges) {
        const glm::dvec2 m = 0.5 * (a + b);
        if (m.x < 1 || m.y < 1 || m.x > kW - 2 || m.y > kH - 2) continue;
        bool near = false;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) near = near || lit(px, int(m.x) + dx, int(m.y) + dy);
        EXPECT_TRUE(near) << "edge middle " << m.x << "," << m.y << " not drawn";
    }
}

TEST(Overlays, TheLevelRangeHidesTheLevelsOutsideIt) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Regular);
    const Camera& cam = s->scene->camera;
    Overlays ov;
    ov.options.leaves = true;
    ov.update(s, cam, kW, kH);
    const StructureView& sv = *ov.view();
    const size_t n = sv.regionCount();
    ASSERT_GT(n, 2u);
    std::map<int, size_t> perLevel;
    for (uint32_t i = 0; i < n; ++i) ++perLevel[sv.leafLevel(i)];
    ASSERT_GE(perLevel.size(), 2u) << "the test needs leaves at two levels";
    // The leaves' edges, each drawn once: neighbours share them.
    EXPECT_TRUE(viewer::testing::sameLineCover(leafEdges(sv), ov.geometry().wires));
    EXPECT_LT(ov.geometry().wires.lineCount(), 12 * n);
    const gl::ImageProjector proj(cam, kW, kH);
    for (const auto& [level, count] : perLevel) {
        ov.options.levelMin = ov.options.levelMax = level;
        ov.update(s, cam, kW, kH);
        EXPECT_EQ(ov.geometry().regionsDrawn, count) << "level " << level;
        EXPECT_TRUE(
            viewer::testing::sameLineCover(leafEdges(sv, level, level), ov.geometry().wires))
            << "level " << level;
        // Every lit pixel lies on the outline of a leaf of this level (a pixel of slack).
        std::vector<uint8_t> mask(size_t(kW) * kH, 0);
        for (uint32_t i = 0; i < n; ++i) {
            if (sv.leafLevel(i) != level) continue;
            const std::array<Vec3, 8> c = sv.regionCorners(i);
            const glm::dvec2 a = *proj.toImage(c[0]), b = *proj.toImage(c[7]);
            const glm::dvec2 lo = glm::min(a, b), hi = glm::max(a, b);
            for (int y = 0; y < kH; ++y)
                for (int x = 0; x < kW; ++x) {
                    const double px = x + 0.5, py = y + 0.5;
                    const bool inY = py > lo.y - 1.5 && py < hi.y + 1.5;
                    const bool inX = px > lo.x - 1.5 && px < hi.x + 1.5;
                    if ((inY && (std::abs(px - lo.x) < 1.5 || std::abs(px - hi.x) < 1.5)) ||
                        (inX && (std::abs(py - lo.y) < 1.5 || std::abs(py - hi.y) < 1.5)))
                        mask[size_t(y) * kW + size_t(x)] = 1;
                }
        }
        const std::vector<uint8_t> px = drawn(gl, ov, cam);
        size_t litCount = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x)
                if (lit(px, x, y)) {
                    ++litCount;
                    ASSERT_TRUE(mask[size_t(y) * kW + size_t(x)])
                        << "level " << level << ": pixel " << x << "," << y
                        << " lit off every leaf of the level";
                }
        EXPECT_GT(litCount, 0u) << "level " << level;
    }
    // A range with no leaf draws nothing.
    ov.options.levelMin = ov.options.levelMax = perLevel.rbegin()->first + 1;
    ov.update(s, cam, kW, kH);
    EXPECT_EQ(ov.geometry().wires.lineCount(), 0u);
    const std::vector<uint8_t> px = drawn(gl, ov, cam);
    for (size_t i = 0; i < px.size(); i += 4) ASSERT_LE(px[i] + px[i + 1] + px[i + 2], 0);
}

/// A node's BSP level, independently of the level the description gives: the cuts whose cell
/// holds cells [lo, hi) and is larger (the nodes above it).
int cutsAbove(const std::vector<CutPlane>& cuts, const uint32_t lo[3], const uint32_t hi[3]) {
    int above = 0;
    for (const CutPlane& c : cuts) {
        bool holds = true, equal = true;
        for (int a = 0; a < 3; ++a) {
            holds = holds && c.cellLo[a] <= lo[a] && hi[a] <= c.cellHi[a];
            equal = equal && c.cellLo[a] == lo[a] && c.cellHi[a] == hi[a];
        }
        above += holds && !equal;
    }
    return above;
}

// The level range is the BSP level, for the leaves (RegionInfo::level) and for the directory
// grid's blocks (an entry by its leaf's level, a sub-table by its node's), not the depth of the
// sub-table holding an entry.
TEST(Overlays, TheLevelRangeSelectsLeavesAndGridBlocksByBspLevel) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Regular);
    const Camera& cam = s->scene->camera;
    Overlays ov;
    ov.options.grid = true;
    ov.update(s, cam, kW, kH);
    const StructureView& sv = *ov.view();
    const std::vector<CutPlane> cuts = sv.cutPlanes();
    for (uint32_t i = 0; i < sv.regionCount(); ++i) {
        const RegionInfo r = sv.region(i);
        EXPECT_EQ(r.level, cutsAbove(cuts, r.cellLo, r.cellHi)) << "leaf " << i;
        EXPECT_EQ(sv.leafLevel(i), r.level);
    }
    const std::vector<DirectoryBlock> blocks = sv.directoryBlocks();
    std::map<int, size_t> perLevel, perDepth;
    for (const DirectoryBlock& b : blocks) {
        if (b.subTable) {
            EXPECT_EQ(b.level, cutsAbove(cuts, b.lo, b.hi));
        } else {
            EXPECT_EQ(b.level, sv.region(b.leaf).level) << "an entry has its leaf's level";
        }
        ++perLevel[b.level];
        ++perDepth[b.depth];
    }
    ASSERT_GE(perLevel.size(), 2u) << "the test needs blocks at two levels";
    bool depthDiffers = false;
    for (const auto& [level, count] : perLevel) {
        ov.options.levelMin = ov.options.levelMax = level;
        ov.update(s, cam, kW, kH);
        EXPECT_EQ(ov.geometry().regionsTotal, count) << "level " << level;
        // A sub-table's outline is drawn over the entries' edges it shares.
        EXPECT_TRUE(viewer::testing::drawnByPrecedence(
            {blockEdges(sv, level, level, true), blockEdges(sv, level, level, false)},
            ov.geometry().wires))
            << "level " << level;
        depthDiffers |= perDepth[level] != count;
    }
    EXPECT_TRUE(depthDiffers) << "the scene must tell BSP levels from sub-table depths";
    // Every colouring draws the same blocks.
    for (GridColor c : {GridColor::Kind, GridColor::Level, GridColor::TableDepth}) {
        ov.options.gridColor = c;
        ov.options.levelMin = 0;
        ov.options.levelMax = 64;
        ov.update(s, cam, kW, kH);
        EXPECT_EQ(ov.geometry().regionsTotal, blocks.size());
    }
}

TEST(Overlays, LeavesAndGridTogetherDrawEachSharedEdgeOnceInTheColourThatSaysMore) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    Overlays ov;
    ov.options.grid = ov.options.leaves = true;
    const auto s = twoBoxes(SchemeKind::Regular);
    const Camera& cam = s->scene->camera;
    ov.update(s, cam, kW, kH);
    const StructureView& sv = *ov.view();
    const gl::Batch subTables = blockEdges(sv, 0, 64, true), entries = blockEdges(sv, 0, 64, false);
    const gl::Batch leaves = leafEdges(sv);
    ASSERT_GT(entries.lineCount(), 0u);
    // Sub-tables (none in this small table) over leaves over entries, every point of each
    // drawn once.
    EXPECT_TRUE(
        viewer::testing::drawnByPrecedence({subTables, leaves, entries}, ov.geometry().wires));
    // The table cuts some leaves: there the entries' lines still show.
    const gl::Rgba8 entryColour = gl::rgba8(glm::vec3(0.55f, 0.65f, 0.8f));
    size_t entryLines = 0;
    for (size_t k = 0; k < ov.geometry().wires.lineCount(); ++k)
        entryLines += ov.geometry().wires.lines[2 * k].color == entryColour;
    EXPECT_GT(entryLines, 0u);
    // Each layer alone draws its own edges whole.
    ov.options.grid = false;
    ov.update(s, cam, kW, kH);
    EXPECT_TRUE(viewer::testing::sameLineCover(leaves, ov.geometry().wires));
    // And drawn: a leaf edge shared with an entry shows the leaf's level colour, not the
    // entry's grey-blue (the pixels of the whole layer at once).
    ov.options.grid = true;
    ov.update(s, cam, kW, kH);
    gl.clear(0, 0, 0);
    ov.drawLayers(cam, kW, kH);
    const std::vector<uint8_t> both = gl.read();
    ov.options.grid = false;
    ov.update(s, cam, kW, kH);
    gl.clear(0, 0, 0);
    ov.drawLayers(cam, kW, kH);
    const std::vector<uint8_t> alone = gl.read();
    size_t leafPixels = 0, kept = 0;
    for (size_t i = 0; i < alone.size(); i += 4) {
        if (alone[i] == 0 && alone[i + 1] == 0 && alone[i + 2] == 0) continue;
        ++leafPixels;
        kept += both[i] == alone[i] && both[i + 1] == alone[i + 1] && both[i + 2] == alone[i + 2];
    }
    ASSERT_GT(leafPixels, size_t(kW));
    // The leaf pixels keep their colour (a sub-table's outline would replace it with orange;
    // this table has none), but where an entry's line crosses a leaf edge (2% of them here).
    // Before, the entries drawn over the leaves took every one (the same count, 2026-12-06).
    EXPECT_GE(kept, leafPixels * 19 / 20);
}

TEST(Overlays, ARebuildAtAnotherMaxLevelChangesTheDrawnLeavesAndOnlyThen) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto coarse = twoBoxes(SchemeKind::Regular, 3), fine = twoBoxes(SchemeKind::Regular, 8);
    const Camera& cam = coarse->scene->camera;
    Overlays ov;
    ov.options.leaves = true;
    ov.update(coarse, cam, kW, kH);
    const uint64_t builds = ov.rebuilds();
    const size_t coarseLines = ov.geometry().wires.lineCount();
    const std::vector<uint8_t> before = drawn(gl, ov, cam);
    // Same structure, camera, size and options: the cached batches are drawn as they are.
    ov.update(coarse, cam, kW, kH);
    EXPECT_EQ(ov.rebuilds(), builds);
    // No new structure yet (a build under way): the old overlays stay.
    ov.update(nullptr, cam, kW, kH);
    EXPECT_EQ(ov.rebuilds(), builds);
    EXPECT_EQ(drawn(gl, ov, cam), before);
    // The new structure arrives: rebuilt once, more leaves, other pixels.
    ov.update(fine, cam, kW, kH);
    EXPECT_EQ(ov.rebuilds(), builds + 1);
    EXPECT_GT(ov.geometry().wires.lineCount(), coarseLines);
    EXPECT_TRUE(viewer::testing::sameLineCover(leafEdges(*ov.view()), ov.geometry().wires));
    const std::vector<uint8_t> after = drawn(gl, ov, cam);
    size_t changed = 0;
    for (size_t i = 0; i < after.size(); i += 4)
        changed += lit(after, int(i / 4) % kW, int(i / 4) / kW) !=
                   lit(before, int(i / 4) % kW, int(i / 4) / kW);
    EXPECT_GT(changed, 10u);
}

TEST(Overlays, BatchesCulledForAViewAreCulledAgainOnlyOnceTheCameraRests) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Regular, 8);
    Camera cam = s->scene->camera;
    Overlays ov;
    ov.options.leaves = true;
    ov.options.cap = 3;  // fewer than the leaves: culled by visibility, for the camera
    ov.update(s, cam, kW, kH);
    ASSERT_TRUE(ov.geometry().cameraDependent);
    const uint64_t builds = ov.rebuilds();
    cam.from.y += 0.5;
    ov.update(s, cam, kW, kH, true);
    EXPECT_EQ(ov.rebuilds(), builds) << "culled again at each step of a drag";
    ov.update(s, cam, kW, kH, false);
    EXPECT_EQ(ov.rebuilds(), builds + 1) << "not culled again once the camera rests";
    ov.update(s, cam, kW, kH, false);
    EXPECT_EQ(ov.rebuilds(), builds + 1);
}

TEST(Overlays, BuiltInTheBackgroundTheBatchesComeAtALaterUpdateAndEqualTheDirectBuild) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto coarse = twoBoxes(SchemeKind::Regular, 3), fine = twoBoxes(SchemeKind::Regular, 8);
    const Camera& cam = coarse->scene->camera;
    Overlays direct;
    direct.options.leaves = true;
    direct.update(fine, cam, kW, kH);

    std::mutex m;
    std::condition_variable cv;
    int woken = 0;
    Overlays ov;
    ov.buildInBackground([&] {
        std::lock_guard lock(m);
        ++woken;
        cv.notify_all();
    });
    ov.options.leaves = true;
    auto waitFor = [&](int n) {
        std::unique_lock lock(m);
        return cv.wait_for(lock, std::chrono::seconds(30), [&] { return woken >= n; });
    };
    ov.update(coarse, cam, kW, kH);
    EXPECT_EQ(ov.rebuilds(), 0u) << "update() does not wait for the worker";
    EXPECT_TRUE(ov.building());
    ASSERT_TRUE(waitFor(1));
    // A new structure while nothing is under way: the finished batches are taken, then the new
    // structure's are begun, and the coarse ones stay until they come.
    ov.update(fine, cam, kW, kH);
    EXPECT_EQ(ov.rebuilds(), 1u);
    EXPECT_TRUE(ov.building());
    const size_t coarseLines = ov.geometry().wires.lineCount();
    ASSERT_TRUE(waitFor(2));
    ov.update(fine, cam, kW, kH);
    EXPECT_EQ(ov.rebuilds(), 2u);
    EXPECT_FALSE(ov.building()) << "nothing changed since: no build begun";
    EXPECT_GT(ov.geometry().wires.lineCount(), coarseLines);
    EXPECT_EQ(ov.geometry().wires.lineCount(), direct.geometry().wires.lineCount());
    EXPECT_TRUE(viewer::testing::sameLineCover(leafEdges(*ov.view()), ov.geometry().wires));
    EXPECT_EQ(drawn(gl, ov, cam), drawn(gl, direct, cam));
}

TEST(Overlays, ALargeLayerIsDrawnInPartsLongestFirstWithinAFramesBudget) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Regular, 8);
    const Camera& cam = s->scene->camera;
    Overlays ov;
    ov.options.leaves = true;
    ov.look.lineOpacity = 1.0f;
    ov.update(s, cam, kW, kH);
    const size_t total = ov.layerLines();
    ASSERT_GT(total, 12u);
    ov.look.restLines = total / 4 + 1;  // four parts
    ov.look.restMs = 0.0;               // one a call
    Image black(kW, kH);
    ImageView view;
    view.upload(black, ViewMode::Color);
    auto composited = [&](unsigned tex) {
        view.setOverlay(tex, ov.layerVersion());
        gl.clear(0, 0, 0);
        view.draw(kW, kH, ViewMode::Color, 1.0f);
        return gl.read();
    };
    auto litCount = [](const std::vector<uint8_t>& px) {
        size_t n = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) n += lit(px, x, y);
        return n;
    };
    gl.clear(0, 0, 0);
    ov.drawLayers(cam, kW, kH);
    const std::vector<uint8_t> whole = gl.read();
    // The first part: the longest lines only, a layer still pending.
    unsigned tex = ov.layerTexture(cam, kW, kH);
    ASSERT_NE(tex, 0u);
    EXPECT_TRUE(ov.layerPending());
    EXPECT_TRUE(ov.layerStale(cam, kW, kH));
    EXPECT_EQ(ov.layerDrawn(), ov.look.restLines);
    const size_t firstLit = litCount(composited(tex));
    EXPECT_GT(firstLit, 0u);
    EXPECT_LT(firstLit, litCount(whole));
    // Each call draws the next part on it; the fourth ends it.
    int calls = 1;
    while (ov.layerPending() && calls < 100) {
        ov.layerTexture(cam, kW, kH);
        ++calls;
        EXPECT_EQ(ov.layerDrawn(), std::min(size_t(calls) * ov.look.restLines, total));
    }
    EXPECT_EQ(calls, 4);
    EXPECT_FALSE(ov.layerPartial());
    EXPECT_FALSE(ov.layerStale(cam, kW, kH));
    const uint64_t version = ov.layerVersion();
    EXPECT_EQ(ov.layerTexture(cam, kW, kH), tex);
    EXPECT_EQ(ov.layerVersion(), version) << "whole: not drawn again";
    // Whole, it lights the pixels the layer drawn at once lights (in another order, so where
    // two colours cross either may be on top).
    const std::vector<uint8_t> parts = composited(tex);
    size_t differ = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) differ += lit(parts, x, y) != lit(whole, x, y);
    EXPECT_EQ(differ, 0u);
    // A moving camera's cap is the first part: once it rests, the layer goes on from there.
    Camera moved = cam;
    moved.from.x += 0.5;
    ov.look.movingLines = 3;
    ov.layerTexture(moved, kW, kH, true);
    EXPECT_EQ(ov.layerDrawn(), 3u);
    EXPECT_FALSE(ov.layerPending()) << "moving: capped, not pending";
    ov.layerTexture(moved, kW, kH);
    EXPECT_EQ(ov.layerDrawn(), 3u + ov.look.restLines);
    EXPECT_TRUE(ov.layerPending());
    // While moving, parts too: a frame's budget spent after its first part (movingMs 0), the
    // cap not reached; with time to spare, up to the cap.
    ov.look.movingLines = total;
    ov.look.movingMs = 0.0;
    moved.from.y += 0.5;
    ov.layerTexture(moved, kW, kH, true);
    EXPECT_EQ(ov.layerDrawn(), ov.look.restLines);
    ov.look.movingMs = 1e9;
    ov.look.movingLines = 2 * ov.look.restLines;
    moved.from.y += 0.5;
    ov.layerTexture(moved, kW, kH, true);
    EXPECT_EQ(ov.layerDrawn(), 2 * ov.look.restLines);
}

/// twoBoxes' leaves (max level 8) in opaque lines, in two overlays: `ov` under test, `free`
/// drawn without a budget.
struct LeavesInParts {
    std::shared_ptr<SceneBuild> s = twoBoxes(SchemeKind::Regular, 8);
    const Camera& cam = s->scene->camera;
    OffscreenGl gl{kW, kH};  // before the overlays: they need its context
    Overlays free, ov;
    LeavesInParts() {
        if (!gl.ok()) return;
        for (Overlays* o : {&free, &ov}) {
            o->options.leaves = true;
            o->look.lineOpacity = 1.0f;
            o->update(s, cam, kW, kH);
        }
    }
};

/// A black image with `o`'s layer for `cam` composited over it, as drawn.
std::vector<uint8_t> overBlack(const OffscreenGl& gl, ImageView& view, Overlays& o,
                               const Camera& cam) {
    if (view.width() == 0) view.upload(Image(kW, kH), ViewMode::Color);
    view.setOverlay(o.layerTexture(cam, kW, kH), o.layerVersion());
    gl.clear(0, 0, 0);
    view.draw(kW, kH, ViewMode::Color, 1.0f);
    return gl.read();
}

TEST(Overlays, WithTheFramesBudgetSpentTheLayerWaitsAndEndsAsTheOneDrawnWithoutIt) {
    // The same layer drawn in parts without a budget and with one that earlier steps of the
    // frame spent in some frames.
    LeavesInParts t;
    ASSERT_TRUE(t.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    const size_t total = t.ov.layerLines();
    ASSERT_GT(total, 12u);
    for (Overlays* o : {&t.free, &t.ov}) {
        o->look.restLines = total / 4 + 1;  // four parts
        o->look.restMs = 1e9;               // each as many parts as the frame allows
    }
    t.free.look.restMs = 0.0;  // one part a call
    // The clock: 6 ms a reading, so a frame of 33 ms keeping 10 for later steps has room for
    // three parts of the four; `now += 30` stands for the frame's earlier steps.
    double now = 0.0;
    FrameBudget budget(33.0, [&] { return now += 6.0; });
    t.ov.setFrameBudget(&budget, 10.0);
    ImageView view;
    // A frame whose earlier steps spent the budget: no part, nothing drawn, the layer pending
    // (the window stays eager).
    budget.begin();
    now += 30.0;
    t.ov.layerTexture(t.cam, kW, kH);
    EXPECT_EQ(t.ov.layerDrawn(), 0u);
    EXPECT_EQ(t.ov.layerVersion(), 0u) << "nothing drawn";
    EXPECT_TRUE(t.ov.layerPending()) << "deferred: pending";
    EXPECT_GE(budget.deferred(), 1);
    // A frame with room makes the texture of the size, and draws into it from the next.
    budget.begin();
    t.ov.layerTexture(t.cam, kW, kH);
    EXPECT_EQ(t.ov.layerVersion(), 0u) << "nothing drawn";
    // A frame with room: parts until the budget less the reserve is spent, not the whole.
    budget.begin();
    t.ov.layerTexture(t.cam, kW, kH);
    const size_t first = t.ov.layerDrawn();
    EXPECT_GE(first, t.ov.look.restLines);
    EXPECT_LT(first, total) << "stopped by the frame's budget, not by restMs";
    int frames = 1;
    while (t.ov.layerPending() && frames < 100) {
        budget.begin();
        if (frames % 2 == 1) now += 30.0;  // every other frame spent before the layer
        const size_t before = t.ov.layerDrawn();
        t.ov.layerTexture(t.cam, kW, kH);
        if (frames % 2 == 1) {
            EXPECT_EQ(t.ov.layerDrawn(), before) << "frame " << frames;
        }
        ++frames;
    }
    EXPECT_FALSE(t.ov.layerPending());
    EXPECT_EQ(t.ov.layerDrawn(), total);
    // The same picture as the layer drawn in parts without a budget.
    while (t.free.layerPending() || t.free.layerVersion() == 0) t.free.layerTexture(t.cam, kW, kH);
    EXPECT_EQ(overBlack(t.gl, view, t.ov, t.cam), overBlack(t.gl, view, t.free, t.cam));
    // A moving camera's layer draws its first part whatever the budget.
    Camera moved = t.cam;
    moved.from.x += 0.5;
    t.ov.look.movingLines = total;
    budget.begin();
    now += 100.0;
    t.ov.layerTexture(moved, kW, kH, true);
    EXPECT_EQ(t.ov.layerDrawn(), t.ov.look.restLines);
    t.ov.setFrameBudget(nullptr, 0.0);
}

TEST(Overlays, APartStartsOnlyWhenItsLearnedCostFitsAndAMovingFirstPartIsSizedToTheBudget) {
    LeavesInParts t;
    ASSERT_TRUE(t.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    const size_t total = t.ov.layerLines();
    ASSERT_GT(total, 40u);
    t.ov.look.movingLines = total;
    t.ov.look.movingMs = 1e9;
    t.ov.look.movingMinLines = 10;
    // A clock only the test moves: each part measured costs nothing, so the learned costs
    // shrink a quarter at each part.
    double now = 0.0;
    FrameBudget budget(33.0, [&] { return now; });
    t.ov.setFrameBudget(&budget, 10.0);
    Camera moved = t.cam;
    moved.from.x += 0.5;
    // A moving camera with 0.1 ms left beyond the reserve: at 7 ms per 1,000 lines (the
    // estimate until measured) 14 lines fit; the first part holds them, not restLines.
    t.ov.look.restLines = total;
    budget.begin();
    now += 22.9;
    t.ov.layerTexture(moved, kW, kH, true);
    EXPECT_EQ(t.ov.layerDrawn(), 14u);
    // With the budget spent, the least part (the longest lines) whatever the budget.
    budget.begin();
    now += 100.0;
    moved.from.x += 0.5;
    t.ov.layerTexture(moved, kW, kH, true);
    EXPECT_EQ(t.ov.layerDrawn(), 10u);
    // With room, the whole cap.
    budget.begin();
    moved.from.x += 0.5;
    t.ov.layerTexture(moved, kW, kH, true);
    EXPECT_EQ(t.ov.layerDrawn(), total);
    // At rest, in parts of a quarter (5 ms per 500 lines until measured): with 0.01 ms left
    // beyond the reserve no part starts (some budget is left, but not a part's cost), and the
    // layer waits.
    t.ov.look.restLines = total / 4 + 1;
    t.ov.look.restMs = 1e9;
    budget.begin();
    now += 22.99;
    const double partMs = double(t.ov.look.restLines) * 5.0 / 500.0;
    ASSERT_GT(partMs, 0.01);
    const uint64_t version = t.ov.layerVersion();
    t.ov.layerTexture(t.cam, kW, kH);
    EXPECT_EQ(t.ov.layerVersion(), version) << "nothing drawn";
    EXPECT_TRUE(t.ov.layerPending());
    EXPECT_GE(budget.deferred(), 1);
    // A frame with room draws every part (they cost nothing measured); then the layer drawn
    // without a budget.
    budget.begin();
    t.ov.layerTexture(t.cam, kW, kH);
    EXPECT_FALSE(t.ov.layerPending());
    EXPECT_EQ(t.ov.layerDrawn(), total);
    t.free.look = t.ov.look;
    t.free.look.restMs = 0.0;
    while (t.free.layerPending() || t.free.layerVersion() == 0) t.free.layerTexture(t.cam, kW, kH);
    ImageView view;
    EXPECT_EQ(overBlack(t.gl, view, t.ov, t.cam), overBlack(t.gl, view, t.free, t.cam));
    t.ov.setFrameBudget(nullptr, 0.0);
}

/// The texels of a w x h RGBA8 texture.
std::vector<uint8_t> texels(unsigned texture, int w, int h) {
    std::vector<uint8_t> out(size_t(w) * size_t(h) * 4);
    glBindTexture(GL_TEXTURE_2D, texture);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, out.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    return out;
}

TEST(Overlays, ATextureOfANewSizeIsMadeWhenItsLearnedCostFitsAndDrawnIntoFromTheNextFrame) {
    LeavesInParts t;
    ASSERT_TRUE(t.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    constexpr int w = 1280, h = 720;  // the viewer's size: the texture's figure, 10 ms
    for (Overlays* o : {&t.free, &t.ov}) o->update(t.s, t.cam, w, h);
    // A clock only the test moves: what is measured costs nothing.
    double now = 0.0;
    FrameBudget budget(33.0, [&] { return now; });
    t.ov.setFrameBudget(&budget, 10.0);
    // 9 ms left beyond the reserve: room for the layer's part, not for the texture: nothing
    // made, no layer.
    budget.begin();
    now += 14.0;
    EXPECT_EQ(t.ov.layerTexture(t.cam, w, h), 0u);
    EXPECT_EQ(t.ov.layerVersion(), 0u);
    EXPECT_TRUE(t.ov.layerPending());
    EXPECT_GE(budget.deferred(), 1);
    // 11 ms left: the texture made, and nothing drawn into it in that frame (the layer's
    // drawing and its read-back come in the next), though its part fits.
    budget.begin();
    now += 12.0;
    EXPECT_EQ(t.ov.layerTexture(t.cam, w, h), 0u);
    EXPECT_EQ(t.ov.layerVersion(), 0u);
    EXPECT_TRUE(t.ov.layerPending());
    // The next frame draws the layer, as the one drawn without a budget.
    budget.begin();
    now += 12.0;
    const unsigned texture = t.ov.layerTexture(t.cam, w, h);
    ASSERT_NE(texture, 0u);
    EXPECT_EQ(t.ov.layerVersion(), 1u);
    EXPECT_FALSE(t.ov.layerPending());
    const unsigned whole = t.free.layerTexture(t.cam, w, h);
    ASSERT_FALSE(t.free.layerPending());
    EXPECT_EQ(texels(texture, w, h), texels(whole, w, h));
    // A new size (a resized window): the layer drawn at the old size stays (the same
    // texture, no new version) in the frame the new one is made, and is drawn after.
    budget.begin();
    now += 12.0;
    EXPECT_EQ(t.ov.layerTexture(t.cam, w, h / 2), texture);
    EXPECT_EQ(t.ov.layerVersion(), 1u);
    EXPECT_TRUE(t.ov.layerPending());
    budget.begin();
    now += 12.0;
    EXPECT_EQ(t.ov.layerTexture(t.cam, w, h / 2), texture);
    EXPECT_EQ(t.ov.layerVersion(), 2u);
    EXPECT_FALSE(t.ov.layerPending());
    // A texture no frame would hold (a reserve of 30 ms leaves 3, the texture's learned cost
    // more): made at once, not waited for for ever; the layer drawn into it at the next call.
    t.ov.setFrameBudget(&budget, 30.0);
    budget.begin();
    EXPECT_EQ(t.ov.layerTexture(t.cam, w, h), texture);
    EXPECT_EQ(t.ov.layerVersion(), 2u);
    budget.begin();
    t.ov.layerTexture(t.cam, w, h);
    EXPECT_EQ(t.ov.layerVersion(), 3u);
    t.ov.setFrameBudget(nullptr, 0.0);
}

TEST(Overlays, NoStepOfTheLayerWaitsForEverBesideWhatEachFrameSpendsBeforeIt) {
    // The quiet machine's run that never settled (balls4's slabs with the inspector at
    // 1280x720, 2026-12-07): the texture's learned cost (10 ms at 1280x720) is within the
    // budget less the reserve (23 ms), so it is not made at once, yet never fits beside what
    // each frame spends before the layer. Here each frame spends 24 ms before it: neither the
    // texture nor any part of the layer ever fits. Each still starts after kPatienceFrames
    // frames of waiting: the layer is whole within a bounded number of frames, as drawn
    // without a budget.
    LeavesInParts t;
    ASSERT_TRUE(t.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    constexpr int w = 1280, h = 720;
    const size_t total = t.ov.layerLines();
    ASSERT_GT(total, 12u);
    for (Overlays* o : {&t.free, &t.ov}) {
        o->update(t.s, t.cam, w, h);
        o->look.restLines = total / 4 + 1;  // four parts
        o->look.restMs = 1e9;               // as many parts a frame as the budget allows
    }
    double now = 0.0;
    FrameBudget budget(33.0, [&] { return now; });
    t.ov.setFrameBudget(&budget, 10.0);
    // The texture's frame, then one frame a part, each after its patience.
    constexpr int parts = 4;
    constexpr int bound = (1 + parts) * int(kPatienceFrames + 1);
    int frames = 0, forced = 0;
    while ((t.ov.layerVersion() == 0 || t.ov.layerPending()) && frames < 10 * bound) {
        budget.begin();
        now += 24.0;
        t.ov.layerTexture(t.cam, w, h);
        forced += budget.forced();
        ++frames;
    }
    EXPECT_LE(frames, bound) << "the texture and each part within their patience";
    EXPECT_EQ(forced, 1 + parts) << "each let in over the budget, once a frame";
    ASSERT_FALSE(t.ov.layerPending());
    EXPECT_EQ(t.ov.layerDrawn(), total);
    const unsigned whole = t.free.layerTexture(t.cam, w, h);
    ASSERT_FALSE(t.free.layerPending());
    EXPECT_EQ(texels(t.ov.layerTexture(t.cam, w, h), w, h), texels(whole, w, h));
    t.ov.setFrameBudget(nullptr, 0.0);
}

/// Two boxes' regular leaves built at once (direct) and on a worker (ov).
struct LeavesInTheBackground {
    OffscreenGl gl{kW, kH};
    std::shared_ptr<SceneBuild> s = twoBoxes(SchemeKind::Regular, 8);
    const Camera& cam = s->scene->camera;
    Overlays direct, ov;
    LeavesInTheBackground() {
        direct.options.leaves = ov.options.leaves = true;
        if (gl.ok()) direct.update(s, cam, kW, kH);
        ov.buildInBackground({});
    }
    /// Frames of `frame()` then ov's update (`copy`) until the worker's build is taken.
    void untilTaken(bool copy, const std::function<void()>& frame = {}) {
        const auto start = std::chrono::steady_clock::now();
        while (ov.rebuilds() == 0 &&
               std::chrono::steady_clock::now() - start < std::chrono::seconds(30)) {
            if (frame) frame();
            ov.update(s, cam, kW, kH, false, copy);
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
    }
};

TEST(Overlays, BatchesBuiltInTheBackgroundAreCopiedInPartsAndTheLayerFollowsThem) {
    LeavesInTheBackground t;
    ASSERT_TRUE(t.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    OffscreenGl& gl = t.gl;
    auto& s = t.s;
    const Camera& cam = t.cam;
    Overlays &direct = t.direct, &ov = t.ov;
    // The leaves built at once, and on a worker copied to GL in parts.
    ov.look.uploadBytes = 16 * sizeof(gl::BatchVertex);  // 8 lines a part
    ov.look.uploadMs = 0.0;                              // one part a frame
    ov.look.restMs = 0.0;
    ov.look.restLines = 4;
    t.untilTaken(true);
    ASSERT_EQ(ov.rebuilds(), 1u);
    const size_t total = ov.layerLines();
    ASSERT_GT(total, 24u);
    // Taken: one part copied, the rest in the next frames; the layer drawn meanwhile holds only
    // lines already copied, and never more than a frame's part.
    EXPECT_FALSE(ov.uploaded());
    EXPECT_TRUE(ov.building()) << "not settled while copying";
    int frames = 0;
    size_t ready = ov.layerReady();
    EXPECT_LT(ready, total);
    while ((!ov.uploaded() || ov.layerPending()) && frames < 10000) {
        const size_t before = ov.layerDrawn();
        ov.layerTexture(cam, kW, kH);
        EXPECT_LE(ov.layerDrawn(), std::min(ov.layerReady(), total));
        EXPECT_LE(ov.layerDrawn(), before + ov.look.restLines) << frames;
        ov.update(s, cam, kW, kH);
        EXPECT_GE(ov.layerReady(), ready) << "copied in order";
        ready = ov.layerReady();
        ++frames;
    }
    EXPECT_GT(frames, int(total / 8) - 1) << "copied over many frames";
    EXPECT_TRUE(ov.uploaded());
    EXPECT_FALSE(ov.building());
    EXPECT_EQ(ov.layerDrawn(), total);
    // Whole, the batches are the direct build's, and the layer lights what it lights.
    EXPECT_EQ(drawn(gl, ov, cam), drawn(gl, direct, cam));
    auto layerPixels = [&](Overlays& o) {
        gl.clear(0, 0, 0);
        ImageView view;
        view.upload(Image(kW, kH), ViewMode::Color);
        view.setOverlay(o.layerTexture(cam, kW, kH), o.layerVersion());
        view.draw(kW, kH, ViewMode::Color, 1.0f);
        return gl.read();
    };
    const std::vector<uint8_t> mine = layerPixels(ov), theirs = layerPixels(direct);
    size_t differ = 0, lits = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            differ += lit(mine, x, y) != lit(theirs, x, y);
            lits += lit(theirs, x, y);
        }
    EXPECT_GT(lits, 0u);
    EXPECT_EQ(differ, 0u);
}

TEST(Overlays, TheFramesFirstUpdateTakesTheBatchesAndLeavesTheirCopyToTheBudgetedUpdate) {
    LeavesInTheBackground t;
    ASSERT_TRUE(t.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto& s = t.s;
    const Camera& cam = t.cam;
    Overlays& ov = t.ov;
    ov.look.uploadMs = 1000.0;  // a copy that fits copies everything
    double now = 0.0;           // a clock only the test moves: each frame has room
    FrameBudget budget(33.0, [&] { return now; });
    ov.setFrameBudget(&budget, 0.0);
    // The viewer's frame: an update without the copy (before the steps after the layer have
    // said what they take), then one with it.
    t.untilTaken(false, [&] { budget.begin(); });
    ASSERT_EQ(ov.rebuilds(), 1u);
    EXPECT_FALSE(ov.uploaded()) << "taken, nothing copied";
    EXPECT_EQ(ov.layerReady(), 0u);
    ov.update(s, cam, kW, kH, false, false);
    EXPECT_FALSE(ov.uploaded());
    ov.update(s, cam, kW, kH);
    EXPECT_TRUE(ov.uploaded()) << "copied by the frame's update with the copy";
    EXPECT_EQ(drawn(t.gl, ov, cam), drawn(t.gl, t.direct, cam));
}

// A part of the batches' copy is as large as what the frame's budget leaves holds at its
// learned cost, uploadBytes at most and a 16th of it at least: a part let in over the budget
// after its patience is the least one (a whole part there pushed balls4's frames to 33.0-35.8
// ms of UI CPU, 2026-12-07), and a frame with room copies a whole part.
TEST(Overlays, APartOfTheCopyFollowsWhatTheBudgetLeavesTheLeastWhenLetInOverIt) {
    LeavesInTheBackground t;
    ASSERT_TRUE(t.gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    Overlays& ov = t.ov;
    ov.look.uploadBytes = 64 * sizeof(gl::BatchVertex);  // 32 lines at most, 2 at least
    ov.look.uploadMs = 0.0;                              // one part a frame
    double now = 0.0;                                    // a clock only the test moves
    FrameBudget budget(33.0, [&] { return now; });
    ov.setFrameBudget(&budget, 0.0);
    t.untilTaken(false, [&] { budget.begin(); });
    ASSERT_EQ(ov.rebuilds(), 1u);
    ASSERT_EQ(ov.copiedBytes(), 0u);
    ASSERT_GT(ov.layerLines(), 40u);
    // Vertices copied by a frame whose earlier steps took `spentMs`.
    size_t copied = 0;
    auto frame = [&](double spentMs) {
        budget.begin();
        now += spentMs;
        ov.update(t.s, t.cam, kW, kH);
        const size_t before = copied;
        copied = ov.copiedBytes() / sizeof(gl::BatchVertex);
        return copied - before;
    };
    // Every frame's budget spent: nothing for kPatienceFrames frames, then the least part (4
    // vertices: a triangle of the fills, copied whole, counts 3).
    for (unsigned i = 0; i < kPatienceFrames; ++i) EXPECT_EQ(frame(40.0), 0u) << i;
    const size_t least = frame(40.0);
    EXPECT_EQ(budget.forced(), 1);
    EXPECT_GE(least, 1u);
    EXPECT_LE(least, 4u) << "the least part, let in over the budget";
    // A frame with room: a whole part (its learned cost per byte fits many times over).
    const size_t whole = frame(0.0);
    EXPECT_EQ(budget.forced(), 0);
    EXPECT_GE(whole, 62u);
    EXPECT_LE(whole, 64u);
    ov.setFrameBudget(nullptr, 0.0);
}

TEST(Overlays, TheLayerTextureCompositedIntoTheImageShowsWhatDrawingDirectlyShows) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Irregular);
    const Camera& cam = s->scene->camera;
    Overlays ov;
    ov.options.bsp = ov.options.zones = true;
    ov.update(s, cam, kW, kH);
    Image img(kW, kH);
    for (size_t i = 0; i < img.color.size(); ++i) img.color[i] = glm::vec3(0.2f, 0.3f, 0.4f);
    // Drawn directly over the image, then composited by the image view: the same pixels.
    ImageView view;
    view.upload(img, ViewMode::Color);
    view.draw(kW, kH, ViewMode::Color, 1.0f);
    ov.drawLayers(cam, kW, kH);
    const std::vector<uint8_t> direct = gl.read();
    const unsigned tex = ov.layerTexture(cam, kW, kH);
    ASSERT_NE(tex, 0u);
    const uint64_t version = ov.layerVersion();
    EXPECT_EQ(ov.layerTexture(cam, kW, kH), tex);
    EXPECT_EQ(ov.layerVersion(), version) << "nothing changed: the texture is not drawn again";
    view.setOverlay(tex, version);
    gl.clear(0, 0, 0);
    view.draw(kW, kH, ViewMode::Color, 1.0f);
    const std::vector<uint8_t> composited = gl.read();
    int worst = 0;
    size_t differing = 0;
    for (size_t i = 0; i < direct.size(); ++i) {
        worst = std::max(worst, std::abs(int(direct[i]) - int(composited[i])));
        differing += direct[i] != composited[i];
    }
    EXPECT_LE(worst, 2);
    size_t overlaid = 0;  // and the overlays are there at all
    for (size_t i = 0; i < direct.size(); i += 4)
        overlaid += std::abs(int(composited[i + 2]) - int(std::lround(0.4f * 255.0f))) > 8;
    EXPECT_GT(overlaid, size_t(kW));
    // Rows uploaded while the layer is shown (a pass's band) show their new colour under the
    // same layer, and the other rows stay as they were.
    const int b0 = kH / 4, b1 = kH / 2;
    for (int y = b0; y < b1; ++y)
        for (int x = 0; x < kW; ++x) img.color[img.index(x, y)] = glm::vec3(0.6f, 0.1f, 0.1f);
    view.upload(img, ViewMode::Color, b0, b1);
    gl.clear(0, 0, 0);
    view.draw(kW, kH, ViewMode::Color, 1.0f);
    const std::vector<uint8_t> banded = gl.read();
    size_t newColour = 0, layerKept = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const size_t i = (size_t(y) * kW + size_t(x)) * 4;
            const bool plain = std::abs(int(composited[i + 2]) - 102) <= 1 &&
                               std::abs(int(composited[i]) - 51) <= 1;
            if (y < b0 || y >= b1) {
                ASSERT_EQ(banded[i], composited[i]) << x << "," << y << ": outside the band";
            } else if (plain) {
                newColour += std::abs(int(banded[i]) - 153) <= 1 && banded[i + 2] <= 26;
            } else {
                layerKept += banded[i] != 153 || banded[i + 2] > 26;
            }
        }
    EXPECT_GT(newColour, size_t(kW));
    EXPECT_GT(layerKept, 0u) << "the layer's lines in the band are still drawn over it";
    // A change of look draws the texture again; turning the layer off restores the image.
    ov.look.fillOpacity = 0.8f;
    ov.layerTexture(cam, kW, kH);
    EXPECT_EQ(ov.layerVersion(), version + 1);
    view.setOverlay(0, 0);
    view.draw(kW, kH, ViewMode::Color, 1.0f);
    const std::vector<uint8_t> plain = gl.read();
    for (size_t i = 0; i < plain.size(); i += 4) {
        const int y = int(i / 4) / kW;
        ASSERT_NEAR(plain[i + 2], y >= b0 && y < b1 ? 26 : 102, 1);
    }
}

TEST(Overlays, WhileTheCameraMovesTheLayerHoldsTheLongestLinesAndAllOnceItRests) {
    OffscreenGl gl(kW, kH);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    auto s = twoBoxes(SchemeKind::Regular);
    Camera cam = s->scene->camera;
    Overlays ov;
    ov.options.leaves = true;
    ov.look.lineOpacity = 1.0f;
    ov.update(s, cam, kW, kH);
    const OverlayGeometry& g = ov.geometry();
    // The same lines, longest first.
    const gl::Batch& longest = g.wiresLongestFirst;
    EXPECT_EQ(longest.lineCount(), g.wires.lineCount());
    EXPECT_TRUE(viewer::testing::sameLineCover(g.wires, longest));
    for (size_t k = 1; k < longest.lineCount(); ++k)
        EXPECT_GE(
            glm::distance(longest.lines[2 * k - 2].position, longest.lines[2 * k - 1].position),
            glm::distance(longest.lines[2 * k].position, longest.lines[2 * k + 1].position));
    // Capped: fewer pixels, all of them lit by the whole layer too.
    const size_t cap = 4;
    ASSERT_GT(g.wires.lineCount(), 3 * cap);
    ov.look.movingLines = cap;
    gl.clear(0, 0, 0);
    ov.drawLayers(cam, kW, kH, cap);
    const std::vector<uint8_t> capped = gl.read();
    gl.clear(0, 0, 0);
    ov.drawLayers(cam, kW, kH);
    const std::vector<uint8_t> whole = gl.read();
    size_t litCapped = 0, litWhole = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            litCapped += lit(capped, x, y);
            litWhole += lit(whole, x, y);
            if (lit(capped, x, y)) {
                EXPECT_TRUE(lit(whole, x, y)) << x << "," << y;
            }
        }
    EXPECT_GT(litCapped, 0u);
    EXPECT_LT(litCapped, litWhole);
    // The texture: capped while moving, once for one view; whole at the first call at rest.
    const unsigned tex = ov.layerTexture(cam, kW, kH, true);
    ASSERT_NE(tex, 0u);
    EXPECT_TRUE(ov.layerPartial());
    EXPECT_TRUE(ov.layerStale(cam, kW, kH)) << "a capped layer is drawn again at rest";
    const uint64_t v = ov.layerVersion();
    EXPECT_EQ(ov.layerTexture(cam, kW, kH, true), tex);
    EXPECT_EQ(ov.layerVersion(), v) << "the same view while moving: not drawn again";
    cam.from.x += 0.5;
    ov.layerTexture(cam, kW, kH, true);
    EXPECT_EQ(ov.layerVersion(), v + 1) << "the camera moved: the capped layer again";
    ov.layerTexture(cam, kW, kH, false);
    EXPECT_EQ(ov.layerVersion(), v + 2);
    EXPECT_FALSE(ov.layerPartial());
    EXPECT_FALSE(ov.layerStale(cam, kW, kH));
    EXPECT_EQ(ov.layerTexture(cam, kW, kH, true), tex) << "at rest and whole: kept while moving";
    // No line while moving: no layer.
    ov.look.movingLines = 0;
    cam.from.y += 0.5;
    EXPECT_EQ(ov.layerTexture(cam, kW, kH, true), 0u);
}

TEST(Overlays, TheShowListTurnsLayersOnAndNamesWhatItDoesNotDraw) {
    OverlayOptions o;
    EXPECT_TRUE(applyShowList("bsp,zones", o).empty());
    EXPECT_TRUE(o.bsp && o.zones && !o.leaves && !o.grid && !o.slabs);
    EXPECT_EQ(applyShowList("leaves,inspector,ray", o),
              (std::vector<std::string>{"inspector", "ray"}));
    EXPECT_TRUE(o.leaves && !o.bsp);
    EXPECT_TRUE(applyShowList("none", o).empty());
    EXPECT_FALSE(o.any());
    try {
        applyShowList("bsp,bogus", o);
        ADD_FAILURE() << "an unknown item must throw";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("bogus"), std::string::npos) << e.what();
    }
}

TEST(Overlays, TheShowListNamesLayersTheSchemeDoesNotHave) {
    // The BVH draws its nodes as the regular scheme draws its leaves (the Overlays panel's
    // "nodes"): `--show leaves` is theirs too.
    EXPECT_EQ(showListMismatch("leaves,tests", SchemeKind::Bvh), "");
    EXPECT_EQ(showListMismatch("leaves,grid", SchemeKind::Regular), "");
    EXPECT_EQ(showListMismatch("bsp,zones,slabs", SchemeKind::Irregular), "");
    EXPECT_NE(showListMismatch("grid", SchemeKind::Bvh).find("no grid"), std::string::npos);
    EXPECT_NE(showListMismatch("leaves", SchemeKind::Irregular).find("no leaves"),
              std::string::npos);
    EXPECT_NE(showListMismatch("slabs", SchemeKind::Regular).find("no slabs"), std::string::npos);
}

}  // namespace
}  // namespace lancer::viewer::overlay
