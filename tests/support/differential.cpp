#include "tests/support/differential.h"

#include <gtest/gtest.h>

#include <sstream>

#include "engine/accel/irregular/camera_frame.h"

namespace lancer::test {

Scene randomCsgScene(uint64_t seed, const RandomSceneOptions& opt) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0), pos(0.3, 1.5);
    Scene s;
    s.name = "random:" + std::to_string(seed);
    std::vector<int> nodes;
    const int groups = std::max(1, opt.groups);
    const int perGroup = (opt.primitives + groups - 1) / groups;
    Vec3 centre(0.0);
    for (int i = 0; i < opt.primitives; ++i) {
        Vec3 c;
        if (groups == 1) {
            c = opt.spread * Vec3(u(rng), u(rng), u(rng));
        } else {
            if (i % perGroup == 0) centre = opt.spread * Vec3(u(rng), u(rng), u(rng));
            c = centre + 1.5 * Vec3(u(rng), u(rng), u(rng));
        }
        Shape shape;
        Transform xf = Transform::translate(c + opt.offset);
        switch (rng() % (opt.tori ? 5 : 4)) {
            case 0:
                shape = Sphere{Vec3(0.0), pos(rng)};
                break;
            case 1:
                shape =
                    Block{-Vec3(pos(rng), pos(rng), pos(rng)), Vec3(pos(rng), pos(rng), pos(rng))};
                break;
            case 2: {
                double r = pos(rng);
                shape = Cone{r, r, 2.0 * pos(rng), false};
                break;
            }
            case 3:
                shape = Cone{pos(rng), (rng() % 3 == 0) ? 0.0 : pos(rng), 2.0 * pos(rng), false};
                break;
            default: {  // a ring torus, one in four a horn torus (R = r, its hole closed)
                const double r = 0.5 * pos(rng);
                shape = Torus{rng() % 4 == 0 ? r : r + pos(rng), r};
                break;
            }
        }
        if (opt.transforms && rng() % 2) {
            xf = xf * Transform::rotate(180.0 * u(rng), {u(rng), u(rng), u(rng) + 1.5}) *
                 Transform::scale({pos(rng), pos(rng), pos(rng)});
        }
        s.prims.push_back(makePrimitive(shape, xf, 0));
        nodes.push_back(s.tree.leaf(uint32_t(s.prims.size() - 1)));
    }
    // Random binary trees, one per group: repeatedly combine two random nodes of the group with
    // a random operator.
    std::vector<int> roots;
    for (size_t g0 = 0; g0 < nodes.size(); g0 += size_t(perGroup)) {
        std::vector<int> group(nodes.begin() + long(g0),
                               nodes.begin() + long(std::min(nodes.size(), g0 + size_t(perGroup))));
        while (group.size() > 1) {
            size_t i = rng() % group.size();
            int a = group[i];
            group.erase(group.begin() + long(i));
            size_t j = rng() % group.size();
            int b = group[j];
            Op op = std::array<Op, 4>{Op::Union, Op::Union, Op::Intersection,
                                      Op::Difference}[rng() % 4];
            group[j] = s.tree.combine(op, a, b);
        }
        roots.push_back(group[0]);
    }
    int root = roots.empty() ? -1 : s.tree.balanced(Op::Union, roots);
    if (opt.surfaces) {
        std::vector<int> top{root};
        for (int i = 0; i < 4; ++i) {
            Vec3 c = opt.spread * Vec3(u(rng), u(rng), u(rng)) + opt.offset;
            Triangle t;
            for (auto& p : t.p) p = c + 2.0 * Vec3(u(rng), u(rng), u(rng));
            s.prims.push_back(makePrimitive(t, Transform(), 0));
            top.push_back(s.tree.leaf(uint32_t(s.prims.size() - 1)));
            Cone open{pos(rng), pos(rng), 2.0 * pos(rng), true};
            s.prims.push_back(makePrimitive(
                open, Transform::translate(c) * Transform::rotate(90.0 * u(rng), {1, 0, 0}), 0));
            top.push_back(s.tree.leaf(uint32_t(s.prims.size() - 1)));
        }
        root = s.tree.balanced(Op::Union, top);
    }
    s.tree.root = root;
    s.prepare();
    s.frameCamera({-1.0, 2.0, -1.0}, {0, 0, 1});
    s.defaultLights();
    return s;
}

