// The GL room (app/viewer/gl/): embedded shaders and their errors, batches of lines and fills in
// image pixels and in world space, drawn where the tracer's pixels are.
#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "app/viewer/gl/batch.h"
#include "app/viewer/gl/program.h"
#include "app/viewer/gl/transforms.h"
#include "tests/gl/line_cover.h"
#include "tests/gl/offscreen_gl.h"

namespace lancer::viewer::gl {
namespace {

using viewer::testing::OffscreenGl;

const uint8_t* at(const std::vector<uint8_t>& px, int w, int x, int y) {
    return &px[(size_t(y) * size_t(w) + size_t(x)) * 4];
}

bool isColor(const uint8_t* p, int r, int g, int b, int tol = 2) {
    return std::abs(p[0] - r) <= tol && std::abs(p[1] - g) <= tol && std::abs(p[2] - b) <= tol;
}

TEST(GlRoom, EveryShaderFileIsEmbeddedAndErrorsNameTheShader) {
    for (const char* name : {"image.vert", "image.frag", "batch.vert", "batch.frag"})
        EXPECT_NE(std::string(shaderSource(name)).find("#version 330 core"), std::string::npos)
            << name;
    try {
        shaderSource("missing.frag");
        ADD_FAILURE() << "an unknown shader must throw";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("missing.frag"), std::string::npos) << e.what();
    }
    OffscreenGl gl(8, 8);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    try {
        Program bad(shaderSource("batch.vert"), "#version 330 core\nvoid main() { oops; }\n",
                    "broken.frag");
        ADD_FAILURE() << "a shader that does not compile must throw";
    } catch (const std::runtime_error& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("broken.frag (fragment)"), std::string::npos) << what;
        EXPECT_NE(what.find("oops"), std::string::npos) << "the compiler's log: " << what;
    }
    Program good("batch.vert", "batch.frag");
    EXPECT_NE(good.id(), 0u);
    EXPECT_GE(good.uniform("toClip"), 0);
}

TEST(GlRoom, ImageSpaceLinesAndTranslucentFillsLandOnTheirPixels) {
    const int w = 64, h = 48;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    gl.clear(0, 0, 0);
    BatchRenderer renderer;
    Batch b;
    // Through pixel centres: a row and a column of pixels.
    b.line(glm::vec2(4.5f, 10.5f), glm::vec2(40.5f, 10.5f), rgba8(glm::vec3(1, 0, 0)));
    b.line(glm::vec2(50.5f, 2.5f), glm::vec2(50.5f, 30.5f), rgba8(glm::vec3(0, 1, 0)));
    b.fillRect({20.0f, 30.0f}, {30.0f, 40.0f}, rgba8(glm::vec3(0, 0, 1), 0.5f));
    GpuBatch gpu;
    gpu.upload(b);
    EXPECT_EQ(gpu.lineCount(), 2u);
    EXPECT_EQ(gpu.triangleCount(), 2u);
    renderer.draw(gpu, imagePixelsToClip(float(w), float(h)));
    auto px = gl.read();
    for (int x = 6; x <= 39; ++x) {
        EXPECT_TRUE(isColor(at(px, w, x, 10), 255, 0, 0)) << x;
        EXPECT_TRUE(isColor(at(px, w, x, 9), 0, 0, 0)) << x;
        EXPECT_TRUE(isColor(at(px, w, x, 11), 0, 0, 0)) << x;
    }
    for (int y = 4; y <= 29; ++y) EXPECT_TRUE(isColor(at(px, w, 50, y), 0, 255, 0)) << y;
    // Half-transparent blue over black: half blue, inside [20, 30) x [30, 40) only.
    EXPECT_TRUE(isColor(at(px, w, 25, 35), 0, 0, 128, 2));
    EXPECT_TRUE(isColor(at(px, w, 20, 30), 0, 0, 128, 2));
    EXPECT_TRUE(isColor(at(px, w, 29, 39), 0, 0, 128, 2));
    EXPECT_TRUE(isColor(at(px, w, 19, 35), 0, 0, 0));
    EXPECT_TRUE(isColor(at(px, w, 30, 35), 0, 0, 0));
    EXPECT_TRUE(isColor(at(px, w, 25, 40), 0, 0, 0));

    // A line range draws only its segments; the opacity scales alpha.
    gl.clear(0, 0, 0);
    DrawOptions only2;
    only2.firstLine = 1;
    only2.triangles = false;
    renderer.draw(gpu, imagePixelsToClip(float(w), float(h)), only2);
    px = gl.read();
    EXPECT_TRUE(isColor(at(px, w, 20, 10), 0, 0, 0)) << "the first segment is out of range";
    EXPECT_TRUE(isColor(at(px, w, 50, 20), 0, 255, 0));
    EXPECT_TRUE(isColor(at(px, w, 25, 35), 0, 0, 0)) << "triangles were turned off";
    gl.clear(0, 0, 0);
    DrawOptions faint;
    faint.opacity = 0.5f;
    Batch once;
    once.line(glm::vec2(0.0f, 5.5f), glm::vec2(float(w), 5.5f), rgba8(glm::vec3(1, 1, 1)));
    renderer.drawNow(once, imagePixelsToClip(float(w), float(h)), faint);
    px = gl.read();
    EXPECT_TRUE(isColor(at(px, w, 30, 5), 128, 128, 128, 2));
}

