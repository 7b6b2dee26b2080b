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

bool zeroArea(const Triangle& tr) {
    return glm::length(glm::cross(tr.p[1] - tr.p[0], tr.p[2] - tr.p[0])) == 0.0;
}

/// The words of an NFF file, entity by entity: each keyword's handler reads the words of its
/// entity and adds to the scene; finish() turns what was read into the scene.
class NffReader {
  public:
    explicit NffReader(const SourceText& src) : src_(src), in_(src) { scene_.name = src.path(); }

    Scene read(NffCounts* countsOut) {
        for (Token t = in_.next(); !t.text.empty(); t = in_.next()) (this->*handler(t))(t);
        return finish(countsOut);
    }

  private:
    using Handler = void (NffReader::*)(const Token& keyword);
    struct Entity {
        std::string_view keyword;
        Handler read;
    };
    /// Every NFF entity by its keyword (`#` comments are skipped by the word reader).
    static const Entity kEntities[8];

    Handler handler(const Token& t) const {
        for (const Entity& e : kEntities)
            if (e.keyword == t.text) return e.read;
        std::string list;
        for (const Entity& e : kEntities)
            list += (list.empty() ? "" : ", ") + std::string(e.keyword);
        src_.fail(t.pos,
                  "unknown NFF entity '" + std::string(t.text) + "' (expected " + list + " or #)");
    }

    /// v: from, at, up, angle, hither, resolution, keyword-led, in this order.
    void view(const Token& t) {
        auto expect = [&](const char* word) {
            Token w = in_.next();
            if (w.text.empty())
                src_.fail(w.pos, std::string("unexpected end of file: expected '") + word +
                                     "' in the viewpoint ('v') block");
            if (w.text != word)
                src_.fail(w.pos, std::string("expected '") + word +
                                     "' in the viewpoint ('v') block, got '" + std::string(w.text) +
                                     "'");
        };
        expect("from");
        scene_.camera.from = in_.vec3("the 'from' point");
        expect("at");
        scene_.camera.at = in_.vec3("the 'at' point");
        expect("up");
        scene_.camera.up = in_.vec3("the 'up' vector");
        expect("angle");
        size_t apos = in_.peek().pos;
        angle_ = in_.number("the view angle");
        if (!(angle_ > 0.0 && angle_ < 180.0))
            src_.fail(apos, "the view angle must be in (0, 180) degrees");
        expect("hither");
        // Hither is the near clipping distance; primary rays start at the eye, as in SPD's
        // reference tracers, so it is checked and otherwise unused.
        size_t hpos = in_.peek().pos;
        if (in_.number("the hither distance") < 0.0)
            src_.fail(hpos, "the hither distance must not be negative");
        expect("resolution");
        size_t wpos = in_.peek().pos;
        scene_.width = in_.count("the image width", 16384);
        if (scene_.width < 1) src_.fail(wpos, "the resolution must be at least 1 x 1");
        size_t rpos = in_.peek().pos;
        resH_ = in_.count("the image height", 16384);
        if (resH_ < 1) src_.fail(rpos, "the resolution must be at least 1 x 1");
        scene_.height = resH_;
        haveView_ = true;
        if (std::string e = scene_.camera.validate(); !e.empty()) src_.fail(t.pos, e);
    }

    /// b: the background colour.
    void background(const Token&) { scene_.background = in_.vec3("the background colour"); }

    /// l: a light's position and, optionally, its colour.
    void light(const Token&) {
        lightPos_.push_back(in_.vec3("the light position"));
        double v;
        bool c = parseFiniteDouble(in_.peek().text, v);
        lightColor_.push_back(c ? in_.vec3("the light colour") : Vec3(1.0));
        lightHasColor_.push_back(c);
        ++counts_.lights;
    }

    /// f: the material of the primitives that follow.
    void fill(const Token&) {
        Material m;
        m.color = in_.vec3("the fill colour");
        auto weight = [&](const char* what) {
            size_t wpos = in_.peek().pos;
            double v = in_.number(what);
            if (v < 0.0) src_.fail(wpos, std::string(what) + " must not be negative");
            return v;
        };
        m.diffuse = weight("Kd");
        m.specular = weight("Ks");
        m.shininess = weight("Shine");
        m.transmit = weight("T");
        size_t ipos = in_.peek().pos;
        m.ior = in_.number("the index of refraction");
        // SPD writes 0 for opaque materials (T = 0), where the index is unused.
        if (m.ior < 0.0) src_.fail(ipos, "the index of refraction must not be negative");
        if (m.ior == 0.0 && m.transmit > 0.0)
            src_.fail(ipos, "a transmitting material (T > 0) needs a positive index of refraction");
        if (m.ior == 0.0) m.ior = 1.0;
        m.reflect = m.specular;  // NFF: Ks also weights the mirror reflection
        m.ambient = 0.1;
        scene_.materials.push_back(m);
        material_ = int(scene_.materials.size()) - 1;
        ++counts_.materials;
    }

    /// s: a solid sphere.
    void sphere(const Token& t) {
        Sphere s;
        s.c = in_.vec3("the sphere centre");
        size_t rpos = in_.peek().pos;
        s.r = in_.number("the sphere radius");
        if (!(s.r > 0.0)) src_.fail(rpos, "the sphere radius must be positive");
        add(s, Transform(), t.pos);
        ++counts_.spheres;
    }

    /// p: a flat polygon (a triangle when it has 3 vertices).
    void polygon(const Token& t) {
        std::vector<Vec3> pts = vertices(nullptr);
        ++counts_.polygons;
        if (pts.size() == 3) {
            Triangle tr;
            for (int i = 0; i < 3; ++i) tr.p[i] = pts[size_t(i)];
            if (zeroArea(tr))
                ++counts_.degenerate;
            else
                add(tr, Transform(), t.pos);
        } else {
            flat(pts, t.pos);
        }
    }