Scene turnedBars(uint64_t seed, int count, double degrees) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0), thin(0.05, 0.25), len(2.5, 4.5);
    const double angle = 30.0 + 120.0 * std::abs(u(rng));
    const Transform turn =
        Transform::translate(Vec3(u(rng), u(rng), u(rng))) *
        Transform::rotate(degrees < 0.0 ? angle : degrees, {u(rng), u(rng), u(rng) + 1.5});
    Scene s;
    s.name = "turned-bars:" + std::to_string(seed);
    std::vector<int> nodes;
    for (int i = 0; i < count; ++i) {
        const int axis = int(rng() % 3);
        Transform xf = turn * Transform::translate(2.5 * Vec3(u(rng), u(rng), u(rng)));
        Shape shape;
        switch (rng() % 3) {
            case 0: {
                Vec3 h(thin(rng));
                h[axis] = len(rng);
                shape = Block{-h, h};
                break;
            }
            case 1: {
                const double r = thin(rng);
                shape = Cone{r, r, 2.0 * len(rng), false};
                if (axis < 2)
                    xf = xf * Transform::rotate(90.0, axis == 0 ? Vec3(0, 1, 0) : Vec3(1, 0, 0));
                break;
            }
            default:
                shape = Sphere{Vec3(0.0), 0.5 + thin(rng)};
        }
        s.prims.push_back(makePrimitive(shape, xf, 0));
        nodes.push_back(s.tree.leaf(uint32_t(s.prims.size() - 1)));
    }
    while (nodes.size() > 1) {
        const size_t i = rng() % nodes.size();
        const int a = nodes[i];
        nodes.erase(nodes.begin() + long(i));
        const size_t j = rng() % nodes.size();
        // Mostly unions and differences: intersections of thin bars are mostly empty.
        const Op op =
            std::array<Op, 6>{Op::Union,      Op::Union,      Op::Union,
                              Op::Difference, Op::Difference, Op::Intersection}[rng() % 6];
        nodes[j] = s.tree.combine(op, a, nodes[j]);
    }
    s.tree.root = nodes[0];
    s.prepare();
    s.frameCamera({-1.0, 2.0, -1.0}, {0, 0, 1});
    return s;
}

Scene randomGlassyCsgScene(uint64_t seed, const RandomSceneOptions& opt) {
    Scene scene = randomCsgScene(seed, opt);
    scene.materials[0].reflect = 0.3;
    scene.materials[0].transmit = 0.5;
    scene.materials[0].ior = 1.4;
    scene.frameCamera(Vec3(0.3, 1.0, -0.4), Vec3(0.0, 0.0, 1.0));
    scene.defaultLights();
    return scene;
}

void makeOrthographic(Scene& scene) {
    const CameraFrame f = CameraFrame::of(scene.camera);
    const Box3 b = f.box(scene.bounds);
    scene.camera.projection = Projection::Orthographic;
    scene.camera.orthoHeight = 1.1 * std::max(b.extent().x, b.extent().y);
    // The orthographic eye plane must stand in front of the scene for primary rays to see it all.
    scene.camera.from = f.toWorld({0.5 * (b.lo.x + b.hi.x), 0.5 * (b.lo.y + b.hi.y), b.lo.z - 1.0});
    scene.camera.at = scene.camera.from + f.z;
}

std::vector<Ray> randomRays(const Scene& scene, uint64_t seed, int count) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Box3 b = scene.bounds.isEmpty() ? Box3{Vec3(-1.0), Vec3(1.0)} : scene.bounds;
    Vec3 ext = b.extent();
    double diag = std::max(glm::length(ext), 1e-9);
    auto inside = [&] { return b.lo + Vec3(u(rng), u(rng), u(rng)) * ext; };
    std::vector<Ray> rays;
    rays.reserve(size_t(count));
    for (int i = 0; i < count; ++i) {
        Vec3 target = inside();
        Vec3 origin;
        switch (i % 4) {
            case 0:  // from far outside
            case 1: {
                Vec3 d = glm::normalize(Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) + 1e-3);
                origin = b.center() + d * diag * 1.5;
                break;
            }
            case 2:
                origin = inside();
                break;  // from inside the scene
            default: {  // axis-parallel
                int axis = int(rng() % 3);
                Vec3 d(0.0);
                d[axis] = (rng() % 2) ? 1.0 : -1.0;
                rays.push_back({target - d * diag * 1.5, d});
                continue;
            }
        }
        Vec3 d = target - origin;
        if (glm::dot(d, d) == 0.0) d = Vec3(0, 0, 1);
        rays.push_back({origin, glm::normalize(d)});
    }
    return rays;
}

std::vector<Ray> raysThroughPoints(const std::vector<Vec3>& points, const Box3& bounds,
                                   uint64_t seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    double diag = std::max(glm::length(bounds.extent()), 1e-9);
    std::vector<Ray> rays;
    for (const Vec3& p : points) {
        Vec3 d = glm::normalize(Vec3(u(rng), u(rng), u(rng)) + 1e-3);
        rays.push_back({p - d * diag, d});  // aimed exactly at p
        rays.push_back({p, d});             // starting exactly on p
        int axis = int(rng() % 3);
        Vec3 a(0.0);
        a[axis] = (rng() % 2) ? 1.0 : -1.0;
        rays.push_back({p - a * diag, a});  // axis-parallel through p
        // Diagonal through p in a coordinate plane (exits through edges and corners).
        Vec3 diag2(0.0);
        diag2[axis] = 1.0;
        diag2[(axis + 1) % 3] = 1.0;
        rays.push_back({p - diag2 * diag, glm::normalize(diag2)});
    }
    return rays;
}

