#include "engine/scene/nff_reader.h"

#include <cmath>

#include "engine/scene/tokenizer.h"

namespace lancer {

namespace {
constexpr int kMaxVertices = 1 << 20;  // refuses absurd counts before allocating

/// True when the polygon turns the same way at every vertex (and so a fan covers it exactly).
bool isConvex(const std::vector<Vec3>& p) {
    Vec3 n(0.0);  // Newell normal
    size_t k = p.size();
    for (size_t i = 0; i < k; ++i) n += glm::cross(p[i], p[(i + 1) % k]);
    for (size_t i = 0; i < k; ++i) {
        Vec3 turn = glm::cross(p[(i + 1) % k] - p[i], p[(i + 2) % k] - p[(i + 1) % k]);
        if (glm::dot(turn, n) < 0.0) return false;
    }
    return true;
}
}  // namespace

Scene readNff(const SourceText& src, NffCounts* countsOut) {
    WordReader in(src);
    Scene scene;
    scene.name = src.path();
    NffCounts counts;
    std::vector<int> leaves;
    int material = 0;
    bool haveView = false;
    double angle = 45.0;
    int resH = 0;
    std::vector<Vec3> lightPos;
    std::vector<Vec3> lightColor;
    std::vector<bool> lightHasColor;

    auto addPrim = [&](Shape shape, const Transform& xf, size_t pos) {
        Primitive p = makePrimitive(std::move(shape), xf, material);
        p.origin = src.where(pos);
        scene.prims.push_back(std::move(p));
        leaves.push_back(scene.tree.leaf(uint32_t(scene.prims.size() - 1)));
    };
    auto nextIsNumber = [&] {
        double v;
        return parseFiniteDouble(in.peek().text, v);
    };

    while (true) {
        Token t = in.next();
        if (t.text.empty()) break;
        std::string_view k = t.text;
        if (k == "v") {
            // from, at, up, angle, hither, resolution: keyword-led, in this order.
            auto expect = [&](const char* word) {
                Token w = in.next();
                if (w.text.empty())
                    src.fail(w.pos, std::string("unexpected end of file: expected '") + word +
                                        "' in the viewpoint ('v') block");
                if (w.text != word)
                    src.fail(w.pos, std::string("expected '") + word +
                                        "' in the viewpoint ('v') block, got '" +
                                        std::string(w.text) + "'");
            };
            expect("from");
            scene.camera.from = in.vec3("the 'from' point");
            expect("at");
            scene.camera.at = in.vec3("the 'at' point");
            expect("up");
            scene.camera.up = in.vec3("the 'up' vector");
            expect("angle");
            size_t apos = in.peek().pos;
            angle = in.number("the view angle");
            if (!(angle > 0.0 && angle < 180.0))
                src.fail(apos, "the view angle must be in (0, 180) degrees");
            expect("hither");
            // Hither is the near clipping distance; primary rays start at the eye, as in SPD's
            // reference tracers, so it is checked and otherwise unused.
            size_t hpos = in.peek().pos;
            if (in.number("the hither distance") < 0.0)
                src.fail(hpos, "the hither distance must not be negative");
            expect("resolution");
            size_t wpos = in.peek().pos;
            scene.width = in.count("the image width", 16384);
            if (scene.width < 1) src.fail(wpos, "the resolution must be at least 1 x 1");
            size_t rpos = in.peek().pos;
            resH = in.count("the image height", 16384);
            if (resH < 1) src.fail(rpos, "the resolution must be at least 1 x 1");
            scene.height = resH;
            haveView = true;
            if (std::string e = scene.camera.validate(); !e.empty()) src.fail(t.pos, e);
        } else if (k == "b") {
            scene.background = in.vec3("the background colour");
        } else if (k == "l") {
            lightPos.push_back(in.vec3("the light position"));
            bool c = nextIsNumber();
            lightColor.push_back(c ? in.vec3("the light colour") : Vec3(1.0));
            lightHasColor.push_back(c);
            ++counts.lights;
        } else if (k == "f") {
            Material m;
            m.color = in.vec3("the fill colour");
            auto weight = [&](const char* what) {
                size_t wpos = in.peek().pos;
                double v = in.number(what);
                if (v < 0.0) src.fail(wpos, std::string(what) + " must not be negative");
                return v;
            };
            m.diffuse = weight("Kd");
            m.specular = weight("Ks");
            m.shininess = weight("Shine");
            m.transmit = weight("T");
            size_t ipos = in.peek().pos;
            m.ior = in.number("the index of refraction");
            // SPD writes 0 for opaque materials (T = 0), where the index is unused.
            if (m.ior < 0.0) src.fail(ipos, "the index of refraction must not be negative");
            if (m.ior == 0.0 && m.transmit > 0.0)
                src.fail(ipos,
                         "a transmitting material (T > 0) needs a positive index of refraction");
            if (m.ior == 0.0) m.ior = 1.0;
            m.reflect = m.specular;  // NFF: Ks also weights the mirror reflection
            m.ambient = 0.1;
            scene.materials.push_back(m);
            material = int(scene.materials.size()) - 1;
            ++counts.materials;
        } else if (k == "s") {
            Sphere s;
            s.c = in.vec3("the sphere centre");
            size_t rpos = in.peek().pos;
            s.r = in.number("the sphere radius");
            if (!(s.r > 0.0)) src.fail(rpos, "the sphere radius must be positive");
            addPrim(s, Transform(), t.pos);
            ++counts.spheres;
        } else if (k == "p" || k == "pp") {
            bool patch = k == "pp";
            size_t cpos = in.peek().pos;
            int n = in.count("the vertex count", kMaxVertices);
            if (n < 3) src.fail(cpos, "a polygon needs at least 3 vertices");
            std::vector<Vec3> pts, nrm;
            for (int i = 0; i < n; ++i) {
                pts.push_back(in.vec3("a vertex"));
                if (patch) nrm.push_back(in.vec3("a vertex normal"));
            }
            (patch ? counts.patches : counts.polygons)++;
            if (patch && isConvex(pts)) {
                // Fan of smooth triangles: exact for a convex patch (SPD writes triangles).
                for (int i = 1; i + 1 < n; ++i) {
                    Triangle tr;
                    tr.p[0] = pts[0], tr.p[1] = pts[size_t(i)], tr.p[2] = pts[size_t(i + 1)];
                    tr.n[0] = nrm[0], tr.n[1] = nrm[size_t(i)], tr.n[2] = nrm[size_t(i + 1)];
                    tr.smooth = true;
                    if (glm::length(glm::cross(tr.p[1] - tr.p[0], tr.p[2] - tr.p[0])) == 0.0) {
                        ++counts.degenerate;
                        continue;
                    }
                    addPrim(tr, Transform(), t.pos);
                }
            } else if (patch) {
                // A non-convex patch: its exact outline as a flat polygon (the vertex normals,
                // shading only, are not interpolated over it).
                Polygon pg;
                if (makePolygon(pts, pg))
                    addPrim(std::move(pg), Transform(), t.pos);
                else
                    ++counts.degenerate;
            } else if (n == 3) {
                Triangle tr;
                for (int i = 0; i < 3; ++i) tr.p[i] = pts[size_t(i)];
                if (glm::length(glm::cross(tr.p[1] - tr.p[0], tr.p[2] - tr.p[0])) == 0.0)
                    ++counts.degenerate;
                else
                    addPrim(tr, Transform(), t.pos);
            } else {
                Polygon pg;
                if (makePolygon(pts, pg))
                    addPrim(std::move(pg), Transform(), t.pos);
                else
                    ++counts.degenerate;
            }
        } else if (k == "c") {
            Vec3 base = in.vec3("the cone base point");
            size_t r0pos = in.peek().pos;
            double r0 = in.number("the cone base radius");
            Vec3 apex = in.vec3("the cone apex point");
            size_t r1pos = in.peek().pos;
            double r1 = in.number("the cone apex radius");
            // NFF: both radii negative means only the inside is visible. Lancer's surfaces
            // are seen from both sides, so that is the same open cone.
            if (r0 < 0.0 && r1 < 0.0) r0 = -r0, r1 = -r1;
            if (r0 < 0.0)
                src.fail(r0pos,
                         "a cone radius must not be negative (unless both are, for an "
                         "inside-visible cone)");
            if (r1 < 0.0)
                src.fail(r1pos,
                         "a cone radius must not be negative (unless both are, for an "
                         "inside-visible cone)");
            if (r0 == 0.0 && r1 == 0.0)
                src.fail(r0pos, "a cone needs a positive radius at one end");
            Vec3 axis = apex - base;
            double h = glm::length(axis);
            if (!(h > 0.0)) src.fail(t.pos, "the cone's base and apex are the same point");
            Cone c{r0, r1, h, true};
            addPrim(c, Transform::alongAxis(base, axis / h), t.pos);
            ++counts.cones;
        } else {
            src.fail(t.pos, "unknown NFF entity '" + std::string(k) +
                                "' (expected v, b, l, f, s, p, pp, c or #)");
        }
    }

    // NFF lights have equal intensity; scale so several lights do not wash the image out.
    double share = lightPos.empty() ? 1.0 : 1.0 / std::sqrt(double(lightPos.size()));
    for (size_t i = 0; i < lightPos.size(); ++i)
        scene.lights.push_back(
            {lightPos[i], lightHasColor[i] ? lightColor[i] * share : Vec3(share)});
    scene.tree.root = scene.tree.balanced(Op::Union, leaves);
    scene.prepare();
    if (haveView) {
        // NFF's angle spans the centres of the top and bottom pixel rows: widen it to the edges.
        double half = std::tan(glm::radians(angle) * 0.5);
        if (resH > 1) half *= double(resH) / double(resH - 1);
        scene.camera.fov = glm::degrees(2.0 * std::atan(half));
    } else {
        scene.frameCamera({-1.0, 2.0, -1.0}, {0, 0, 1});
    }
    if (scene.lights.empty()) scene.defaultLights();
    if (countsOut) *countsOut = counts;
    return scene;
}

}  // namespace lancer
