#include "engine/scene/openscad/builder.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>

#include "engine/scene/openscad/colors.h"

namespace lancer::openscad {

namespace {

/// A subtree's contribution: left out of the model (`*`, `%`), present but empty (an empty
/// group, a zero-size primitive), or a CSG node.
struct Built {
    enum class Kind : uint8_t { Absent, Empty, Node } kind = Kind::Empty;
    int node = -1;
    static Built absent() { return {Kind::Absent, -1}; }
    static Built empty() { return {Kind::Empty, -1}; }
    static Built of(int n) { return {Kind::Node, n}; }
};

/// A node's arguments, matched to OpenSCAD's parameter names (positional ones in order).
class Args {
  public:
    Args(const SourceText& src, const Node& n, std::initializer_list<const char*> positional,
         std::initializer_list<const char*> named)
        : src_(src), node_(n) {
        size_t next = 0;
        std::vector<const char*> pos(positional), all(positional);
        all.insert(all.end(), named.begin(), named.end());
        for (const Arg& a : n.args) {
            std::string name = a.name;
            if (name.empty()) {
                if (next >= pos.size())
                    src.fail(a.pos, n.name + "() takes at most " + std::to_string(pos.size()) +
                                        " positional argument" + (pos.size() == 1 ? "" : "s"));
                name = pos[next++];
            } else if (name[0] == '$') {
                continue;  // $fn, $fa, $fs: tessellation settings; Lancer traces the exact solid
            } else {
                bool known = false;
                for (const char* k : all) known = known || name == k;
                if (!known) {
                    std::string list;
                    for (const char* k : all) list += std::string(list.empty() ? "" : ", ") + k;
                    src.fail(a.pos, "unknown argument '" + name + "' of " + n.name +
                                        "() (expected " + (list.empty() ? "none" : list) + ")");
                }
            }
            if (values_.count(name))
                src.fail(a.pos, "argument '" + name + "' of " + n.name + "() is given twice");
            if (a.value.kind != Value::Kind::Undef)
                values_[name] = &a.value;  // undef: as if absent
        }
    }
    const Value* get(const std::string& name) const {
        auto it = values_.find(name);
        return it == values_.end() ? nullptr : it->second;
    }
    double number(const Value& v, const std::string& what) const {
        if (v.kind != Value::Kind::Number) src_.fail(v.pos, "expected a number for " + what);
        return v.number;
    }
    std::optional<double> number(const std::string& name) const {
        const Value* v = get(name);
        if (!v) return std::nullopt;
        return number(*v, "'" + name + "' of " + node_.name + "()");
    }
    bool boolean(const std::string& name, bool fallback) const {
        const Value* v = get(name);
        if (!v) return fallback;
        if (v->kind != Value::Kind::Bool)
            src_.fail(v->pos, "expected true or false for '" + name + "' of " + node_.name + "()");
        return v->boolean;
    }
    /// [x, y, z] (or [x, y] with z = `z2d` when `allow2d`).
    Vec3 vec3(const Value& v, const std::string& what, bool allow2d = false,
              double z2d = 0.0) const {
        if (v.kind != Value::Kind::Vector ||
            !(v.items.size() == 3 || (allow2d && v.items.size() == 2)))
            src_.fail(v.pos, "expected " +
                                 std::string(allow2d ? "[x, y] or [x, y, z]" : "[x, y, z]") +
                                 " for " + what);
        Vec3 r(z2d);
        for (size_t k = 0; k < v.items.size(); ++k) r[int(k)] = number(v.items[k], what);
        return r;
    }

  private:
    const SourceText& src_;
    const Node& node_;
    std::map<std::string, const Value*> values_;
};

class Builder {
  public:
    Builder(const SourceText& src, Scene& scene, OpenScadCounts& counts)
        : src_(src), scene_(scene), counts_(counts) {}

    /// The whole model: the children of the file's top level, or the first `!` subtree.
    int model(const std::vector<Node>& top) {
        const Node* root = nullptr;
        for (const Node& n : top)
            if ((root = findRoot(n))) break;
        Built b;
        if (root) {
            // As OpenSCAD does: the `!` node becomes the root of the design, so the transforms
            // and colours above it do not apply, and everything else is left out.
            countLeftOut(top, root);
            b = node(*root, Transform(), 0);
        } else {
            b = unionOf(top, Transform(), 0);
        }
        return b.kind == Built::Kind::Node ? b.node : -1;
    }