    /// pp: a polygon with a normal per vertex.
    void patch(const Token& t) {
        std::vector<Vec3> nrm;
        std::vector<Vec3> pts = vertices(&nrm);
        ++counts_.patches;
        if (!isConvex(pts)) {
            // A non-convex patch: its exact outline as a flat polygon (the vertex normals,
            // shading only, are not interpolated over it).
            flat(pts, t.pos);
            return;
        }
        // Fan of smooth triangles: exact for a convex patch (SPD writes triangles).
        for (size_t i = 1; i + 1 < pts.size(); ++i) {
            Triangle tr;
            tr.p[0] = pts[0], tr.p[1] = pts[i], tr.p[2] = pts[i + 1];
            tr.n[0] = nrm[0], tr.n[1] = nrm[i], tr.n[2] = nrm[i + 1];
            tr.smooth = true;
            if (zeroArea(tr)) {
                ++counts_.degenerate;
                continue;
            }
            add(tr, Transform(), t.pos);
        }
    }

    /// A polygon's vertex count and vertices (with a normal after each when `normals`).
    std::vector<Vec3> vertices(std::vector<Vec3>* normals) {
        size_t cpos = in_.peek().pos;
        int n = in_.count("the vertex count", kMaxVertices);
        if (n < 3) src_.fail(cpos, "a polygon needs at least 3 vertices");
        std::vector<Vec3> pts;
        for (int i = 0; i < n; ++i) {
            pts.push_back(in_.vec3("a vertex"));
            if (normals) normals->push_back(in_.vec3("a vertex normal"));
        }
        return pts;
    }

    void flat(const std::vector<Vec3>& pts, size_t pos) {
        Polygon pg;
        if (makePolygon(pts, pg))
            add(std::move(pg), Transform(), pos);
        else
            ++counts_.degenerate;
    }

    /// c: an open cone (or cylinder) from a base point and radius to an apex point and radius.
    void cone(const Token& t) {
        Vec3 base = in_.vec3("the cone base point");
        size_t r0pos = in_.peek().pos;
        double r0 = in_.number("the cone base radius");
        Vec3 apex = in_.vec3("the cone apex point");
        size_t r1pos = in_.peek().pos;
        double r1 = in_.number("the cone apex radius");
        // NFF: both radii negative means only the inside is visible. Lancer's surfaces
        // are seen from both sides, so that is the same open cone.
        if (r0 < 0.0 && r1 < 0.0) r0 = -r0, r1 = -r1;
        if (r0 < 0.0)
            src_.fail(r0pos,
                      "a cone radius must not be negative (unless both are, for an "
                      "inside-visible cone)");
        if (r1 < 0.0)
            src_.fail(r1pos,
                      "a cone radius must not be negative (unless both are, for an "
                      "inside-visible cone)");
        if (r0 == 0.0 && r1 == 0.0) src_.fail(r0pos, "a cone needs a positive radius at one end");
        Vec3 axis = apex - base;
        double h = glm::length(axis);
        if (!(h > 0.0)) src_.fail(t.pos, "the cone's base and apex are the same point");
        Cone c{r0, r1, h, true};
        add(c, Transform::alongAxis(base, axis / h), t.pos);
        ++counts_.cones;
    }

    void add(Shape shape, const Transform& xf, size_t pos) {
        Primitive p = makePrimitive(std::move(shape), xf, material_);
        p.origin = src_.where(pos);
        scene_.prims.push_back(std::move(p));
        leaves_.push_back(scene_.tree.leaf(uint32_t(scene_.prims.size() - 1)));
    }

    Scene finish(NffCounts* countsOut) {
        // NFF lights have equal intensity; scale so several lights do not wash the image out.
        double share = lightPos_.empty() ? 1.0 : 1.0 / std::sqrt(double(lightPos_.size()));
        for (size_t i = 0; i < lightPos_.size(); ++i)
            scene_.lights.push_back(
                {lightPos_[i], lightHasColor_[i] ? lightColor_[i] * share : Vec3(share)});
        scene_.tree.root = scene_.tree.balanced(Op::Union, leaves_);
        scene_.prepare();
        if (haveView_) {
            // NFF's angle spans the centres of the top and bottom pixel rows: widen it to the
            // edges.
            double half = std::tan(glm::radians(angle_) * 0.5);
            if (resH_ > 1) half *= double(resH_) / double(resH_ - 1);
            scene_.camera.fov = glm::degrees(2.0 * std::atan(half));
        } else {
            scene_.frameCamera({-1.0, 2.0, -1.0}, {0, 0, 1});
        }
        if (scene_.lights.empty()) scene_.defaultLights();
        if (countsOut) *countsOut = counts_;
        return std::move(scene_);
    }

    const SourceText& src_;
    WordReader in_;
    Scene scene_;
    NffCounts counts_;
    std::vector<int> leaves_;  ///< one per primitive, for the top-level union
    int material_ = 0;         ///< of the last `f`
    bool haveView_ = false;
    double angle_ = 45.0;
    int resH_ = 0;
    std::vector<Vec3> lightPos_, lightColor_;
    std::vector<bool> lightHasColor_;
};

const NffReader::Entity NffReader::kEntities[8] = {
    {"v", &NffReader::view},   {"b", &NffReader::background}, {"l", &NffReader::light},
    {"f", &NffReader::fill},   {"s", &NffReader::sphere},     {"p", &NffReader::polygon},
    {"pp", &NffReader::patch}, {"c", &NffReader::cone},
};

}  // namespace

Scene readNff(const SourceText& src, NffCounts* counts) { return NffReader(src).read(counts); }

}  // namespace lancer