TEST(GlRoom, ABatchOfSeveralBuffersIsCopiedInPartsAndDrawsRangesAcrossThem) {
    const int w = 64, h = 48;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    BatchRenderer renderer;
    // Line k across row k % h: more lines than two buffers hold.
    const size_t perChunk = GpuBatch::kChunkVertices / 2, n = 2 * perChunk + 100;
    Batch b;
    for (size_t k = 0; k < n; ++k) {
        const float y = float(k % size_t(h)) + 0.5f;
        b.line(glm::vec2(0.0f, y), glm::vec2(float(w), y), rgba8(glm::vec3(1, 1, 1)));
    }
    GpuBatch gpu;
    gpu.beginUpload(b);
    EXPECT_EQ(gpu.lineCount(), 0u);
    int parts = 0;
    size_t before = 0;
    while (!gpu.uploadMore(size_t(1) << 20) && parts < 100) {
        ++parts;
        EXPECT_GT(gpu.lineCount(), before) << "copied in order, a part at a time";
        before = gpu.lineCount();
        EXPECT_LT(before, n);
    }
    EXPECT_GE(parts, 3);
    EXPECT_EQ(gpu.lineCount(), n);
    EXPECT_TRUE(gpu.uploaded());
    // A range across the first buffers' boundary draws its lines and no other.
    DrawOptions range;
    range.firstLine = perChunk - 5;
    range.lineLimit = 10;
    gl.clear(0, 0, 0);
    renderer.draw(gpu, imagePixelsToClip(float(w), float(h)), range);
    auto px = gl.read();
    for (size_t k = range.firstLine - 3; k < range.firstLine + range.lineLimit + 3; ++k) {
        const bool in = k >= range.firstLine && k < range.firstLine + range.lineLimit;
        EXPECT_EQ(isColor(at(px, w, w / 2, int(k % size_t(h))), 255, 255, 255), in) << k;
    }
    // Every line of a batch copied again in one go (smaller: a buffer given back).
    Batch small;
    small.line(glm::vec2(0.0f, 3.5f), glm::vec2(float(w), 3.5f), rgba8(glm::vec3(0, 1, 0)));
    gpu.upload(small);
    EXPECT_EQ(gpu.lineCount(), 1u);
    gl.clear(0, 0, 0);
    renderer.draw(gpu, imagePixelsToClip(float(w), float(h)));
    px = gl.read();
    EXPECT_TRUE(isColor(at(px, w, w / 2, 3), 0, 255, 0));
    EXPECT_TRUE(isColor(at(px, w, w / 2, 4), 0, 0, 0));
}

Camera orthoCamera() {
    Camera c;
    c.from = {0.0, 0.0, 10.0};
    c.at = {0.0, 0.0, 0.0};
    c.up = {0.0, 1.0, 0.0};
    c.projection = Projection::Orthographic;
    c.orthoHeight = 10.0;  // 100 pixels: 10 pixels a unit
    return c;
}

