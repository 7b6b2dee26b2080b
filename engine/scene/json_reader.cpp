#include "engine/scene/json_reader.h"

#include <cmath>

namespace lancer {

using nlohmann::json;

namespace {

/// Reads chars for nlohmann's lexer and keeps count of how far it has read.
struct CountingIterator {
    using iterator_category = std::forward_iterator_tag;
    using value_type = char;
    using difference_type = std::ptrdiff_t;
    using pointer = const char*;
    using reference = const char&;
    const char* p;
    size_t* consumed;
    const char* base;
    reference operator*() const { return *p; }
    CountingIterator& operator++() {
        ++p;
        *consumed = size_t(p - base);
        return *this;
    }
    CountingIterator operator++(int) {
        CountingIterator t = *this;
        ++*this;
        return t;
    }
    bool operator==(const CountingIterator& o) const { return p == o.p; }
    bool operator!=(const CountingIterator& o) const { return p != o.p; }
};

std::string escapePointerToken(const std::string& s) {
    std::string r;
    for (char c : s) {
        if (c == '~')
            r += "~0";
        else if (c == '/')
            r += "~1";
        else
            r += c;
    }
    return r;
}

}  // namespace

/// Builds the DOM like nlohmann's own SAX DOM parser, recording where each value starts.
struct LocatingSax {
    LocatedJson& doc;
    const std::string& text;
    size_t consumed = 0;
    std::vector<json*> stack;
    std::vector<std::string> paths;
    std::string pendingKey;
    size_t pendingKeyPos = 0;
    bool haveKey = false;
    std::string errorMessage;
    size_t errorPos = 0;

    // Start of the token that ends just before `consumed` (the lexer may have read one more).
    size_t tokenStart(bool isString) const {
        size_t e = std::min(consumed, text.size());
        if (e == 0) return 0;
        size_t p = e - 1;
        if (isString) {
            while (p > 0 && text[p] != '"') --p;  // closing quote
            if (p > 0) --p;
            while (p > 0 && !(text[p] == '"' && text[p - 1] != '\\')) --p;
            return p;
        }
        auto part = [](char c) {
            return std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '+' || c == '-';
        };
        while (p > 0 && !part(text[p])) --p;
        while (p > 0 && part(text[p - 1])) --p;
        return p;
    }