std::string RayMismatch::toString(const Scene& scene) const {
    std::ostringstream os;
    os.precision(17);
    os << ray.toString() << "\n  brute: ";
    if (expectedFound)
        os << "t=" << expected.t << " p" << expected.prim << " "
           << scene.prims[expected.prim].toString();
    else
        os << "miss";
    os << "\n  got:   ";
    if (gotFound)
        os << "t=" << got.t << " p" << got.prim << " " << scene.prims[got.prim].toString();
    else
        os << "miss";
    return os.str();
}

std::vector<RayMismatch> compareWithBrute(const Scene& scene, const Accelerator& accel,
                                          const std::vector<Ray>& rays, double tmin, double relTol,
                                          size_t maxReport, Precision precision) {
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    auto brute = buildAccelerator(scene, bp);
    TraceContext cb(scene.prims.size(), scene.tree.depth()),
        ca(scene.prims.size(), scene.tree.depth());
    cb.useMailboxes = brute->usesMailboxes();
    ca.useMailboxes = accel.usesMailboxes();
    cb.precision = ca.precision = precision;
    NullObserver obs;
    std::vector<RayMismatch> out;
    for (const Ray& r : rays) {
        Hit hb, ha;
        cb.beginRay();
        ca.beginRay();
        bool fb = brute->intersect(r, tmin, kInf, cb, obs, hb);
        bool fa = accel.intersect(r, tmin, kInf, ca, obs, ha);
        bool same = fb == fa;
        if (same && fb) {
            double scale = std::max(1.0, std::abs(hb.t));
            same = std::abs(hb.t - ha.t) <= relTol * scale &&
                   (hb.prim == ha.prim || hb.t == ha.t);  // equal t on two primitives: a tie
        }
        if (!same && out.size() < maxReport) out.push_back({r, hb, ha, fb, fa});
    }
    return out;
}

RayCounters traceCounters(const Scene& scene, const Accelerator& accel,
                          const std::vector<Ray>& rays, double tmin) {
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    ctx.useMailboxes = accel.usesMailboxes();
    NullObserver obs;
    for (const Ray& r : rays) {
        Hit h;
        ctx.beginRay();
        accel.intersect(r, tmin, kInf, ctx, obs, h);
    }
    return ctx.counters;
}

RecordingObserver recordWalk(const Accelerator& accel, const Ray& ray, TraceContext& ctx) {
    RecordingObserver obs;
    Hit hit;
    ctx.beginRay();
    accel.intersect(ray, 0.0, kInf, ctx, obs, hit);
    return obs;
}

bool bruteHit(const Scene& scene, const Ray& ray, Hit& hit) {
    BuildParams bp;
    bp.scheme = SchemeKind::Brute;
    auto brute = buildAccelerator(scene, bp);
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    NullObserver obs;
    ctx.beginRay();
    return brute->intersect(ray, 0.0, kInf, ctx, obs, hit);
}

std::vector<Ray> pixelRays(const Scene& scene, int w, int h) {
    std::vector<Ray> rays;
    rays.reserve(size_t(w) * size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) rays.push_back(scene.camera.primaryRay(x, y, w, h));
    return rays;
}

void expectSame(const Scene& scene, const Accelerator& accel, const std::vector<Ray>& rays,
                const std::string& what, double tmin) {
    auto bad = compareWithBrute(scene, accel, rays, tmin);
    EXPECT_TRUE(bad.empty()) << what << ": " << bad.size() << " mismatches of " << rays.size()
                             << ", first:\n"
                             << (bad.empty() ? "" : bad[0].toString(scene));
}

void expectEverySchemeSame(const Scene& scene, const std::vector<Ray>& rays) {
    for (const SchemeInfo& info : kSchemeTable) {
        BuildParams p;
        p.scheme = info.kind;
        expectSame(scene, *buildAccelerator(scene, p), rays, info.name);
    }
}

void expectSamePixelsAndSecondaries(const Scene& scene, const Accelerator& accel, int n,
                                    uint64_t seed, const std::string& what) {
    const std::vector<Ray> rays = pixelRays(scene, n, n);
    expectSame(scene, accel, rays, what);
    expectSame(scene, accel, secondaryRays(scene, rays, seed), what + " secondary",
               1e-9 * scene.scale());
}

std::vector<Ray> secondaryRays(const Scene& scene, const std::vector<Ray>& primary, uint64_t seed) {
    auto brute = buildAccelerator(scene, BuildParams{});
    TraceContext ctx(scene.prims.size(), scene.tree.depth());
    NullObserver obs;
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> n;
    std::vector<Ray> rays;
    for (const Ray& r : primary) {
        Hit h;
        ctx.beginRay();
        if (!brute->intersect(r, 0.0, kInf, ctx, obs, h)) continue;
        const Vec3 p = r.at(h.t);
        rays.push_back({p, glm::normalize(Vec3(n(rng), n(rng), n(rng)))});
        if (!scene.lights.empty())
            rays.push_back({p, glm::normalize(scene.lights[0].position - p)});
    }
    return rays;
}

}  // namespace lancer::test