  private:
    const Node* findRoot(const Node& n) {
        if (n.disable) return nullptr;
        if (n.root) return &n;
        for (const Node& c : n.children)
            if (const Node* r = findRoot(c)) return r;
        return nullptr;
    }
    void countLeftOut(const std::vector<Node>& nodes, const Node* root) {
        for (const Node& n : nodes) {
            if (&n == root) continue;
            if (findRoot(n) == root)
                countLeftOut(n.children, root);
            else
                ++counts_.leftOut;
        }
    }

    Built unionOf(const std::vector<Node>& kids, const Transform& xf, int mat) {
        std::vector<int> items;
        for (const Node& k : kids) {
            Built b = node(k, xf, mat);
            if (b.kind == Built::Kind::Node) items.push_back(b.node);
        }
        return items.empty() ? Built::empty() : Built::of(scene_.tree.balanced(Op::Union, items));
    }

    Built node(const Node& n, const Transform& xf, int mat) {
        if (n.disable || n.background) {
            ++counts_.leftOut;
            return Built::absent();
        }
        const std::string& k = n.name;
        if (k == "group" || k == "union" || k == "render") {
            if (k == "render")
                Args(src_, n, {"convexity"}, {});  // checks the arguments
            else
                Args(src_, n, {}, {});
            ++counts_.operators;
            return unionOf(n.children, xf, mat);
        }
        if (k == "intersection" || k == "difference") {
            Args a(src_, n, {}, {});
            ++counts_.operators;
            return boolean(n, k == "intersection" ? Op::Intersection : Op::Difference, xf, mat);
        }
        if (k == "multmatrix" || k == "translate" || k == "rotate" || k == "scale" ||
            k == "mirror") {
            ++counts_.transforms;
            Transform t = xf * transform(n);
            // Each step is finite and invertible; their product may still overflow.
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    if (!std::isfinite(t.m[c][r]) || !std::isfinite(t.inv[c][r]))
                        src_.fail(n.pos, k + "() gives a transform with non-finite entries");
            return unionOf(n.children, t, mat);
        }
        if (k == "color") {
            ++counts_.colors;
            return unionOf(n.children, xf, color(n, mat));
        }
        if (k == "cube" || k == "sphere" || k == "cylinder") {
            if (!n.children.empty()) src_.fail(n.children.front().pos, k + "() takes no children");
            return primitive(n, xf, mat);
        }
        refuse(n);
    }

    [[noreturn]] void refuse(const Node& n) {
        static const char* twoD[] = {"circle", "square",     "polygon",   "text",
                                     "offset", "projection", "import_dxf"};
        for (const char* t : twoD)
            if (n.name == t)
                src_.fail(n.pos,
                          "the 2D node '" + n.name + "' is not supported: Lancer traces 3D solids");
        std::string list;
        for (const std::string& s : openScadSupportedNodes())
            list += (list.empty() ? "" : ", ") + s;
        src_.fail(n.pos, "the node '" + n.name + "' is not supported (supported: " + list + ")");
    }

    Built boolean(const Node& n, Op op, const Transform& xf, int mat) {
        // Children left out by `*` or `%` are not there at all, as in OpenSCAD; a present but
        // empty child empties an intersection, and an empty first child empties a difference.
        std::vector<Built> kids;
        for (const Node& c : n.children) {
            Built b = node(c, xf, mat);
            if (b.kind != Built::Kind::Absent) kids.push_back(b);
        }
        if (kids.empty()) return Built::empty();
        if (op == Op::Intersection) {
            std::vector<int> items;
            for (const Built& b : kids) {
                if (b.kind == Built::Kind::Empty) return Built::empty();
                items.push_back(b.node);
            }
            return Built::of(scene_.tree.balanced(Op::Intersection, items));
        }
        if (kids[0].kind == Built::Kind::Empty) return Built::empty();
        std::vector<int> cut;
        for (size_t i = 1; i < kids.size(); ++i)
            if (kids[i].kind == Built::Kind::Node) cut.push_back(kids[i].node);
        if (cut.empty()) return kids[0];
        return Built::of(scene_.tree.combine(Op::Difference, kids[0].node,
                                             scene_.tree.balanced(Op::Union, cut)));
    }