    json* place(json&& v, size_t pos) {
        if (stack.empty()) {
            doc.root_ = std::move(v);
            doc.offsets_[""] = pos;
            paths.push_back("");
            return &doc.root_;
        }
        json& parent = *stack.back();
        std::string path;
        json* slot;
        if (parent.is_array()) {
            path = paths.back() + "/" + std::to_string(parent.size());
            parent.push_back(std::move(v));
            slot = &parent.back();
            doc.offsets_[path] = pos;
        } else {
            path = paths.back() + "/" + escapePointerToken(pendingKey);
            slot = &parent[pendingKey];
            *slot = std::move(v);
            doc.offsets_[path] = haveKey ? pendingKeyPos : pos;
            haveKey = false;
        }
        paths.push_back(path);
        return slot;
    }
    bool scalar(json&& v, bool isString = false) {
        place(std::move(v), tokenStart(isString));
        paths.pop_back();
        return true;
    }
    bool null() { return scalar(nullptr); }
    bool boolean(bool b) { return scalar(b); }
    bool number_integer(json::number_integer_t v) { return scalar(v); }
    bool number_unsigned(json::number_unsigned_t v) { return scalar(v); }
    bool number_float(json::number_float_t v, const std::string&) { return scalar(v); }
    bool string(std::string& s) { return scalar(s, true); }
    bool binary(json::binary_t&) { return true; }
    bool start_object(std::size_t) {
        stack.push_back(place(json::object(), consumed ? consumed - 1 : 0));
        return true;
    }
    bool key(std::string& k) {
        pendingKey = k;
        pendingKeyPos = tokenStart(true);
        haveKey = true;
        return true;
    }
    bool end_object() {
        stack.pop_back();
        paths.pop_back();
        return true;
    }
    bool start_array(std::size_t) {
        stack.push_back(place(json::array(), consumed ? consumed - 1 : 0));
        return true;
    }
    bool end_array() { return end_object(); }
    bool parse_error(std::size_t position, const std::string&,
                     const nlohmann::detail::exception& ex) {
        errorPos = position ? position - 1 : 0;
        std::string m = ex.what();
        // Keep nlohmann's explanation, drop its "[json.exception...] parse error at ...:" prefix.
        size_t colon = m.find(": ");
        errorMessage = colon == std::string::npos ? m : m.substr(colon + 2);
        return false;
    }
};

LocatedJson::LocatedJson(const SourceText& src) : src_(&src) {
    const std::string& t = src.text();
    LocatingSax sax{*this, t, 0, {}, {}, {}, 0, false, {}, 0};
    CountingIterator first{t.data(), &sax.consumed, t.data()};
    CountingIterator last{t.data() + t.size(), &sax.consumed, t.data()};
    bool ok = json::sax_parse(first, last, &sax, json::input_format_t::json, true, true);
    if (!ok) src.fail(sax.errorPos, "JSON syntax error: " + sax.errorMessage);
}

size_t LocatedJson::offset(const std::string& pointer) const {
    std::string p = pointer;
    while (true) {
        auto it = offsets_.find(p);
        if (it != offsets_.end()) return it->second;
        if (p.empty()) return 0;
        p = p.substr(0, p.rfind('/'));
    }
}

void LocatedJson::fail(const std::string& pointer, const std::string& message) const {
    std::string where = pointer.empty() ? "" : " (at " + pointer + ")";
    src_->fail(offset(pointer), message + where);
}

JsonAt JsonAt::operator[](const std::string& key) const {
    if (!value.is_object()) fail("expected an object");
    auto it = value.find(key);
    if (it == value.end()) fail("missing \"" + key + "\"");
    return {doc, *it, pointer + "/" + escapePointerToken(key)};
}

JsonAt JsonAt::operator[](size_t index) const {
    if (!value.is_array() || index >= value.size())
        fail("expected an array with at least " + std::to_string(index + 1) + " elements");
    return {doc, value[index], pointer + "/" + std::to_string(index)};
}

double JsonAt::number() const {
    if (!value.is_number()) fail("expected a number");
    double v = value.get<double>();
    if (!std::isfinite(v)) fail("expected a finite number");
    return v;
}
double JsonAt::positive() const {
    double v = number();
    if (!(v > 0.0)) fail("expected a positive number, got " + value.dump());
    return v;
}
double JsonAt::nonNegative() const {
    double v = number();
    if (v < 0.0) fail("expected a number >= 0, got " + value.dump());
    return v;
}
int JsonAt::integer(int lo, int hi) const {
    if (!value.is_number_integer()) fail("expected an integer");
    long long v = value.get<long long>();
    if (v < lo || v > hi)
        fail("expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return int(v);
}
bool JsonAt::boolean() const {
    if (!value.is_boolean()) fail("expected true or false");
    return value.get<bool>();
}
std::string JsonAt::string() const {
    if (!value.is_string()) fail("expected a string");
    return value.get<std::string>();
}
Vec3 JsonAt::vec3() const {
    if (!value.is_array() || value.size() != 3) fail("expected [x, y, z]");
    return {(*this)[0].number(), (*this)[1].number(), (*this)[2].number()};
}
const json::array_t& JsonAt::array() const {
    if (!value.is_array()) fail("expected an array");
    return value.get_ref<const json::array_t&>();
}
const json::object_t& JsonAt::object() const {
    if (!value.is_object()) fail("expected an object");
    return value.get_ref<const json::object_t&>();
}
void JsonAt::onlyKeys(std::initializer_list<const char*> allowed) const {
    for (const auto& [k, v] : object()) {
        bool ok = false;
        for (const char* a : allowed) ok = ok || k == a;
        if (!ok) {
            std::string list;
            for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
            (*this)[k].fail("unknown key \"" + k + "\" (expected one of: " + list + ")");
        }
    }
}

/// Lights: [[x, y, z], ...] or [{"position": [..], "color": [..]}, ...].
static void readLights(const JsonAt& ls, Scene& scene) {
    scene.lights.clear();
    for (size_t i = 0; i < ls.array().size(); ++i) {
        JsonAt l = ls[i];
        if (l.value.is_array()) {
            scene.lights.push_back({l.vec3(), Vec3(1.0)});
            continue;
        }
        l.onlyKeys({"position", "color"});
        Light light{l["position"].vec3(), Vec3(1.0)};
        if (l.has("color")) light.color = l["color"].vec3();
        scene.lights.push_back(light);
    }
}

void applyCameraJson(const JsonAt& cam, Scene& scene, bool strictKeys) {
    if (strictKeys)
        cam.onlyKeys({"from", "at", "up", "fov", "width", "height", "projection", "ortho_height",
                      "lights", "background"});
    Camera& c = scene.camera;
    if (cam.has("from")) c.from = cam["from"].vec3();
    if (cam.has("at")) c.at = cam["at"].vec3();
    if (cam.has("up")) c.up = cam["up"].vec3();
    if (cam.has("fov")) {
        c.fov = cam["fov"].number();
        if (!(c.fov > 0.0 && c.fov < 180.0)) cam["fov"].fail("\"fov\" must be in (0, 180) degrees");
    }
    if (cam.has("width")) scene.width = cam["width"].integer(1, 16384);
    if (cam.has("height")) scene.height = cam["height"].integer(1, 16384);
    if (cam.has("projection")) {
        std::string p = cam["projection"].string();
        if (p == "perspective")
            c.projection = Projection::Perspective;
        else if (p == "orthographic")
            c.projection = Projection::Orthographic;
        else
            cam["projection"].fail("expected \"perspective\" or \"orthographic\"");
    }
    if (cam.has("ortho_height")) c.orthoHeight = cam["ortho_height"].positive();
    if (cam.has("background")) scene.background = cam["background"].vec3();
    if (cam.has("lights")) readLights(cam["lights"], scene);
    if (std::string e = c.validate(); !e.empty()) cam.fail(e);
}

namespace {

struct JsonSceneBuilder {
    Scene& scene;
    std::unordered_map<std::string, int> materialByName;

    int material(const JsonAt& m, int inherited) {
        if (m.value.is_string()) {
            auto it = materialByName.find(m.string());
            if (it == materialByName.end()) m.fail("unknown material \"" + m.string() + "\"");
            return it->second;
        }
        m.onlyKeys({"color", "ambient", "diffuse", "specular", "shininess", "reflect", "transmit",
                    "ior", "name"});
        Material mat = scene.materials[size_t(inherited)];
        mat.name.clear();
        if (m.has("color")) mat.color = m["color"].vec3();
        if (m.has("ambient")) mat.ambient = m["ambient"].nonNegative();
        if (m.has("diffuse")) mat.diffuse = m["diffuse"].nonNegative();
        if (m.has("specular")) mat.specular = m["specular"].nonNegative();
        if (m.has("shininess")) mat.shininess = m["shininess"].nonNegative();
        if (m.has("reflect")) mat.reflect = m["reflect"].nonNegative();
        if (m.has("transmit")) mat.transmit = m["transmit"].nonNegative();
        if (m.has("ior")) mat.ior = m["ior"].positive();
        scene.materials.push_back(mat);
        return int(scene.materials.size()) - 1;
    }

    Transform transform(const JsonAt& list) {
        Transform xf;
        for (size_t i = 0; i < list.array().size(); ++i) {
            JsonAt step = list[i];
            step.onlyKeys({"translate", "scale", "rotate", "matrix"});
            if (step.object().size() != 1)
                step.fail("a transform step has exactly one of translate, scale, rotate, matrix");
            Transform t;
            if (step.has("translate")) {
                t = Transform::translate(step["translate"].vec3());
            } else if (step.has("scale")) {
                JsonAt s = step["scale"];
                Vec3 v = s.value.is_number() ? Vec3(s.number()) : s.vec3();
                if (v.x == 0.0 || v.y == 0.0 || v.z == 0.0)
                    s.fail("scale factors must be non-zero");
                t = Transform::scale(v);
            } else if (step.has("rotate")) {
                // Euler angles in degrees, applied about x, then y, then z (as OpenSCAD's rotate).
                Vec3 a = step["rotate"].vec3();
                t = Transform::rotate(a.z, {0, 0, 1}) * Transform::rotate(a.y, {0, 1, 0}) *
                    Transform::rotate(a.x, {1, 0, 0});
            } else {
                JsonAt m = step["matrix"];
                if (!m.value.is_array() || (m.value.size() != 16 && m.value.size() != 12))
                    m.fail("expected 12 or 16 numbers (row-major 3x4 or 4x4)");
                Mat4 mm(1.0);
                for (size_t k = 0; k < m.value.size(); ++k)
                    mm[int(k % 4)][int(k / 4)] = m[k].number();
                if (m.value.size() == 16 &&
                    (mm[0][3] != 0 || mm[1][3] != 0 || mm[2][3] != 0 || mm[3][3] != 1))
                    m.fail("the last row of an affine matrix must be [0, 0, 0, 1]");
                t = Transform(mm);
            }
            if (!t.isInvertible()) step.fail("transform is singular");
            xf = t * xf;  // later steps apply after earlier ones
        }
        return xf;
    }

    std::vector<Vec3> points(const JsonAt& list, size_t minCount) {
        std::vector<Vec3> pts;
        for (size_t i = 0; i < list.array().size(); ++i) pts.push_back(list[i].vec3());
        if (pts.size() < minCount)
            list.fail("expected at least " + std::to_string(minCount) + " points");
        return pts;
    }

    int primitive(const JsonAt& at, Shape shape, const Transform& xf, int mat) {
        Primitive p = makePrimitive(std::move(shape), xf, mat);
        p.origin = at.doc.source().where(at.doc.offset(at.pointer));
        scene.prims.push_back(std::move(p));
        return scene.tree.leaf(uint32_t(scene.prims.size() - 1));
    }

    /// A torus's radii, checked: R >= r, since the solid of a spindle torus (whose tube crosses
    /// its axis) is not the inside of its quartic and OpenSCAD refuses it too.
    static Torus torus(const JsonAt& body) {
        body.onlyKeys({"major", "minor"});
        Torus t;
        t.R = body["major"].positive();
        t.r = body["minor"].positive();
        if (t.r > t.R)
            body["minor"].fail(
                "a torus's \"minor\" radius must not exceed its \"major\" one (a "
                "spindle torus, whose tube crosses its axis, is not modelled)");
        return t;
    }

    static constexpr int kMaxDepth = 2000;  // deeper nesting is refused, not recursed into

    int node(const JsonAt& n, const Transform& parentXf, int parentMat, int depth = 0) {
        if (depth > kMaxDepth)
            n.fail("nesting deeper than " + std::to_string(kMaxDepth) + " levels");
        static const char* kinds[] = {"sphere",       "box",       "cylinder", "cone",
                                      "torus",        "triangle",  "polygon",  "union",
                                      "intersection", "difference"};
        n.object();
        std::string kind;
        for (const char* k : kinds)
            if (n.has(k)) {
                if (!kind.empty())
                    n.fail(
                        "a node has exactly one of sphere, box, cylinder, cone, torus, triangle, "
                        "polygon, union, intersection, difference; found both \"" +
                        kind + "\" and \"" + k + "\"");
                kind = k;
            }
        if (kind.empty())
            n.fail(
                "expected a node: one of sphere, box, cylinder, cone, torus, triangle, polygon, "
                "union, intersection, difference");
        for (const auto& [k, v] : n.object())
            if (k != kind && k != "transform" && k != "material" && k != "name")
                n[k].fail("unknown key \"" + k + "\" in a " + kind + " node");
        Transform xf = parentXf;
        if (n.has("transform")) xf = parentXf * transform(n["transform"]);
        int mat = n.has("material") ? material(n["material"], parentMat) : parentMat;
        JsonAt body = n[kind];

        if (kind == "union" || kind == "intersection" || kind == "difference") {
            Op op = kind == "union"          ? Op::Union
                    : kind == "intersection" ? Op::Intersection
                                             : Op::Difference;
            std::vector<int> kids;
            for (size_t i = 0; i < body.array().size(); ++i) {
                int k = node(body[i], xf, mat, depth + 1);
                // An empty child (an empty operator) is the empty set: it vanishes from a union
                // and from the subtracted part of a difference, and empties an intersection or
                // a difference it starts.
                if (k >= 0) {
                    kids.push_back(k);
                } else if (op == Op::Intersection || (op == Op::Difference && i == 0)) {
                    return -1;
                }
            }
            if (kids.empty()) return -1;  // an empty operator contributes nothing
            if (op != Op::Difference) return scene.tree.balanced(op, kids);
            // First child minus all the others.
            std::vector<int> rest(kids.begin() + 1, kids.end());
            int cut = scene.tree.balanced(Op::Union, rest);
            return cut < 0 ? kids[0] : scene.tree.combine(Op::Difference, kids[0], cut);
        }
        if (kind == "sphere") {
            body.onlyKeys({"center", "radius"});
            Sphere s;
            if (body.has("center")) s.c = body["center"].vec3();
            s.r = body["radius"].positive();
            return primitive(n, s, xf, mat);
        }
        if (kind == "box") {
            body.onlyKeys({"min", "max", "size", "center"});
            Block b;
            if (body.has("size")) {
                JsonAt s = body["size"];
                Vec3 v = s.value.is_number() ? Vec3(s.positive()) : s.vec3();
                if (!(v.x > 0 && v.y > 0 && v.z > 0)) s.fail("box sizes must be positive");
                bool centered = body.has("center") && body["center"].boolean();
                b.lo = centered ? -0.5 * v : Vec3(0.0);
                b.hi = b.lo + v;
            } else {
                b.lo = body["min"].vec3();
                b.hi = body["max"].vec3();
                if (!(b.lo.x < b.hi.x && b.lo.y < b.hi.y && b.lo.z < b.hi.z))
                    body.fail("box \"min\" must be below \"max\" on every axis");
            }
            return primitive(n, b, xf, mat);
        }
        if (kind == "cylinder" || kind == "cone") {
            Cone c;
            if (kind == "cylinder") {
                body.onlyKeys({"radius", "height", "center"});
                c.r1 = c.r2 = body["radius"].positive();
            } else {
                body.onlyKeys({"r1", "r2", "height", "center"});
                c.r1 = body["r1"].nonNegative();
                c.r2 = body["r2"].nonNegative();
                if (c.r1 == 0.0 && c.r2 == 0.0) body.fail("a cone needs r1 > 0 or r2 > 0");
            }
            c.h = body["height"].positive();
            Transform local = (body.has("center") && body["center"].boolean())
                                  ? Transform::translate({0, 0, -0.5 * c.h})
                                  : Transform();
            return primitive(n, c, xf * local, mat);
        }
        if (kind == "torus") return primitive(n, torus(body), xf, mat);
        // Surfaces: world-space points through the transform.
        std::vector<Vec3> pts = points(body, 3);
        for (Vec3& p : pts) p = xf.point(p);
        if (kind == "triangle") {
            if (pts.size() != 3) body.fail("a triangle has exactly 3 points");
            Triangle t;
            for (int i = 0; i < 3; ++i) t.p[i] = pts[size_t(i)];
            if (glm::length(glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0])) == 0.0)
                body.fail("degenerate triangle (zero area)");
            return primitive(n, t, Transform(), mat);
        }
        Polygon pg;
        if (!makePolygon(pts, pg)) body.fail("degenerate polygon (zero area)");
        return primitive(n, pg, Transform(), mat);
    }
};

}  // namespace