TEST(GlRoom, WorldSpaceBoxesProjectAsTheTracersRays) {
    // CPU projection: a point on pixel (i, j)'s primary ray lands on that pixel's centre.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Camera persp;
    persp.from = {1.0, -8.0, 2.0};
    persp.at = {0.0, 0.0, 0.5};
    persp.up = {0.0, 0.0, 1.0};
    persp.fov = 50.0;
    for (const Camera& cam : {persp, orthoCamera()}) {
        const int w = 160, h = 90;
        ImageProjector proj(cam, w, h);
        const glm::dmat4 m = glm::dmat4(worldToClip(cam, w, h, 0.01, 100.0));
        for (int k = 0; k < 50; ++k) {
            const double x = std::floor(u(rng) * w), y = std::floor(u(rng) * h);
            const Ray ray = cam.primaryRay(x, y, w, h);
            const Vec3 p = ray.at(1.0 + 9.0 * u(rng));
            const auto q = proj.toImage(p);
            ASSERT_TRUE(q.has_value());
            EXPECT_NEAR(q->x, x + 0.5, 1e-9);
            EXPECT_NEAR(q->y, y + 0.5, 1e-9);
            const glm::dvec4 c = m * glm::dvec4(p, 1.0);  // the GL matrix agrees (in float)
            EXPECT_NEAR((c.x / c.w + 1.0) * 0.5 * w, x + 0.5, 1e-3);
            EXPECT_NEAR((1.0 - c.y / c.w) * 0.5 * h, y + 0.5, 1e-3);
        }
    }
    ImageProjector behind(persp, 10, 10);
    EXPECT_FALSE(behind.toImage(Vec3(1.0, -20.0, 2.0)).has_value());

    // A box under the orthographic camera: edges on the pixel columns and rows they project to
    // (x = -2.05 is continuous x 29.5, the centre of column 29).
    const int w = 100, h = 100;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    gl.clear(0, 0, 0);
    BatchRenderer renderer;
    Batch b;
    b.box(glm::vec3(-2.05f, -1.05f, -1.0f), glm::vec3(1.95f, 2.95f, 1.0f),
          rgba8(glm::vec3(1, 1, 0)));
    renderer.drawNow(b, worldToClip(orthoCamera(), w, h, 0.0, 20.0));
    auto px = gl.read();
    // Columns 29 and 69, rows 60 (y = -1.05) and 20 (y = 2.95), image row 0 on top.
    for (int y = 22; y <= 58; ++y) {
        EXPECT_TRUE(isColor(at(px, w, 29, y), 255, 255, 0)) << y;
        EXPECT_TRUE(isColor(at(px, w, 69, y), 255, 255, 0)) << y;
        EXPECT_TRUE(isColor(at(px, w, 49, y), 0, 0, 0)) << y;
    }
    for (int x = 31; x <= 67; ++x) {
        EXPECT_TRUE(isColor(at(px, w, x, 20), 255, 255, 0)) << x;
        EXPECT_TRUE(isColor(at(px, w, x, 60), 255, 255, 0)) << x;
        EXPECT_TRUE(isColor(at(px, w, x, 40), 0, 0, 0)) << x;
    }
}

/// The boxes of a random BSP of [0, 16)^3 cut at integer planes (faces shared, edges lying
/// partly on longer ones), coloured by depth among three colours, as Batch::box draws them.
void randomBsp(std::mt19937& rng, glm::vec3 lo, glm::vec3 hi, int depth, Batch& out) {
    std::uniform_int_distribution<int> axisOf(0, 2);
    const int a = axisOf(rng);
    const int span = int(hi[a] - lo[a]);
    if (depth == 0 || span < 2 || (depth < 5 && rng() % 4 == 0)) {
        const glm::vec3 palette[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
        out.box(lo, hi, rgba8(palette[depth % 3]));
        return;
    }
    const int cut = std::uniform_int_distribution<int>(1, span - 1)(rng);
    glm::vec3 mid = hi;
    mid[a] = lo[a] + float(cut);
    randomBsp(rng, lo, mid, depth - 1, out);
    mid = lo;
    mid[a] = lo[a] + float(cut);
    randomBsp(rng, mid, hi, depth - 1, out);
}

TEST(GlRoom, MergedLinesCoverExactlyTheSegmentsTheyReplace) {
    for (uint32_t seed = 1; seed <= 20; ++seed) {
        SCOPED_TRACE(seed);
        std::mt19937 rng(seed);
        Batch b;
        randomBsp(rng, glm::vec3(0.0f), glm::vec3(16.0f), 7, b);
        const size_t edges = b.lineCount();
        // Segments that are not merged: oblique, two-coloured, of no length; and a fill.
        b.line(glm::vec3(0, 0, 0), glm::vec3(3, 4, 0), rgba8(glm::vec3(1, 0, 0)));
        b.lines.push_back({glm::vec3(0, 0, 0), rgba8(glm::vec3(1, 0, 0))});
        b.lines.push_back({glm::vec3(16, 0, 0), rgba8(glm::vec3(0, 1, 0))});
        b.line(glm::vec3(5, 5, 5), glm::vec3(5, 5, 5), rgba8(glm::vec3(1, 0, 0)));
        b.fillRect({0.0f, 0.0f}, {1.0f, 1.0f}, rgba8(glm::vec3(1, 1, 1), 0.5f));
        const Batch m = mergeCollinearLines(b);
        EXPECT_TRUE(viewer::testing::sameLineCover(b, m));
        // Shared faces: far fewer lines.
        if (edges > 12 * 8) {
            EXPECT_LT(m.lineCount(), edges * 3 / 4) << edges << " edges";
        }
        // Merging again changes nothing.
        const Batch again = mergeCollinearLines(m);
        EXPECT_EQ(again.lineCount(), m.lineCount());
        EXPECT_TRUE(viewer::testing::sameLineCover(m, again));
    }
    // The checker itself tells a gap and a colour apart.
    Batch two, gap, recoloured;
    two.line(glm::vec3(0, 0, 0), glm::vec3(2, 0, 0), rgba8(glm::vec3(1, 0, 0)));
    two.line(glm::vec3(1, 0, 0), glm::vec3(3, 0, 0), rgba8(glm::vec3(1, 0, 0)));
    gap.line(glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), rgba8(glm::vec3(1, 0, 0)));
    gap.line(glm::vec3(1.5f, 0, 0), glm::vec3(3, 0, 0), rgba8(glm::vec3(1, 0, 0)));
    recoloured.line(glm::vec3(0, 0, 0), glm::vec3(3, 0, 0), rgba8(glm::vec3(0, 1, 0)));
    const Batch merged = mergeCollinearLines(two);
    ASSERT_EQ(merged.lineCount(), 1u);
    EXPECT_EQ(merged.lines[0].position, glm::vec3(0, 0, 0));
    EXPECT_EQ(merged.lines[1].position, glm::vec3(3, 0, 0));
    EXPECT_TRUE(viewer::testing::sameLineCover(two, merged));
    EXPECT_FALSE(viewer::testing::sameLineCover(two, gap));
    EXPECT_FALSE(viewer::testing::sameLineCover(two, recoloured));
    EXPECT_FALSE(viewer::testing::sameLineCover(two, two)) << "two is not maximal";
}

