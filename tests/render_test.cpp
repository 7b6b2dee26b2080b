// Rendering: the golden image of builtin:default, analytic depths at chosen pixels, the depth
// PFM's layout, and per-pixel counters that add up to the totals.
#include <gtest/gtest.h>

#include <cstdio>

#include "engine/render/renderer.h"
#include "engine/render/stats.h"
#include "engine/scene/loader.h"

namespace lancer {
namespace {

struct Rendered {
    Scene scene;
    std::unique_ptr<Accelerator> accel;
    Image img;
    RenderStats stats;
};

Rendered renderScene(const std::string& spec, int w, int h, int bounces = 3) {
    Rendered r{loadScene(spec), nullptr, Image(w, h), {}};
    r.accel = buildAccelerator(r.scene, BuildParams{});
    RenderOptions ro;
    ro.width = w;
    ro.height = h;
    ro.shading.bounces = bounces;
    r.stats = render(r.scene, *r.accel, ro, r.img);
    return r;
}

// Golden image: within 3/255 per channel on 99.5% of pixels and no pixel off by more than
// 64/255 (an edge pixel may flip between two surfaces across compilers, nothing more).
TEST(Golden, DefaultSceneMatchesTheStoredImage) {
    Rendered r = renderScene("builtin:default", 160, 100);
    int gw, gh;
    std::vector<uint8_t> golden =
        readPng(std::string(LANCER_SOURCE_DIR) + "/tests/golden/default_160x100.png", gw, gh);
    ASSERT_EQ(gw, 160);
    ASSERT_EQ(gh, 100);
    std::vector<uint8_t> got = r.img.rgba8();
    int off = 0, worst = 0;
    for (size_t i = 0; i < got.size(); i += 4) {
        int d = 0;
        for (int c = 0; c < 3; ++c)
            d = std::max(d, std::abs(int(got[i + size_t(c)]) - int(golden[i + size_t(c)])));
        off += d > 3;
        worst = std::max(worst, d);
    }
    EXPECT_LE(off, 160 * 100 / 200) << "pixels off by more than 3/255";
    EXPECT_LE(worst, 64);
}

// Ray-plane and ray-sphere distances computed here, independently of the engine.
double planeDistance(const Ray& r, int axis, double value) {
    return (value - r.o[axis]) / r.d[axis];
}
double sphereDistance(const Ray& r, Vec3 c, double radius) {
    Vec3 oc = r.o - c;
    double b = glm::dot(oc, r.d), cc = glm::dot(oc, oc) - radius * radius;
    return -b - std::sqrt(b * b - cc);
}

TEST(Golden, DepthMatchesAnalyticValues) {
    const int w = 160, h = 100;
    Rendered r = renderScene("builtin:default", w, h, 0);
    const Camera& cam = r.scene.camera;
    auto depthAt = [&](int x, int y) { return double(r.img.depth[r.img.index(x, y)]); };
    int checked = 0;
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            Ray ray = cam.primaryRay(x, y, w, h);
            double expected = -1.0;
            // The green rounded cube's front face (y = -1) where the sphere does not cut it.
            double tf = planeDistance(ray, 1, -1.0);
            Vec3 pf = ray.at(tf);
            if (std::abs(pf.x) < 0.85 && std::abs(pf.z) < 0.85 && pf.x * pf.x + pf.z * pf.z < 0.8)
                expected = tf;
            // The red sphere's front (above the cylinder, in front of nothing else).
            Vec3 red(-3.0, 0.0, 0.6);
            Vec3 oc = ray.o - red;
            double b = glm::dot(oc, ray.d);
            if (b * b - (glm::dot(oc, oc) - 0.81) > 0.05 &&
                ray.at(sphereDistance(ray, red, 0.9)).z > 0.2)
                expected = sphereDistance(ray, red, 0.9);
            // The floor's top (z = -1) in the front strip, clear of every object's shadow of view.
            double tz = planeDistance(ray, 2, -1.0);
            Vec3 pz = ray.at(tz);
            if (tz > 0 && pz.y < -3.0 && pz.y > -3.9 && std::abs(pz.x) < 5.5) expected = tz;
            if (expected < 0) continue;
            EXPECT_NEAR(depthAt(x, y), expected, 2e-6 * expected) << "pixel " << x << " " << y;
            ++checked;
        }
    }
    EXPECT_GT(checked, 500);
    // A pixel at the top corner sees only the background: +inf.
    EXPECT_TRUE(std::isinf(depthAt(0, 0)));
}

TEST(Render, PixelRaysAreCameraPrimaryRaysBitForBit) {
    // The render's rays come from per-column and per-row terms: each must be the ray that
    // Camera::primaryRay (trace, the viewer's picks, the structure overlays) gives.
    for (Projection projection : {Projection::Perspective, Projection::Orthographic}) {
        Camera cam;
        cam.from = {1.3, -7.1, 2.9};
        cam.at = {-0.4, 0.6, 0.2};
        cam.up = {0.1, 0.2, 1.0};
        cam.fov = 37.0;
        cam.projection = projection;
        cam.orthoHeight = 6.5;
        for (auto [w, h] : {std::pair{97, 61}, std::pair{64, 200}}) {
            const PrimaryRays rays(cam, w, h);
            for (int y = 0; y < h; ++y) {
                for (int x = 0; x < w; ++x) {
                    const Ray a = rays.pixel(x, y), b = cam.primaryRay(x, y, w, h);
                    for (int k = 0; k < 3; ++k) {
                        ASSERT_EQ(a.o[k], b.o[k]) << x << " " << y;
                        ASSERT_EQ(a.d[k], b.d[k]) << x << " " << y;
                    }
                }
            }
        }
    }
}