    Transform transform(const Node& n) {
        const std::string& k = n.name;
        Transform t;
        if (k == "multmatrix") {
            Args a(src_, n, {"m"}, {});
            const Value* m = a.get("m");
            if (!m) return t;  // OpenSCAD's default: the identity
            auto bad = [&] {
                src_.fail(m->pos,
                          "multmatrix expects a 4x4 matrix (or its first 3 rows) of numbers, as "
                          "[[a, b, c, d], ...]");
            };
            if (m->kind != Value::Kind::Vector || (m->items.size() != 4 && m->items.size() != 3))
                bad();
            Mat4 mm(1.0);
            for (size_t r = 0; r < m->items.size(); ++r) {
                const Value& row = m->items[r];
                if (row.kind != Value::Kind::Vector || row.items.size() != 4) bad();
                for (size_t c = 0; c < 4; ++c)
                    mm[int(c)][int(r)] =
                        a.number(row.items[c], "a multmatrix entry");  // row-major in the file
            }
            if (mm[0][3] != 0.0 || mm[1][3] != 0.0 || mm[2][3] != 0.0 || mm[3][3] != 1.0)
                src_.fail(m->items.back().pos,
                          "the last row of a multmatrix must be [0, 0, 0, 1] (projective "
                          "transforms are not supported)");
            t = Transform(mm);
        } else if (k == "translate") {
            Args a(src_, n, {"v"}, {});
            if (const Value* v = a.get("v"))
                t = Transform::translate(a.vec3(*v, "'v' of translate()", true));
        } else if (k == "scale") {
            Args a(src_, n, {"v"}, {});
            if (const Value* v = a.get("v"))
                t = Transform::scale(v->kind == Value::Kind::Number
                                         ? Vec3(v->number)
                                         : a.vec3(*v, "'v' of scale()", true, 1.0));
        } else if (k == "mirror") {
            Args a(src_, n, {"v"}, {});
            if (const Value* v = a.get("v")) {
                Vec3 p = a.vec3(*v, "'v' of mirror()", true);
                double len2 = glm::dot(p, p);
                if (len2 > 0.0) {
                    Vec3 u = p / std::sqrt(len2);
                    Mat4 mm(1.0);
                    for (int c = 0; c < 3; ++c)
                        for (int r = 0; r < 3; ++r) mm[c][r] -= 2.0 * u[c] * u[r];
                    t = Transform(mm);
                }
            }
        } else {  // rotate(a, v): a number about v (default z), or [x, y, z] applied x, then y,
                  // then z
            Args a(src_, n, {"a", "v"}, {});
            const Value* ang = a.get("a");
            if (!ang) return t;
            if (ang->kind == Value::Kind::Number) {
                Vec3 axis(0, 0, 1);
                if (const Value* v = a.get("v")) axis = a.vec3(*v, "'v' of rotate()");
                if (glm::dot(axis, axis) == 0.0 || !std::isfinite(glm::dot(axis, axis)))
                    src_.fail(n.pos, "rotate() needs a non-zero axis 'v'");
                t = Transform::rotate(ang->number, axis);
            } else {
                Vec3 e = a.vec3(*ang, "'a' of rotate()", true);
                t = Transform::rotate(e.z, {0, 0, 1}) * Transform::rotate(e.y, {0, 1, 0}) *
                    Transform::rotate(e.x, {1, 0, 0});
            }
        }
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(t.m[c][r]))
                    src_.fail(n.pos, k + "() gives a transform with non-finite entries");
        if (!t.isInvertible())
            src_.fail(n.pos, k + "() is singular (it flattens its children to nothing)");
        return t;
    }

    int color(const Node& n, int mat) {
        Args a(src_, n, {"c", "alpha"}, {});
        const Value* c = a.get("c");
        if (!c) return mat;
        if (a.get("alpha")) a.number("alpha");  // checked; opacity is not modelled
        Vec3 rgb;
        if (c->kind == Value::Kind::Vector) {
            if (c->items.size() != 3 && c->items.size() != 4)
                src_.fail(c->pos, "expected [r, g, b] or [r, g, b, a] for the colour");
            for (int i = 0; i < 3; ++i)
                rgb[i] = std::clamp(a.number(c->items[size_t(i)], "a colour component"), 0.0, 1.0);
            if (c->items.size() == 4) a.number(c->items[3], "the alpha component");
        } else if (c->kind == Value::Kind::String) {
            rgb = namedColor(src_, *c);
        } else {
            src_.fail(c->pos,
                      "expected a colour: [r, g, b, a], a name such as \"red\", or \"#rrggbb\"");
        }
        return material(rgb);
    }

    int material(const Vec3& rgb) {
        auto key = std::make_tuple(rgb.x, rgb.y, rgb.z);
        auto it = materialOf_.find(key);
        if (it != materialOf_.end()) return it->second;
        Material m = scene_.materials[0];
        m.color = rgb;
        scene_.materials.push_back(m);
        int id = int(scene_.materials.size()) - 1;
        materialOf_[key] = id;
        return id;
    }