TEST(GlRoom, MergedBoxEdgesDrawThePixelsOfEveryEdge) {
    // Boxes of a BSP seen obliquely in perspective, drawn opaque. Colour by colour, the merged
    // lines light the pixels the twelve edges of every box light, but for a line's end pixel
    // where two segments that touched are now one. Together, each pixel shows one of the
    // colours drawn there: only which colour lands on top where two overlap may differ (the
    // order changed).
    const int w = 160, h = 120;
    OffscreenGl gl(w, h);
    ASSERT_TRUE(gl.ok()) << "OSMesa could not create an OpenGL 3.3 core context";
    std::mt19937 rng(3);
    Batch b;
    randomBsp(rng, glm::vec3(0.0f), glm::vec3(16.0f), 8, b);
    const Batch m = mergeCollinearLines(b);
    ASSERT_LT(m.lineCount(), b.lineCount() * 2 / 3);
    Camera cam;
    cam.from = {30.0, -22.0, 26.0};
    cam.at = {8.0, 8.0, 8.0};
    cam.up = {0.0, 0.0, 1.0};
    cam.fov = 45.0;
    const glm::mat4 toClip = worldToClip(cam, w, h, 1.0, 100.0);
    BatchRenderer renderer;
    auto draw = [&](const Batch& batch) {
        gl.clear(0, 0, 0);
        renderer.drawNow(batch, toClip);
        return gl.read();
    };
    auto isLit = [](const std::vector<uint8_t>& px, size_t i) {
        return (px[i] | px[i + 1] | px[i + 2]) != 0;
    };
    auto only = [](const Batch& batch, Rgba8 c) {
        Batch out;
        for (size_t k = 0; k < batch.lineCount(); ++k)
            if (batch.lines[2 * k].color == c)
                out.line(batch.lines[2 * k].position, batch.lines[2 * k + 1].position, c);
        return out;
    };
    const std::vector<uint8_t> before = draw(b), after = draw(m);
    std::vector<std::vector<uint8_t>> colourLit;
    for (const glm::vec3& c : {glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)}) {
        const std::vector<uint8_t> x = draw(only(b, rgba8(c))), y = draw(only(m, rgba8(c)));
        size_t lit = 0, differ = 0;
        for (size_t i = 0; i < x.size(); i += 4) {
            lit += isLit(x, i);
            differ += isLit(x, i) != isLit(y, i);
        }
        EXPECT_GT(lit, 100u) << "colour " << c.x << c.y << c.z;
        EXPECT_LE(differ, lit / 200) << "colour " << c.x << c.y << c.z << ": " << differ << " of "
                                     << lit << " pixels lit by one drawing only";
        colourLit.push_back(x);
    }
    size_t foreign = 0;
    for (size_t i = 0; i < after.size(); i += 4) {
        if (!isLit(after, i) || std::equal(&before[i], &before[i + 3], &after[i])) continue;
        bool drawnThere = false;
        for (const auto& x : colourLit)
            drawnThere |= isLit(x, i) && std::equal(&x[i], &x[i + 3], &after[i]);
        foreign += !drawnThere;
    }
    EXPECT_EQ(foreign, 0u) << "pixels of a colour no edge there had";
}

}  // namespace
}  // namespace lancer::viewer::gl