TEST(Render, DepthPfmIsStandardBottomToTop) {
    Rendered r = renderScene("builtin:default", 40, 25, 0);
    std::string path = ::testing::TempDir() + "/depth.pfm";
    writeDepthPfm(path, r.img);
    FILE* f = std::fopen(path.c_str(), "rb");
    ASSERT_NE(f, nullptr);
    char header[32] = {};
    ASSERT_EQ(std::fread(header, 1, 13, f), 13u);
    std::fclose(f);
    EXPECT_EQ(std::string(header, 13), "Pf\n40 25\n-1.0");
    int w, h;
    std::vector<float> back = readPfm(path, w, h);
    ASSERT_EQ(back.size(), r.img.depth.size());
    for (size_t i = 0; i < back.size(); ++i)
        ASSERT_TRUE(back[i] == r.img.depth[i] ||
                    (std::isinf(back[i]) && std::isinf(r.img.depth[i])));
}

TEST(Render, PerPixelCountersAddUpAndThreadsDoNotChangeTheImage) {
    Rendered one = renderScene("builtin:default", 64, 40);
    uint64_t sum = 0;
    for (uint32_t v : one.img.primTests) sum += v;
    EXPECT_EQ(sum, one.stats.counters.primTests);
    EXPECT_EQ(one.stats.counters.primaryRays, 64u * 40u);
    EXPECT_GT(one.stats.counters.shadowRays, 0u);
    EXPECT_GT(one.stats.counters.rays,
              one.stats.counters.primaryRays + one.stats.counters.shadowRays);
    // Single-threaded gives the same pixels.
    Scene s = loadScene("builtin:default");
    auto accel = buildAccelerator(s, BuildParams{});
    RenderOptions ro;
    ro.width = 64, ro.height = 40, ro.threads = 1;
    Image img(64, 40);
    render(s, *accel, ro, img);
    EXPECT_EQ(img.rgba8(), one.img.rgba8());
    nlohmann::json j = statsJson(s, *accel, ro, one.stats);
    for (const char* key : {"scheme", "width", "height", "threads", "build_ms", "render_ms", "rays",
                            "primary_rays", "prim_tests", "mailbox_hits", "region_visits",
                            "regions", "memory_bytes", "max_level", "max_objects", "step"})
        EXPECT_TRUE(j.contains(key)) << key;
}

TEST(Render, PixelTimesAddUpToTheRenderTime) {
    // Per-pixel times (the viewer's time heat map) are counter ticks turned into microseconds per
    // tile: on one thread they add up to about the render's wall time, and slow pixels show.
    Scene s = loadScene("builtin:balls:2");
    auto accel = buildAccelerator(s, BuildParams{});
    RenderOptions ro;
    ro.width = 160, ro.height = 100, ro.threads = 1;
    Image img(160, 100);
    RenderStats st = render(s, *accel, ro, img);
    double sumUs = 0.0;
    std::vector<std::pair<uint32_t, float>> work;  // (primitive tests, time) per pixel
    for (size_t i = 0; i < img.timeUs.size(); ++i) {
        ASSERT_GT(img.timeUs[i], 0.0f) << "pixel " << i;
        ASSERT_LT(img.timeUs[i], 1e6f) << "pixel " << i;
        sumUs += img.timeUs[i];
        work.push_back({img.primTests[i] + img.regionVisits[i], img.timeUs[i]});
    }
    EXPECT_LE(sumUs, 1000.0 * st.renderMs * 1.02);
    EXPECT_GE(sumUs, 1000.0 * st.renderMs * 0.5);
    // The quarter of pixels with the most tests and visits take longer than the quarter with
    // the fewest.
    std::sort(work.begin(), work.end());
    const size_t q = work.size() / 4;
    double low = 0.0, high = 0.0;
    for (size_t i = 0; i < q; ++i) low += work[i].second, high += work[work.size() - 1 - i].second;
    EXPECT_GT(high, 1.5 * low);
}

TEST(Render, ProgressivePassesCoverEveryPixelOnce) {
    Scene s = loadScene("builtin:default");
    auto accel = buildAccelerator(s, BuildParams{});
    RenderOptions ro;
    ro.width = 37, ro.height = 23;
    Image img(37, 23);
    uint64_t primary = 0;
    int prev = 0;
    for (int stride : {8, 4, 2, 1}) {
        primary += render(s, *accel, ro, img, PassLattice{stride, prev}).counters.primaryRays;
        prev = stride;
    }
    EXPECT_EQ(primary, 37u * 23u);
    Image full(37, 23);
    render(s, *accel, ro, full);
    EXPECT_EQ(full.rgba8(), img.rgba8());
}

TEST(Render, CancelStopsEarly) {
    Scene s = loadScene("builtin:balls:2");
    auto accel = buildAccelerator(s, BuildParams{});
    RenderOptions ro;
    ro.width = 256, ro.height = 256;
    Image img(256, 256);
    std::atomic<bool> cancel{true};
    RenderStats st = render(s, *accel, ro, img, {}, &cancel);
    EXPECT_TRUE(st.cancelled);
    EXPECT_LT(st.counters.primaryRays, 256u * 256u);
}

}  // namespace
}  // namespace lancer