    /// A size or radius: finite (the lexer made sure) and not negative.
    double nonNegative(const Args& a, const std::string& name, double value) {
        if (value < 0.0) src_.fail(a.get(name)->pos, "'" + name + "' must not be negative");
        return value;
    }

    Built primitive(const Node& n, const Transform& xf, int mat) {
        const std::string& k = n.name;
        Shape shape;
        Transform local;
        if (k == "cube") {
            Args a(src_, n, {"size", "center"}, {});
            Vec3 size(1.0);
            if (const Value* s = a.get("size")) {
                size = s->kind == Value::Kind::Number ? Vec3(s->number)
                                                      : a.vec3(*s, "'size' of cube()");
                for (int i = 0; i < 3; ++i)
                    if (size[i] < 0.0) src_.fail(s->pos, "cube sizes must not be negative");
            }
            bool center = a.boolean("center", false);
            if (size.x == 0.0 || size.y == 0.0 || size.z == 0.0) return emptyPrimitive();
            Block b;
            b.lo = center ? -0.5 * size : Vec3(0.0);
            b.hi = b.lo + size;
            shape = b;
            ++counts_.cubes;
        } else if (k == "sphere") {
            Args a(src_, n, {"r"}, {"d"});
            double r = 1.0;
            if (auto d = a.number("d"))
                r = 0.5 * nonNegative(a, "d", *d);  // d takes precedence, as in OpenSCAD
            else if (auto rr = a.number("r"))
                r = nonNegative(a, "r", *rr);
            if (r == 0.0) return emptyPrimitive();
            shape = Sphere{Vec3(0.0), r};
            ++counts_.spheres;
        } else {
            Args a(src_, n, {"h", "r1", "r2", "center"}, {"r", "d", "d1", "d2"});
            double h = 1.0, r1 = 1.0, r2 = 1.0;
            if (auto v = a.number("h")) h = nonNegative(a, "h", *v);
            // OpenSCAD: d over r, d1 over r1, d2 over r2; r1/r2 (or d1/d2) over r (or d).
            std::optional<double> r, rr1, rr2;
            if (auto d = a.number("d"))
                r = 0.5 * nonNegative(a, "d", *d);
            else if (auto v = a.number("r"))
                r = nonNegative(a, "r", *v);
            if (auto d = a.number("d1"))
                rr1 = 0.5 * nonNegative(a, "d1", *d);
            else if (auto v = a.number("r1"))
                rr1 = nonNegative(a, "r1", *v);
            if (auto d = a.number("d2"))
                rr2 = 0.5 * nonNegative(a, "d2", *d);
            else if (auto v = a.number("r2"))
                rr2 = nonNegative(a, "r2", *v);
            if (r) r1 = r2 = *r;
            if (rr1) r1 = *rr1;
            if (rr2) r2 = *rr2;
            bool center = a.boolean("center", false);
            if (h == 0.0 || (r1 == 0.0 && r2 == 0.0)) return emptyPrimitive();
            shape = Cone{r1, r2, h, false};
            if (center) local = Transform::translate({0.0, 0.0, -0.5 * h});
            ++(r1 == r2 ? counts_.cylinders : counts_.cones);
        }
        Primitive p = makePrimitive(std::move(shape), xf * local, mat);
        if (!p.worldBox.isBounded())
            src_.fail(n.pos, k + "() is too large: its bounds overflow a double");
        p.origin = src_.where(n.pos);
        scene_.prims.push_back(std::move(p));
        return Built::of(scene_.tree.leaf(uint32_t(scene_.prims.size() - 1)));
    }

    Built emptyPrimitive() {
        ++counts_.empty;
        return Built::empty();
    }

    const SourceText& src_;
    Scene& scene_;
    OpenScadCounts& counts_;
    std::map<std::tuple<double, double, double>, int> materialOf_;
};

}  // namespace

void buildModel(const SourceText& src, const std::vector<Node>& top, Scene& scene,
                OpenScadCounts& counts) {
    scene.materials[0].color = hexColor(kDefaultColor);
    scene.tree.root = Builder(src, scene, counts).model(top);
}

}  // namespace lancer::openscad

namespace lancer {

const std::vector<std::string>& openScadSupportedNodes() {
    static const std::vector<std::string> nodes = {
        "group",  "union", "difference", "intersection", "render", "multmatrix", "translate",
        "rotate", "scale", "mirror",     "color",        "cube",   "sphere",     "cylinder"};
    return nodes;
}

}  // namespace lancer