Scene readJsonScene(const SourceText& src) {
    LocatedJson doc(src);
    JsonAt root{doc, doc.root(), ""};
    root.onlyKeys({"camera", "lights", "background", "materials", "scene", "ambient"});
    Scene scene;
    scene.name = src.path();
    JsonSceneBuilder b{scene, {}};
    if (root.has("background")) scene.background = root["background"].vec3();
    if (root.has("materials")) {
        JsonAt ms = root["materials"];
        for (const auto& [name, v] : ms.object()) {
            b.materialByName[name] = b.material(ms[name], 0);
            scene.materials.back().name = name;
        }
    }
    if (root.has("ambient")) {
        double a = root["ambient"].nonNegative();
        for (Material& m : scene.materials) m.ambient = a;
    }
    int top = b.node(root["scene"], Transform(), 0);
    scene.tree.root = top;
    bool haveLights = root.has("lights");
    if (haveLights) readLights(root["lights"], scene);
    scene.prepare();
    if (root.has("camera")) {
        applyCameraJson(root["camera"], scene, true);
    } else {
        scene.frameCamera({-1.0, 2.0, -1.0}, {0, 0, 1});
    }
    if (!haveLights && !(root.has("camera") && root["camera"].has("lights"))) scene.defaultLights();
    return scene;
}

}  // namespace lancer
