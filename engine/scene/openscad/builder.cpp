#include "engine/scene/openscad/builder.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>
#include <tuple>

#include "engine/scene/mesh_file.h"
#include "engine/scene/openscad/colors.h"
#include "engine/scene/openscad/dxf.h"
#include "engine/scene/openscad/facets.h"
#include "engine/scene/openscad/hull3d.h"
#include "engine/scene/openscad/region2d.h"
#include "engine/scene/openscad/surface.h"
#include "engine/scene/openscad/text2d.h"

namespace lancer::openscad {

namespace {

/// A number as the model writes it: the shortest form that reads back ("90", "12.5").
std::string twistText(double x) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

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
                continue;  // $fn, $fa, $fs: read by special() where they count facets
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
    Builder(const SourceText& src, Scene& scene, OpenScadCounts& counts, const ReadOptions& options)
        : src_(src),
          scene_(scene),
          counts_(counts),
          facets_(options.facets == Facets::OpenScad),
          twistParts_(options.twistParts) {}

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
        if (b.kind != Built::Kind::Node && first2D_)
            src_.fail(first2D_->pos,
                      "the model is 2D (its first 2D node is '" + first2D_->name +
                          "') and has no solid: Lancer traces solids; extrude the drawing with "
                          "linear_extrude or rotate_extrude to render it");
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
        if (k == "polyhedron") return polyhedron(n, xf, mat);
        if (k == "hull") return hullNode(n, xf, mat);
        if (k == "linear_extrude") return linearExtrude(n, xf, mat);
        if (k == "rotate_extrude") return rotateExtrude(n, xf, mat);
        if (k == "import" && isMeshFile(importFile(n))) return importMesh(n, xf, mat);
        if (k == "surface") return surface(n, xf, mat);
        if (k == "import" && !importsDxf(n))
            src_.fail(n.pos, "import() of '" + importFile(n) +
                                 "': Lancer imports STL and OFF meshes and DXF drawings (inside "
                                 "an extrusion); other formats are not supported");
        if (is2DNode(k) || k == "import") {
            // As OpenSCAD's render: a 2D object beside solids is not part of the solid model.
            if (!first2D_) first2D_ = &n;
            ++counts_.leftOut2D;
            return Built::absent();
        }
        refuse(n);
    }

    static bool is2DNode(const std::string& k) {
        static const char* names[] = {"circle", "square",     "polygon",   "text",
                                      "offset", "projection", "import_dxf"};
        for (const char* t : names)
            if (k == t) return true;
        return false;
    }

    // ---- 2D regions: a tree of convex pieces and ellipses, in the plane z = 0 ----

    /// A 2D region node: a convex piece, an ellipse (the unit disk under `disk`), or a boolean.
    struct Region {
        enum class Kind : uint8_t { Piece, Disk, Union, Intersection, Difference } kind;
        ConvexPiece piece;
        glm::dmat3 disk{1.0};  ///< 2D affine (homogeneous) of the unit disk
        int a = -1, b = -1;
        size_t pos = 0;  ///< the node that made it
        /// A piece: the longest edge of the outlines it was cut from (its own edges may be
        /// parts of them); 0: its own edges are the outline's.
        double outlineEdge = 0.0;
        /// A disk: OpenSCAD's fragments of its circle (for hull()); 0: by the default rule.
        int fragments = 0;
    };

    int region(Region r) {
        regions_.push_back(std::move(r));
        return int(regions_.size()) - 1;
    }
    int regionOp(Region::Kind k, const std::vector<int>& items, size_t pos) {
        int acc = items[0];
        for (size_t i = 1; i < items.size(); ++i) {
            Region r{k, {}, glm::dmat3(1.0), acc, items[i], pos};
            acc = region(std::move(r));
        }
        return acc;
    }

    /// The plane part of a transform: x and y of the image of (x, y, 0), as OpenSCAD applies a
    /// 3D matrix to 2D geometry.
    static glm::dmat3 planeAffine(const Transform& t) {
        glm::dmat3 a(1.0);
        a[0] = {t.m[0][0], t.m[0][1], 0.0};
        a[1] = {t.m[1][0], t.m[1][1], 0.0};
        a[2] = {t.m[3][0], t.m[3][1], 1.0};
        return a;
    }

    Built region2(const Node& n, const glm::dmat3& af, const Node& extrude) {
        if (n.disable || n.background) {
            ++counts_.leftOut;
            return Built::absent();
        }
        const std::string& k = n.name;
        if (k == "group" || k == "union" || k == "render" || k == "color") {
            if (k == "render")
                Args(src_, n, {"convexity"}, {});
            else if (k == "color")
                color(n, 0);  // checked; the extrusion takes the colour of its own context
            else
                Args(src_, n, {}, {});
            return regionUnion(n.children, af, extrude);
        }
        if (k == "intersection" || k == "difference") {
            Args(src_, n, {}, {});
            std::vector<Built> kids;
            for (const Node& c : n.children) {
                Built b = region2(c, af, extrude);
                if (b.kind != Built::Kind::Absent) kids.push_back(b);
            }
            if (kids.empty()) return Built::empty();
            if (k == "intersection") {
                std::vector<int> items;
                for (const Built& b : kids) {
                    if (b.kind == Built::Kind::Empty) return Built::empty();
                    items.push_back(b.node);
                }
                return Built::of(regionOp(Region::Kind::Intersection, items, n.pos));
            }
            if (kids[0].kind == Built::Kind::Empty) return Built::empty();
            std::vector<int> items{kids[0].node};
            for (size_t i = 1; i < kids.size(); ++i)
                if (kids[i].kind == Built::Kind::Node) items.push_back(kids[i].node);
            return Built::of(regionOp(Region::Kind::Difference, items, n.pos));
        }
        if (k == "multmatrix" || k == "translate" || k == "rotate" || k == "scale" ||
            k == "mirror") {
            ++counts_.transforms;
            glm::dmat3 t = af * planeAffine(transform(n));
            double det = t[0][0] * t[1][1] - t[1][0] * t[0][1];
            if (!(det != 0.0) || !std::isfinite(det))
                src_.fail(n.pos, k + "() flattens its 2D children to nothing");
            return regionUnion(n.children, t, extrude);
        }
        if (k == "square" || k == "circle" || k == "polygon" || k == "text") {
            if (!n.children.empty()) src_.fail(n.children.front().pos, k + "() takes no children");
            return shape2(n, af);
        }
        if (k == "offset") return offsetNode(n, af, extrude);
        if (k == "hull") return hull2(n, af, extrude);
        if (k == "import") return importDxf(n, af);
        if (is2DNode(k))
            src_.fail(n.pos, "the 2D node '" + k +
                                 "' is not supported (supported in 2D: square, "
                                 "circle, polygon, text, their booleans and transforms)");
        if (k == "linear_extrude" || k == "rotate_extrude" || k == "cube" || k == "sphere" ||
            k == "cylinder")
            src_.fail(n.pos, "the 3D node '" + k + "' is inside " + extrude.name + "() at " +
                                 src_.where(extrude.pos) + ", which extrudes 2D children only");
        refuse(n);
    }

    // ---- hull() in 2D ----

    /// hull() of 2D children: the convex hull of their corners, a circle's by OpenSCAD's polygon
    /// of it at its $fn, $fa, $fs (its sagitta joins the profile's error); one convex piece.
    /// Booleans among the children are refused by name (their outline is not their parts').
    Built hull2(const Node& n, const glm::dmat3& af, const Node& extrude) {
        Args(src_, n, {}, {});
        ++counts_.operators;
        Built b = regionUnion(n.children, af, extrude);
        if (b.kind != Built::Kind::Node) return b;
        std::vector<Vec2> pts;
        std::vector<int> stack{b.node};
        while (!stack.empty()) {
            const Region& g = regions_[size_t(stack.back())];
            stack.pop_back();
            if (g.kind == Region::Kind::Union) {
                stack.push_back(g.a);
                stack.push_back(g.b);
            } else if (g.kind == Region::Kind::Piece) {
                pts.insert(pts.end(), g.piece.vertices.begin(), g.piece.vertices.end());
            } else if (g.kind == Region::Kind::Disk) {
                const int k =
                    g.fragments > 0 ? g.fragments : FragmentRule{}.fragments(planeStretch(g.disk));
                for (const Vec2& p : circlePolygon(1.0, k))
                    pts.push_back(Vec2(g.disk * glm::dvec3(p, 1.0)));
                profileSagitta_ = std::max(profileSagitta_, sagitta(1.0, k) * planeStretch(g.disk));
                ++counts_.facetedShapes;
            } else {
                src_.fail(g.pos, "a 2D boolean inside hull() at " + src_.where(n.pos) +
                                     " is not supported: Lancer takes the hull of squares, "
                                     "circles, polygons, text and their unions and transforms");
            }
        }
        const std::vector<Vec2> ring = convexHull2(std::move(pts));
        if (ring.size() < 3) return emptyPrimitive();
        ++counts_.hulls;
        return pieces({ring}, n.pos);
    }

    // ---- import() of DXF drawings ----

    /// The file an import() names (its 'file' argument), as written.
    std::string importFile(const Node& n) const {
        for (size_t i = 0; i < n.args.size(); ++i)
            if (n.args[i].name == "file" || (i == 0 && n.args[i].name.empty()))
                if (n.args[i].value.kind == Value::Kind::String) return n.args[i].value.str;
        return "";
    }

    bool importsDxf(const Node& n) const {
        std::string e = std::filesystem::path(importFile(n)).extension().string();
        for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
        return e == ".dxf";
    }

    /// import() of an STL or OFF mesh, found beside the .csg: a closed mesh as a solid.
    Built importMesh(const Node& n, const Transform& xf, int mat) {
        Args a(src_, n, {"file", "layer", "convexity", "origin", "scale"},
               {"timestamp", "center", "dpi", "id", "width", "height"});
        if (!n.children.empty()) src_.fail(n.children.front().pos, "import() takes no children");
        const Value* f = a.get("file");
        std::filesystem::path path(f->str);
        if (path.is_relative()) path = std::filesystem::path(src_.path()).parent_path() / path;
        TriangleMesh m;
        try {
            m = readMeshFile(path.string());
        } catch (const SceneError& e) {
            src_.fail(f->pos, std::string("import(): ") + e.what());
        }
        return meshNode(std::move(m), xf, mat, n.pos, "import() of '" + f->str + "'");
    }

    /// surface() of a heightmap (.dat or PNG) found beside the .csg: OpenSCAD's closed mesh of
    /// it (surface.h) as a solid; `convexity` is read and ignored.
    Built surface(const Node& n, const Transform& xf, int mat) {
        Args a(src_, n, {"file", "center", "invert", "convexity"}, {"timestamp"});
        if (!n.children.empty()) src_.fail(n.children.front().pos, "surface() takes no children");
        const Value* f = a.get("file");
        if (!f || f->kind != Value::Kind::String)
            src_.fail(n.pos, "surface() needs a 'file' string");
        const bool center = a.boolean("center", false), invert = a.boolean("invert", false);
        a.number("convexity");
        std::filesystem::path path(f->str);
        if (path.is_relative()) path = std::filesystem::path(src_.path()).parent_path() / path;
        TriangleMesh m;
        try {
            m = heightMapMesh(
                readHeightMap(SourceText::fromImportedFile(path.string(), "a heightmap"), invert),
                center);
        } catch (const SceneError& e) {
            src_.fail(f->pos, std::string("surface(): ") + e.what());
        }
        ++counts_.surfaces;
        return meshNode(std::move(m), xf, mat, n.pos, "surface() of '" + f->str + "'");
    }

    /// A closed mesh as the union of its convex pieces (mesh_solid.h), each placed by `xf`.
    Built meshNode(TriangleMesh m, const Transform& xf, int mat, size_t pos,
                   const std::string& what) {
        MeshSolid solid;
        try {
            solid = meshSolid(std::move(m));
        } catch (const MeshError& e) {
            src_.fail(pos, what + " is " + e.what());
        }
        if (solid.pieces.empty()) return emptyPrimitive();
        ++counts_.meshes;
        counts_.meshPieces += int(solid.pieces.size());
        std::vector<int> items;
        items.reserve(solid.pieces.size());
        for (Polytope& p : solid.pieces)
            items.push_back(place(std::move(p), xf, mat, pos, what).node);
        return Built::of(scene_.tree.balanced(Op::Union, items));
    }

    /// import() of a DXF file: the closed outlines of its layer (dxf.cpp), read as OpenSCAD
    /// reads them, arcs and circles cut by $fn, $fa, $fs; the file is found beside the .csg.
    Built importDxf(const Node& n, const glm::dmat3& af) {
        Args a(src_, n, {"file", "layer", "convexity", "origin", "scale"},
               {"timestamp", "center", "dpi", "id", "width", "height"});
        const Value* f = a.get("file");
        if (!f || f->kind != Value::Kind::String)
            src_.fail(n.pos, "import() needs a 'file' string");
        if (!importsDxf(n))
            src_.fail(f->pos, "import() of '" + f->str +
                                  "' inside a 2D context: only DXF drawings are 2D imports");
        std::string layer;
        if (const Value* l = a.get("layer")) {
            if (l->kind != Value::Kind::String)
                src_.fail(l->pos, "expected a string for 'layer' of import()");
            layer = l->str;
        }
        Vec2 origin(0.0);
        if (const Value* o = a.get("origin")) origin = vec2(a, *o, "'origin' of import()");
        const double scale = a.number("scale").value_or(1.0);
        if (!(std::isfinite(scale) && scale > 0.0))
            src_.fail(a.get("scale")->pos, "'scale' of import() must be a positive number");
        openscad::Fragments frag{special(n, "$fn", 0.0), special(n, "$fa", 12.0),
                                 special(n, "$fs", 2.0)};
        if (!(frag.fa > 0.0 && frag.fs > 0.0 && std::isfinite(frag.fn)))
            src_.fail(n.pos, "import() needs $fa > 0 and $fs > 0 to cut arcs");
        std::filesystem::path path(f->str);
        if (path.is_relative()) path = std::filesystem::path(src_.path()).parent_path() / path;
        openscad::DxfOutlines d;
        try {
            d = openscad::readDxf(path.string(), layer, origin, scale, frag);
        } catch (const SceneError& e) {
            src_.fail(f->pos, std::string("import(): ") + e.what());
        }
        ++counts_.dxfImports;
        counts_.dxfOpenChains += d.openChains;
        std::vector<std::vector<Vec2>> loops = std::move(d.loops);
        for (auto& loop : loops)
            for (Vec2& p : loop) p = Vec2(af * glm::dvec3(p, 1.0));
        size_t edges = 0;
        for (const auto& q : loops) edges += q.size();
        if (edges > 20000)
            src_.fail(n.pos, "import() of '" + f->str +
                                 "' has more than 20000 edges, which Lancer does not cut");
        return pieces(loops, n.pos);
    }

    // ---- offset ----

    /// offset(r > 0): the Minkowski sum of the child with a disk of radius r, exact. The sum
    /// distributes over union, and a convex piece's sum is the piece, a rectangle outward of each
    /// edge and a disk at each vertex; a disk's sum is the disk of radius + r. r < 0 erodes
    /// (erode), delta moves the outline (offsetDelta); children made by intersection or
    /// difference are refused by name.
    Built offsetNode(const Node& n, const glm::dmat3& af, const Node& extrude) {
        Args a(src_, n, {}, {"r", "delta", "chamfer"});
        // As OpenSCAD: r when given (round corners), else delta (mitred or chamfered).
        const bool byDelta = !a.get("r") && a.get("delta");
        const char* which = byDelta ? "delta" : "r";
        const bool chamfer = a.boolean("chamfer", false);
        double r = 0.0;
        if (auto v = a.number(which)) r = *v;
        if (!std::isfinite(r))
            src_.fail(a.get(which)->pos, std::string("offset(") + which + ") must be finite");
        // The radius in the parent frame: af must be a similarity for the disk to stay a disk.
        Vec2 ex(af[0][0], af[0][1]), ey(af[1][0], af[1][1]);
        double sx = glm::length(ex), sy = glm::length(ey);
        if (std::abs(sx - sy) > 1e-12 * std::max(sx, sy) ||
            std::abs(glm::dot(ex, ey)) > 1e-12 * sx * sy)
            src_.fail(n.pos, "offset() under a non-uniform scale or shear is not supported");
        double rr = r * sx;
        Built b = regionUnion(n.children, af, extrude);
        if (b.kind != Built::Kind::Node || rr == 0.0) return b;
        if (byDelta) return offsetDelta(b.node, rr, chamfer, n.pos);
        if (rr < 0.0) return erode(b.node, -rr, n.pos);
        std::vector<int> items;
        grow(b.node, rr, n.pos, items);
        return Built::of(regionOp(Region::Kind::Union, items, n.pos));
    }

    /// offset(delta = d): the region's outline moved out by d (in by -d), mitred or chamfered
    /// at its corners as Clipper does (offsetAdditions), exactly. A circle, which has no corner,
    /// becomes the circle of radius + d. The outline must be the children's paths: squares,
    /// polygons, text and DXF drawings whose outlines neither cross nor touch (nor, for d > 0,
    /// lie inside another child's, where the union's outline would not be theirs; for d < 0,
    /// of one child, as a negative r). Anything else is refused by name.
    Built offsetDelta(int id, double d, bool chamfer, size_t pos) {
        std::vector<int> disks, shapes, stack{id};
        while (!stack.empty()) {
            const int i = stack.back();
            stack.pop_back();
            const Region& g = regions_[size_t(i)];
            if (outlines_.count(i)) {
                shapes.push_back(i);
            } else if (g.kind == Region::Kind::Disk) {
                disks.push_back(i);
            } else if (g.kind == Region::Kind::Union) {
                stack.push_back(g.a);
                stack.push_back(g.b);
            } else {
                src_.fail(pos, "offset(delta) of the shape made at " + src_.where(g.pos) +
                                   " (a boolean or an offset) is not supported: Lancer offsets "
                                   "by delta squares, polygons, text, DXF drawings and circles");
            }
        }
        if (!disks.empty()) {
            if (disks.size() + shapes.size() > 1)
                src_.fail(pos, "offset(delta) of a circle (at " +
                                   src_.where(regions_[size_t(disks[0])].pos) +
                                   ") beside other shapes is not supported (only of one circle)");
            const int c = offsetCircle(regions_[size_t(disks[0])], d, pos);
            return c < 0 ? Built::empty() : Built::of(c);
        }
        if (d < 0.0 && shapes.size() > 1)
            src_.fail(pos,
                      "offset(delta < 0) is supported of one square, polygon, glyph or DXF "
                      "drawing only (the shapes made at " +
                          src_.where(regions_[size_t(shapes[0])].pos) + " and " +
                          src_.where(regions_[size_t(shapes[1])].pos) + ")");
        std::vector<std::vector<Vec2>> paths;
        std::vector<size_t> owner;
        for (size_t k = 0; k < shapes.size(); ++k)
            for (const auto& q : outlines_.at(shapes[k])) {
                paths.push_back(q);
                owner.push_back(k);
            }
        std::vector<Outline> outs;
        if (!regionOutlines(paths, outs))
            src_.fail(pos, "offset(delta) of outlines that cross or touch (of the shape" +
                               std::string(shapes.size() > 1 ? "s" : "") + " made at " +
                               src_.where(regions_[size_t(shapes[0])].pos) +
                               (shapes.size() > 1 ? ", ..." : "") +
                               ") is not supported: their region's outline is not their paths");
        std::vector<std::vector<Vec2>> loops;
        for (const Outline& o : outs) {
            const size_t k = owner[size_t(o.source)];
            if (o.parent >= 0 && owner[size_t(outs[size_t(o.parent)].source)] != k)
                src_.fail(
                    pos,
                    "offset(delta) of the shape made at " +
                        src_.where(regions_[size_t(shapes[k])].pos) +
                        ", which lies inside the shape made at " +
                        src_.where(
                            regions_[size_t(shapes[owner[size_t(outs[size_t(o.parent)].source)]])]
                                .pos) +
                        ", is not supported: their union's outline is not theirs");
            loops.push_back(o.points);
            // Shrinking grows the complement: the outline the other way round.
            if (d < 0.0) std::reverse(loops.back().begin(), loops.back().end());
        }
        std::vector<int> items;
        for (const auto& poly : offsetAdditions(loops, std::abs(d), chamfer))
            for (ConvexPiece& c : convexPieces({poly}))
                items.push_back(
                    region({Region::Kind::Piece, std::move(c), glm::dmat3(1.0), -1, -1, pos}));
        if (items.empty()) return Built::of(id);
        const int added = regionOp(Region::Kind::Union, items, pos);
        return Built::of(d > 0.0 ? regionOp(Region::Kind::Union, {id, added}, pos)
                                 : regionOp(Region::Kind::Difference, {id, added}, pos));
    }

    /// The circle `disk` (a Disk region) offset by `r` (either sign) as a new Disk region; -1
    /// when a negative offset leaves nothing. An ellipse is refused by name: its offset is no
    /// ellipse.
    int offsetCircle(const Region& disk, double r, size_t pos) {
        const Vec2 ex(disk.disk[0][0], disk.disk[0][1]), ey(disk.disk[1][0], disk.disk[1][1]);
        const double sx = glm::length(ex), sy = glm::length(ey);
        if (std::abs(sx - sy) > 1e-12 * std::max(sx, sy) ||
            std::abs(glm::dot(ex, ey)) > 1e-12 * sx * sy)
            src_.fail(pos, "offset() of an ellipse (the circle at " + src_.where(disk.pos) +
                               " under a non-uniform scale) is not supported");
        if (sx + r <= 0.0) return -1;
        glm::dmat3 d = disk.disk;
        d[0] = glm::dvec3(ex * ((sx + r) / sx), 0.0);
        d[1] = glm::dvec3(ey * ((sy + r) / sy), 0.0);
        return region({Region::Kind::Disk, {}, d, -1, -1, pos});
    }

    /// offset(r < 0) of one circle (the circle of radius - |r|) or of one square or polygon: the
    /// shape minus the Minkowski sum of its complement (within a box well beyond it) with the
    /// disk of radius |r|, exact. Erosion does not distribute over union, so anything else is
    /// refused by name.
    Built erode(int id, double r, size_t pos) {
        const Region root = regions_[size_t(id)];
        if (root.kind == Region::Kind::Disk) {
            const int d = offsetCircle(root, -r, pos);
            return d < 0 ? Built::empty() : Built::of(d);
        }
        std::vector<int> leaves, stack{id};
        while (!stack.empty()) {
            int i = stack.back();
            stack.pop_back();
            const Region& g = regions_[size_t(i)];
            if (g.kind == Region::Kind::Union) {
                stack.push_back(g.a);
                stack.push_back(g.b);
            } else if (g.kind == Region::Kind::Piece && g.pos == root.pos) {
                leaves.push_back(i);
            } else {
                src_.fail(pos,
                          "offset(r < 0) is supported of one square, polygon or circle only "
                          "(its child made at " +
                              src_.where(g.pos) + " is another shape or a boolean)");
            }
        }
        // The shape's pieces are disjoint: even-odd of a box and their outlines is the box
        // minus the shape.
        Vec2 lo(std::numeric_limits<double>::infinity()), hi(-lo);
        std::vector<std::vector<Vec2>> paths(1);
        for (int i : leaves) {
            paths.push_back(regions_[size_t(i)].piece.vertices);
            for (const Vec2& v : paths.back()) {
                lo = glm::min(lo, v);
                hi = glm::max(hi, v);
            }
        }
        double m = 2.0 * r + 0.1 * std::max(hi.x - lo.x, hi.y - lo.y);
        lo -= Vec2(m);
        hi += Vec2(m);
        paths[0] = {lo, {hi.x, lo.y}, hi, {lo.x, hi.y}};
        std::vector<int> items;
        for (ConvexPiece& c : convexPieces(paths))
            grow(region({Region::Kind::Piece, std::move(c), glm::dmat3(1.0), -1, -1, pos}), r, pos,
                 items);
        if (items.empty()) return Built::of(id);
        int cut = regionOp(Region::Kind::Union, items, pos);
        return Built::of(regionOp(Region::Kind::Difference, {id, cut}, pos));
    }

    void grow(int id, double r, size_t pos, std::vector<int>& out) {
        Region reg = regions_[size_t(id)];
        if (reg.kind == Region::Kind::Union) {
            grow(reg.a, r, pos, out);
            grow(reg.b, r, pos, out);
            return;
        }
        if (reg.kind == Region::Kind::Intersection || reg.kind == Region::Kind::Difference)
            src_.fail(pos, "offset() of an intersection or difference (made at " +
                               src_.where(reg.pos) + ") is not supported (only of unions)");
        if (reg.kind == Region::Kind::Disk) {
            out.push_back(offsetCircle(reg, r, pos));
            return;
        }
        out.push_back(id);
        const std::vector<Vec2>& v = reg.piece.vertices;
        for (size_t i = 0; i < v.size(); ++i) {
            Vec2 p = v[i], q = v[(i + 1) % v.size()];
            Vec2 e = q - p;
            double len = glm::length(e);
            if (!(len > 0.0)) continue;
            Vec2 o = Vec2(e.y, -e.x) * (r / len);  // outward of a counter-clockwise polygon
            std::vector<std::vector<Vec2>> rect{{p, p + o, q + o, q}};
            std::vector<ConvexPiece> ps = convexPieces(rect);
            for (ConvexPiece& c : ps)
                out.push_back(
                    region({Region::Kind::Piece, std::move(c), glm::dmat3(1.0), -1, -1, pos}));
            glm::dmat3 d(1.0);
            d[0][0] = d[1][1] = r;
            d[2] = glm::dvec3(p, 1.0);
            out.push_back(region({Region::Kind::Disk, {}, d, -1, -1, pos}));
        }
    }

    Built regionUnion(const std::vector<Node>& kids, const glm::dmat3& af, const Node& extrude) {
        std::vector<int> items;
        for (const Node& c : kids) {
            Built b = region2(c, af, extrude);
            if (b.kind == Built::Kind::Node) items.push_back(b.node);
        }
        if (items.empty()) return Built::empty();
        return Built::of(regionOp(Region::Kind::Union, items, kids.front().pos));
    }

    Built pieces(const std::vector<std::vector<Vec2>>& paths, size_t pos) {
        std::vector<ConvexPiece> ps = convexPieces(paths);
        if (ps.empty()) return emptyPrimitive();
        double edge = 0.0;
        for (const auto& q : paths)
            for (size_t i = 0; i < q.size(); ++i)
                edge = std::max(edge, glm::length(q[(i + 1) % q.size()] - q[i]));
        std::vector<int> items;
        for (ConvexPiece& p : ps)
            items.push_back(
                region({Region::Kind::Piece, std::move(p), glm::dmat3(1.0), -1, -1, pos, edge}));
        const int id = regionOp(Region::Kind::Union, items, pos);
        outlines_[id] = paths;
        return Built::of(id);
    }

    Vec2 vec2(const Args& a, const Value& v, const std::string& what) {
        if (v.kind != Value::Kind::Vector || (v.items.size() != 2 && v.items.size() != 3))
            src_.fail(v.pos, "expected [x, y] for " + what);
        return {a.number(v.items[0], what), a.number(v.items[1], what)};
    }

    Built shape2(const Node& n, const glm::dmat3& af) {
        const std::string& k = n.name;
        if (k == "text") return text(n, af);
        auto apply = [&](Vec2 p) { return Vec2(af * glm::dvec3(p, 1.0)); };
        if (k == "square") {
            Args a(src_, n, {"size", "center"}, {});
            Vec2 size(1.0);
            if (const Value* s = a.get("size")) {
                size = s->kind == Value::Kind::Number ? Vec2(s->number)
                                                      : vec2(a, *s, "'size' of square()");
                if (size.x < 0.0 || size.y < 0.0)
                    src_.fail(s->pos, "square sizes must not be negative");
            }
            bool center = a.boolean("center", false);
            if (size.x == 0.0 || size.y == 0.0) return emptyPrimitive();
            Vec2 lo = center ? -0.5 * size : Vec2(0.0), hi = lo + size;
            ++counts_.squares;
            return pieces({{apply(lo), apply({hi.x, lo.y}), apply(hi), apply({lo.x, hi.y})}},
                          n.pos);
        }
        if (k == "circle") {
            Args a(src_, n, {"r"}, {"d"});
            double r = 1.0;
            if (auto d = a.number("d"))
                r = 0.5 * nonNegative(a, "d", *d);
            else if (auto rr = a.number("r"))
                r = nonNegative(a, "r", *rr);
            if (r == 0.0) return emptyPrimitive();
            ++counts_.circles;
            if (facets_) {
                // OpenSCAD's polygon of the circle; its sagitta, stretched by the plane map, is
                // the profile's error until the extrusion's transform is known.
                const int k = fragmentRule(n).fragments(r);
                std::vector<Vec2> poly = circlePolygon(r, k);
                for (Vec2& p : poly) p = apply(p);
                ++counts_.facetedShapes;
                profileSagitta_ = std::max(profileSagitta_, sagitta(r, k) * planeStretch(af));
                return pieces({poly}, n.pos);
            }
            glm::dmat3 s(1.0);
            s[0][0] = s[1][1] = r;
            return Built::of(region({Region::Kind::Disk,
                                     {},
                                     af * s,
                                     -1,
                                     -1,
                                     n.pos,
                                     0.0,
                                     fragmentRule(n).fragments(r)}));
        }
        Args a(src_, n, {"points", "paths", "convexity"}, {});
        const Value* pts = a.get("points");
        if (!pts) return emptyPrimitive();
        if (pts->kind != Value::Kind::Vector)
            src_.fail(pts->pos, "expected a list of [x, y] points for 'points' of polygon()");
        std::vector<Vec2> p;
        for (const Value& v : pts->items) p.push_back(apply(vec2(a, v, "a polygon point")));
        std::vector<std::vector<Vec2>> paths;
        if (const Value* ps = a.get("paths")) {
            if (ps->kind != Value::Kind::Vector)
                src_.fail(ps->pos, "expected a list of index lists for 'paths' of polygon()");
            for (const Value& path : ps->items) {
                if (path.kind != Value::Kind::Vector)
                    src_.fail(path.pos, "expected a list of point indices for a polygon path");
                std::vector<Vec2> q;
                for (const Value& iv : path.items) {
                    double i = a.number(iv, "a point index");
                    if (i < 0 || i >= double(p.size()) || i != std::floor(i))
                        src_.fail(iv.pos,
                                  "a polygon path index must be a whole number from 0 "
                                  "to " +
                                      std::to_string(p.size() - 1));
                    q.push_back(p[size_t(i)]);
                }
                paths.push_back(std::move(q));
            }
        } else {
            paths.push_back(p);
        }
        size_t edges = 0;
        for (const auto& q : paths) edges += q.size();
        if (edges > 20000)
            src_.fail(n.pos, "polygon() has more than 20000 edges, which Lancer does not cut");
        ++counts_.polygons;
        return pieces(paths, n.pos);
    }

    /// xf followed by a shift of `z` along local z, with the inverse composed exactly so that
    /// shapes shifted by different amounts see the same local x and y of a ray (their walls then
    /// meet bit for bit).
    static Transform shiftedZ(const Transform& xf, double z) {
        Transform t;
        t.m = xf.m * glm::translate(Mat4(1.0), Vec3(0.0, 0.0, z));
        t.inv = glm::translate(Mat4(1.0), Vec3(0.0, 0.0, -z)) * xf.inv;
        t.normal = xf.normal;
        return t;
    }

    Built place(Shape shape, const Transform& xf, int mat, size_t pos, const std::string& what) {
        Primitive p = makePrimitive(std::move(shape), xf, mat);
        if (!p.worldBox.isBounded())
            src_.fail(pos, what + " is too large: its bounds overflow a double");
        p.origin = src_.where(pos);
        scene_.prims.push_back(std::move(p));
        return Built::of(scene_.tree.leaf(uint32_t(scene_.prims.size() - 1)));
    }

    // ---- linear_extrude ----

    Built linearExtrude(const Node& n, const Transform& xf, int mat) {
        Args a(src_, n, {"height"},
               {"v", "center", "convexity", "twist", "slices", "scale", "segments", "file", "layer",
                "origin"});
        if (a.get("file"))
            src_.fail(
                a.get("file")->pos,
                "linear_extrude(file = ...) imports a DXF drawing, which Lancer does not read");
        double h = 100.0;  // OpenSCAD's default
        if (auto v = a.number("height")) h = *v;
        if (const Value* v = a.get("v")) {
            Vec3 d = a.vec3(*v, "'v' of linear_extrude()");
            if (d.x != 0.0 || d.y != 0.0 || !(d.z > 0.0))
                src_.fail(v->pos,
                          "linear_extrude along a direction other than +z is not "
                          "supported");
            h = d.z;
        }
        const double twist = a.number("twist").value_or(0.0);
        const std::optional<double> slicesArg = a.number("slices");
        a.number("segments");
        Vec2 scale(1.0);
        if (const Value* s = a.get("scale")) {
            scale = s->kind == Value::Kind::Number ? Vec2(s->number)
                                                   : vec2(a, *s, "'scale' of linear_extrude()");
            if (scale.x < 0.0 || scale.y < 0.0)
                src_.fail(s->pos, "'scale' of linear_extrude() must not be negative");
        }
        bool center = a.boolean("center", false);
        Built r = regionUnion(n.children, glm::dmat3(1.0), n);
        noteProfileFacets(xf, std::max({1.0, scale.x, scale.y}));
        if (r.kind != Built::Kind::Node) return r;
        if (!(h > 0.0)) return emptyPrimitive();  // OpenSCAD makes nothing of it
        ++counts_.linearExtrudes;
        Transform local = center ? xf * Transform::translate({0.0, 0.0, -0.5 * h}) : xf;
        if (twist != 0.0) {
            if (!std::isfinite(twist))
                src_.fail(a.get("twist")->pos, "'twist' of linear_extrude() must be finite");
            const int slices = twistSlices(n, slicesArg, r.node, h, twist, scale);
            ++counts_.twistedExtrudes;
            counts_.twistSlices += slices;
            TwistedExtrusion tw{local, mat,    h, glm::radians(twist),
                                scale, slices, 1, stretch(local)};
            // Every piece makes a polytope per part: within the budget, fewer parts, and a
            // model whose OpenSCAD slices alone are over it is refused.
            const double pieces = double(countPieces(r.node));
            if (double(slices) * pieces > double(kMaxTwistPolytopes))
                src_.fail(n.pos, "linear_extrude with twist: " + std::to_string(slices) +
                                     " slices of " + twistText(pieces) +
                                     " convex pieces is over the " +
                                     std::to_string(kMaxTwistPolytopes) +
                                     " polytopes Lancer makes of a twisted extrusion");
            const int parts = twistParts_ > 0
                                  ? std::min(twistParts_, kMaxTwistSubSlices)
                                  : twistSubSlices(r.node, tw, std::sqrt(regionMaxR2(r.node)));
            tw.sub =
                std::min(parts, std::max(1, int(double(kMaxTwistPolytopes) / (slices * pieces))));
            counts_.twistSubSlices = std::max(counts_.twistSubSlices, tw.sub);
            return twistRegion(r.node, n, tw);
        }
        return extrudeRegion(r.node, n, local, mat, h, (scale - 1.0) / h);
    }

    // ---- linear_extrude with twist ----

    /// A twisted extrusion: the section at height z = h t (0 <= t <= 1) is the region rotated by
    /// -twist t (OpenSCAD turns clockwise seen from +z for a positive twist), then scaled by
    /// 1 - (1 - scale) t per axis. Lancer, like OpenSCAD, cuts it into `slices` equal slices
    /// and makes each convex piece's slice the convex hull of its two end sections.
    struct TwistedExtrusion {
        Transform xf;
        int mat;
        double h, twist;  ///< height, total twist in radians
        Vec2 scale;       ///< the top section's scale
        int slices;
        int sub;      ///< each slice cut again into this many (twistSubSlices)
        double norm;  ///< the most xf stretches a length (stretch)
    };

    /// The most `xf` stretches a length: its linear part's largest singular value (power
    /// iteration on M^T M, which converges from above on the Rayleigh quotient's root).
    static double stretch(const Transform& xf) {
        glm::dmat3 m(0.0);
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) m[c][r] = xf.m[c][r];
        const glm::dmat3 g = glm::transpose(m) * m;
        Vec3 v(0.577, 0.578, 0.579);
        double e = 0.0;
        for (int i = 0; i < 100; ++i) {
            const Vec3 w = g * v;
            const double len = glm::length(w);
            if (!(len > 0.0)) return 0.0;
            e = len / glm::length(v);
            v = w / len;
        }
        return std::sqrt(e) * (1.0 + 1e-9);
    }

    /// The linear map of the section at fraction t of the height.
    static glm::dmat2 twistSection(const TwistedExtrusion& tw, double t) {
        const double a = -tw.twist * t, c = std::cos(a), s = std::sin(a);
        const Vec2 sc = Vec2(1.0) - (Vec2(1.0) - tw.scale) * t;
        return glm::dmat2(sc.x * c, sc.y * s, -sc.x * s, sc.y * c);  // columns: S R
    }

    /// The largest squared distance from the axis of the region's parts' vertices (a circle's
    /// facets lie on it): OpenSCAD's radius for its default slice count. It is OpenSCAD's own
    /// value for unions of pieces and circles; for an intersection or difference it is the
    /// larger bound of the parts (OpenSCAD measures the outline left after the boolean).
    double regionMaxR2(int id) const {
        const Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Piece) {
            double m = 0.0;
            for (const Vec2& v : r.piece.vertices) m = std::max(m, glm::dot(v, v));
            return m;
        }
        if (r.kind == Region::Kind::Disk) {
            const double c = std::hypot(r.disk[2][0], r.disk[2][1]);
            const double e = std::max(std::hypot(r.disk[0][0], r.disk[0][1]),
                                      std::hypot(r.disk[1][0], r.disk[1][1]));
            return (c + e) * (c + e);
        }
        const double a = regionMaxR2(r.a), b = regionMaxR2(r.b);
        if (r.kind == Region::Kind::Union) return std::max(a, b);
        if (r.kind == Region::Kind::Intersection) return std::min(a, b);
        return a;
    }

    /// A special variable ($fn, $fa, $fs) given on the node, or OpenSCAD's default.
    double special(const Node& n, const char* name, double fallback) const {
        for (const Arg& g : n.args)
            if (g.name == name) {
                if (g.value.kind != Value::Kind::Number)
                    src_.fail(g.value.pos, std::string("expected a number for ") + name);
                return g.value.number;
            }
        return fallback;
    }

    /// The slice count: `slices` when it is a positive integer (OpenSCAD truncates it), else
    /// OpenSCAD 2021.01's rule for a twist without scale (Calc::get_helix_slices): at least
    /// ceil(|twist| / 120); with $fn > 0, ceil(|twist| / 360 $fn); else the fewer of
    /// ceil(|twist| / $fa) and ceil(helix length / $fs), the helix of the largest radius.
    int twistSlices(const Node& n, const std::optional<double>& given, int region, double h,
                    double twist, const Vec2& scale) const {
        if (given && std::isfinite(*given) && *given >= 1.0) {
            if (*given > double(kMaxTwistSlices))
                src_.fail(n.pos, "linear_extrude with slices = " + twistText(*given) +
                                     ": Lancer makes at most " + std::to_string(kMaxTwistSlices) +
                                     " slices");
            return int(*given);
        }
        if (scale != Vec2(1.0))
            src_.fail(n.pos, "linear_extrude with twist = " + twistText(twist) +
                                 " and scale without 'slices': OpenSCAD's default slice count "
                                 "for a scaled twist (its conical-helix rule) is not "
                                 "implemented; give 'slices'");
        const double fn = special(n, "$fn", 0.0), fa = special(n, "$fa", 12.0),
                     fs = special(n, "$fs", 2.0);
        const double tw = std::abs(twist), r2 = regionMaxR2(region);
        double s = std::max(std::ceil(tw / 120.0), 1.0);
        if (std::sqrt(r2) >= openscad::kGridFine && std::isfinite(fn)) {
            if (fn > 0.0) {
                s = std::max(std::ceil(tw / 360.0 * fn), s);
            } else {
                const double T = glm::radians(tw), c = h / T;
                const double helix = T * std::sqrt(r2 + c * c);
                s = std::max(std::min(std::ceil(tw / fa), std::ceil(helix / fs)), s);
            }
        }
        if (!(s <= double(kMaxTwistSlices)))
            src_.fail(n.pos, "linear_extrude with twist = " + twistText(twist) + " needs " +
                                 twistText(s) +
                                 " slices by OpenSCAD's rule: Lancer makes at "
                                 "most " +
                                 std::to_string(kMaxTwistSlices));
        return int(s);
    }

    static constexpr int kMaxTwistSlices = 10000;  ///< slices beyond this are refused
    /// The most facets (fragments times rings) of one faceted sphere: $fn = 1414.
    static constexpr double kMaxSphereFacets = 1e6;
    static constexpr int kMaxTwistSubSlices = 16;  ///< the most a slice is cut again
    /// The most polytopes one twisted extrusion makes (example020's spring: 20,480).
    static constexpr int kMaxTwistPolytopes = 200000;

    /// A convex piece's centre (its corners' mean) and its corners' farthest distance from it.
    static std::pair<Vec2, double> pieceReach(const std::vector<Vec2>& v) {
        Vec2 c(0.0);
        for (const Vec2& p : v) c += p;
        c /= double(v.size());
        double w = 0.0;
        for (const Vec2& p : v) w = std::max(w, glm::length(p - c));
        return {c, w};
    }

    /// The convex pieces of a region (its disks are not sliced).
    size_t countPieces(int id) const {
        const Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Piece) return 1;
        if (r.kind == Region::Kind::Disk) return 0;
        return countPieces(r.a) + countPieces(r.b);
    }

    /// How many parts each of OpenSCAD's slices is cut into: a piece's hull strays from the
    /// twisted piece by w dA / 2 to first order (w its corners' reach from their mean, dA the
    /// turn), which for a long piece of a non-convex region is its own width at OpenSCAD's
    /// slices (example009's fan: 1.7 on arms 4 wide). Cut until that is 0.2% of the region's
    /// radius `rho`, at most 16 times; the same for every piece, so their slices meet.
    int twistSubSlices(int id, const TwistedExtrusion& tw, double rho) const {
        const Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Disk) return 1;  // exact: no slices
        if (r.kind != Region::Kind::Piece)
            return std::max(twistSubSlices(r.a, tw, rho), twistSubSlices(r.b, tw, rho));
        const auto [c, w] = pieceReach(r.piece.vertices);
        const double first = w * std::abs(tw.twist) / tw.slices / 2.0;
        if (!(rho > 0.0)) return 1;
        return int(std::clamp(std::ceil(first / (0.002 * rho)), 1.0, double(kMaxTwistSubSlices)));
    }

    /// Records how far OpenSCAD's own mesh of a twisted extrusion strays from the exact
    /// surface (OpenScadCounts::openScadTwistMeshError), for a piece or circle whose corners lie
    /// within `rho` of the axis and whose outline edges (OpenSCAD's wall quads) are at most
    /// `longest` long. Per OpenSCAD slice (turn D, scale from s0 to s1, S the larger, dS the
    /// change): a wall point's exact path is a curve S(t) R(t D) x, which strays from the chord
    /// between the slice's ends by |x| (S D^2 / 8 + dS D / 4) (its second derivative over 8);
    /// the quad between the ends is cut into two triangles, which stray from the bilinear
    /// surface by a quarter of |(S1 R1 - S0 R0) e| <= |e| (S D + dS). Then stretched by xf.
    void noteOpenScadTwistMesh(const TwistedExtrusion& tw, double rho, double longest) {
        const double d = std::abs(tw.twist) / tw.slices;
        for (int j = 0; j < tw.slices; ++j) {
            const double t0 = double(j) / tw.slices, t1 = double(j + 1) / tw.slices;
            const Vec2 s0 = Vec2(1.0) - (Vec2(1.0) - tw.scale) * t0;
            const Vec2 s1 = Vec2(1.0) - (Vec2(1.0) - tw.scale) * t1;
            const double smax = std::max({s0.x, s0.y, s1.x, s1.y});
            const double dS = std::max(std::abs(s1.x - s0.x), std::abs(s1.y - s0.y));
            const double e =
                rho * (smax * d * d / 8.0 + dS * d / 4.0) + longest * (smax * d + dS) / 4.0;
            counts_.openScadTwistMeshError = std::max(counts_.openScadTwistMeshError, tw.norm * e);
            if (tw.scale.x == tw.scale.y && tw.scale.x == 1.0) break;  // every slice alike
        }
    }

    /// The twisted extrusion of the region's node: as extrudeRegion, the booleans of the 2D
    /// node become booleans of the twisted leaves (each height's section is the region under
    /// one linear map, which commutes with them).
    Built twistRegion(int id, const Node& n, const TwistedExtrusion& tw) {
        const Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Union || r.kind == Region::Kind::Intersection ||
            r.kind == Region::Kind::Difference) {
            Built a = twistRegion(r.a, n, tw);
            Built b = twistRegion(r.b, n, tw);
            return Built::of(scene_.tree.combine(csgOp(r.kind), a.node, b.node));
        }
        if (r.kind == Region::Kind::Disk) {
            // A round circle centred on the axis turns into itself: the extrusion is the
            // untwisted one, traced exactly. Any other circle or ellipse would sweep a helical
            // tube, which is refused.
            const glm::dmat3& d = r.disk;
            const Vec2 u(d[0][0], d[0][1]), v(d[1][0], d[1][1]);
            const double tol = 1e-12 * (glm::dot(u, u) + glm::dot(v, v));
            if (d[2][0] != 0.0 || d[2][1] != 0.0 || std::abs(glm::dot(u, v)) > tol ||
                std::abs(glm::dot(u, u) - glm::dot(v, v)) > tol || tw.scale.x != tw.scale.y)
                src_.fail(n.pos, "linear_extrude with twist of a circle (at " + src_.where(r.pos) +
                                     ") that is off the twist axis, not round or scaled "
                                     "unevenly: its wall is a helical sweep, which Lancer "
                                     "does not trace");
            // OpenSCAD twists the circle's polygon: its walls are chords of n fragments.
            const double radius = std::sqrt(glm::dot(u, u));
            const double frags = openscad::fragmentsFromR(
                radius, special(n, "$fn", 0.0), special(n, "$fa", 12.0), special(n, "$fs", 2.0));
            noteOpenScadTwistMesh(tw, radius, 2.0 * radius * std::sin(M_PI / std::max(frags, 3.0)));
            return extrudeRegion(id, n, tw.xf, tw.mat, tw.h, (tw.scale - 1.0) / tw.h);
        }
        const std::vector<Vec2>& base = r.piece.vertices;
        double longest = r.outlineEdge;
        for (size_t i = 0; i < base.size(); ++i)
            longest = std::max(longest, glm::length(base[(i + 1) % base.size()] - base[i]));
        noteOpenScadTwistMesh(tw, std::sqrt(regionMaxR2(id)), longest);
        if (2 * base.size() + 2 > 255)
            src_.fail(n.pos, "linear_extrude with twist of a convex piece of " +
                                 std::to_string(base.size()) + " corners (of the 2D node at " +
                                 src_.where(r.pos) +
                                 "): a slice would need more than the 255 planes of a polytope");
        // The piece about its centre c: every corner within w of it, and rho from the axis
        // (docs/scenes.md, "Twisted extrusions", for the bound below).
        const auto [c, w] = pieceReach(base);
        double rho = 0.0;
        for (const Vec2& p : base) rho = std::max(rho, glm::length(p));
        const int parts = tw.slices * tw.sub;
        const double dA = std::abs(tw.twist) / parts;
        Built all = Built::empty();
        for (int j = 0; j < parts; ++j) {
            const double t0 = double(j) / parts, t1 = double(j + 1) / parts;
            const Built s = twistSlice(base, twistSection(tw, t0), twistSection(tw, t1), tw.h * t0,
                                       tw.h * t1, tw, r.pos);
            if (s.kind != Built::Kind::Node) continue;
            all = all.kind == Built::Kind::Node
                      ? Built::of(scene_.tree.combine(Op::Union, all.node, s.node))
                      : s;
            // How far the slice (the hull of its end sections) is from the exact twisted
            // piece, at any height, both ways: s ((|c| + w) dA^2 / 8 + w dA / 2) for the turn,
            // plus rho |dS| dA / 4 for a uniform change of scale dS over the slice, or
            // rho (s dA + |dS|) / 2 when the scale is not uniform; then stretched by xf.
            const Vec2 s0 = Vec2(1.0) - (Vec2(1.0) - tw.scale) * t0;
            const Vec2 s1 = Vec2(1.0) - (Vec2(1.0) - tw.scale) * t1;
            const double smax = std::max({s0.x, s0.y, s1.x, s1.y});
            const double dS = std::max(std::abs(s1.x - s0.x), std::abs(s1.y - s0.y));
            const double e = tw.scale.x == tw.scale.y
                                 ? smax * ((glm::length(c) + w) * dA * dA / 8.0 + w * dA / 2.0) +
                                       rho * dS * dA / 4.0
                                 : rho * (smax * dA + dS) / 2.0;
            counts_.twistError = std::max(counts_.twistError, tw.norm * e);
        }
        return all.kind == Built::Kind::Node ? all : emptyPrimitive();
    }

    /// One slice of a convex piece: the convex hull of the piece under `a0` at height z0 and
    /// under `a1` at z1. Its side faces are, per edge of either end, the plane through the edge
    /// and the other end's corner farthest out along the edge's normal.
    Built twistSlice(const std::vector<Vec2>& base, const glm::dmat2& a0, const glm::dmat2& a1,
                     double z0, double z1, const TwistedExtrusion& tw, size_t pos) {
        const size_t m = base.size();
        std::vector<Vec3> p0(m), p1(m);
        for (size_t i = 0; i < m; ++i) {
            p0[i] = Vec3(a0 * base[i], z0);
            p1[i] = Vec3(a1 * base[i], z1);
        }
        // The piece's winding gives each edge its outward side. Neither end's centre does: a
        // sliver piece (example009's fan cut into trapezoids) has its centre within rounding of
        // its long edges, and a side taken the wrong way left the hull without that face,
        // reaching far outside its corners' box (the schemes, which clip by it, then missed
        // what brute force hit).
        double area2 = 0.0;
        for (size_t i = 0; i < m; ++i) {
            const Vec2 &u = base[i], &v = base[(i + 1) % m];
            area2 += u.x * v.y - u.y * v.x;
        }
        if (!(area2 != 0.0)) return Built::empty();    // no area, no volume
        const double turn = area2 > 0.0 ? 1.0 : -1.0;  // counter-clockwise: outward is right
        Polytope pt;
        auto sides = [&](const std::vector<Vec3>& ring, const std::vector<Vec3>& other) {
            for (size_t i = 0; i < m; ++i) {
                const Vec3 &p = ring[i], &q = ring[(i + 1) % m];
                const Vec2 e(q.x - p.x, q.y - p.y);
                if (e == Vec2(0.0)) continue;  // a zero scale collapses the end
                // The edge's outward normal in the end's plane (the ends keep the piece's
                // winding: a turn and a positive scale), then the other end's farthest corner
                // that way: the hull's face through the edge passes through it.
                const Vec2 out = turn * Vec2(e.y, -e.x);
                size_t best = 0;
                for (size_t k = 1; k < m; ++k)
                    if (glm::dot(out, Vec2(other[k])) > glm::dot(out, Vec2(other[best]))) best = k;
                Vec3 nn = glm::cross(q - p, other[best] - p);
                // The face's normal is square to the edge, so its horizontal part lies along
                // `out` (never zero: the corner is at the other end's height).
                if (glm::dot(Vec2(nn), out) < 0.0) nn = -nn;
                const double len = glm::length(nn);
                if (!(len > 0.0)) continue;
                nn /= len;
                pt.planes.push_back(glm::dvec4(nn, glm::dot(nn, p)));
            }
        };
        sides(p0, p1);
        sides(p1, p0);
        if (pt.planes.empty()) return Built::empty();  // both ends collapsed
        pt.planes.push_back({0.0, 0.0, -1.0, -z0});
        pt.planes.push_back({0.0, 0.0, 1.0, z1});
        for (size_t i = 0; i < m; ++i) {
            pt.bounds.expand(p0[i]);
            pt.bounds.expand(p1[i]);
        }
        Vec3 pad = 1e-9 * (glm::abs(pt.bounds.lo) + glm::abs(pt.bounds.hi)) + Vec3(1e-300);
        pt.bounds.lo -= pad;
        pt.bounds.hi += pad;
        ++counts_.polytopes;
        return place(std::move(pt), tw.xf, tw.mat, pos, "linear_extrude()");
    }

    /// The 3D boolean of a 2D boolean region.
    static Op csgOp(Region::Kind k) {
        return k == Region::Kind::Union          ? Op::Union
               : k == Region::Kind::Intersection ? Op::Intersection
                                                 : Op::Difference;
    }

    /// The region's node extruded: 2D booleans become 3D booleans of the extruded leaves (the
    /// extrusion maps each height's section one to one, so it commutes with them). `k`: the
    /// section at height z is the base scaled by 1 + k z about the origin.
    Built extrudeRegion(int id, const Node& n, const Transform& xf, int mat, double h,
                        const Vec2& k) {
        const Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Union || r.kind == Region::Kind::Intersection ||
            r.kind == Region::Kind::Difference) {
            Built a = extrudeRegion(r.a, n, xf, mat, h, k);
            Built b = extrudeRegion(r.b, n, xf, mat, h, k);
            return Built::of(scene_.tree.combine(csgOp(r.kind), a.node, b.node));
        }
        if (r.kind == Region::Kind::Disk) {
            if (k.x != k.y)
                src_.fail(n.pos, "linear_extrude with a non-uniform scale of a circle (at " +
                                     src_.where(r.pos) +
                                     ") makes a wall that is not a quadric, which Lancer does "
                                     "not trace");
            // The cone of radius 1 to 1 + k h, sheared so that its axis follows the centre's
            // path c (1 + k z), then mapped by the disk's linear part.
            const glm::dmat3& d = r.disk;
            Mat4 m(1.0);
            m[0] = {d[0][0], d[0][1], 0.0, 0.0};
            m[1] = {d[1][0], d[1][1], 0.0, 0.0};
            m[2] = {k.x * d[2][0], k.x * d[2][1], 1.0, 0.0};
            m[3] = {d[2][0], d[2][1], 0.0, 1.0};
            ++(k.x == 0.0 ? counts_.cylinders : counts_.cones);
            return place(Cone{1.0, 1.0 + k.x * h, h, false}, xf * Transform(m), mat, r.pos,
                         "linear_extrude()");
        }
        Polytope pt;
        for (const HalfPlane& s : r.piece.sides) {
            // a x / (1 + kx z) + b y / (1 + ky z) <= c is a plane when kx = ky or a or b is 0.
            double kz;
            if (s.b == 0.0)
                kz = k.x;
            else if (s.a == 0.0 || k.x == k.y)
                kz = k.y;
            else
                src_.fail(n.pos,
                          "linear_extrude with a non-uniform scale of a slanted edge "
                          "(of the 2D node at " +
                              src_.where(r.pos) +
                              ") makes a wall that is not a plane, which Lancer does not "
                              "trace");
            Vec3 nn(s.a, s.b, -s.c * kz);
            double len = glm::length(nn);
            if (!(len > 0.0)) continue;
            pt.planes.push_back(glm::dvec4(nn / len, s.c / len));
        }
        pt.planes.push_back({0.0, 0.0, -1.0, 0.0});
        pt.planes.push_back({0.0, 0.0, 1.0, h});
        for (const Vec2& v : r.piece.vertices) {
            pt.bounds.expand(Vec3(v, 0.0));
            pt.bounds.expand(Vec3(v.x * (1.0 + k.x * h), v.y * (1.0 + k.y * h), h));
        }
        // The corners are computed, the planes are exact: a margin keeps the solid inside.
        Vec3 pad = 1e-9 * (glm::abs(pt.bounds.lo) + glm::abs(pt.bounds.hi)) + Vec3(1e-300);
        pt.bounds.lo -= pad;
        pt.bounds.hi += pad;
        ++counts_.polytopes;
        return place(std::move(pt), xf, mat, r.pos, "linear_extrude()");
    }

    // ---- rotate_extrude ----

    /// The box of a region (union: hull, intersection: overlap, difference: the first's).
    Box3 regionBox(int id) const {
        const Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Piece) {
            Box3 b;
            for (const Vec2& v : r.piece.vertices) b.expand(Vec3(v, 0.0));
            return b;
        }
        if (r.kind == Region::Kind::Disk) {
            double ex = std::hypot(r.disk[0][0], r.disk[1][0]);
            double ey = std::hypot(r.disk[0][1], r.disk[1][1]);
            Vec3 c(r.disk[2][0], r.disk[2][1], 0.0);
            return {c - Vec3(ex, ey, 0.0), c + Vec3(ex, ey, 0.0)};
        }
        Box3 a = regionBox(r.a), b = regionBox(r.b);
        if (r.kind == Region::Kind::Union) {
            a.expand(b);
            return a;
        }
        if (r.kind == Region::Kind::Intersection)
            return {glm::max(a.lo, b.lo), glm::min(a.hi, b.hi)};
        return a;
    }

    void mirrorRegion(int id) {
        Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Piece) {
            for (HalfPlane& s : r.piece.sides) s.a = -s.a;
            for (Vec2& v : r.piece.vertices) v.x = -v.x;
            std::reverse(r.piece.vertices.begin(), r.piece.vertices.end());
        } else if (r.kind == Region::Kind::Disk) {
            for (int c = 0; c < 3; ++c) r.disk[c][0] = -r.disk[c][0];
        } else {
            mirrorRegion(r.a);
            mirrorRegion(r.b);
        }
    }

    Built rotateExtrude(const Node& n, const Transform& xf, int mat) {
        Args a(src_, n, {}, {"angle", "convexity", "file", "layer", "origin", "scale"});
        if (a.get("file"))
            src_.fail(
                a.get("file")->pos,
                "rotate_extrude(file = ...) imports a DXF drawing, which Lancer does not read");
        double angle = std::clamp(a.number("angle").value_or(360.0), -360.0, 360.0);
        Built r = regionUnion(n.children, glm::dmat3(1.0), n);
        noteProfileFacets(xf, 1.0);
        if (r.kind != Built::Kind::Node) return r;
        if (angle == 0.0) return emptyPrimitive();
        Box3 box = regionBox(r.node);
        if (box.lo.x < 0.0 && box.hi.x > 0.0)
            src_.fail(n.pos, "rotate_extrude(): the profile crosses the axis (x from " +
                                 std::to_string(box.lo.x) + " to " + std::to_string(box.hi.x) +
                                 "); as in OpenSCAD, all of it must lie on one side of x = 0");
        if (box.hi.x <= 0.0) {
            mirrorRegion(r.node);
            box = regionBox(r.node);
        }
        if (!(box.hi.x > 0.0) || !(box.hi.y > box.lo.y)) return emptyPrimitive();
        ++counts_.rotateExtrudes;
        Built solid = revolveRegion(r.node, n, xf, mat);
        if (std::abs(angle) == 360.0) return solid;
        // A partial sweep from the +x axis: the solid cut by a wedge (a polytope bounded by a box
        // larger than the solid, so that no face of the wedge's box touches it).
        double sweep = std::abs(angle), start = angle > 0.0 ? 0.0 : angle;
        bool keep = sweep <= 180.0;
        if (!keep) {
            start = angle > 0.0 ? angle : 0.0;
            sweep = 360.0 - sweep;
        }
        double R = 1.1 * box.hi.x + 1e-9, z0 = box.lo.y, z1 = box.hi.y;
        double dz = 0.1 * (z1 - z0) + 1e-9;
        double s0 = glm::radians(start), s1 = glm::radians(start + sweep);
        Polytope w;
        w.planes = {{std::sin(s0), -std::cos(s0), 0.0, 0.0},
                    {-std::sin(s1), std::cos(s1), 0.0, 0.0},
                    {-1, 0, 0, R},
                    {1, 0, 0, R},
                    {0, -1, 0, R},
                    {0, 1, 0, R},
                    {0, 0, -1, -(z0 - dz)},
                    {0, 0, 1, z1 + dz}};
        w.bounds = {Vec3(-R, -R, z0 - dz), Vec3(R, R, z1 + dz)};
        ++counts_.polytopes;
        Built wedge = place(std::move(w), xf, mat, n.pos, "rotate_extrude()");
        return Built::of(
            scene_.tree.combine(keep ? Op::Intersection : Op::Difference, solid.node, wedge.node));
    }

    /// The region revolved about the profile's y axis (which becomes z): booleans commute with
    /// the revolution as with an extrusion.
    Built revolveRegion(int id, const Node& n, const Transform& xf, int mat) {
        const Region& r = regions_[size_t(id)];
        if (r.kind == Region::Kind::Union || r.kind == Region::Kind::Intersection ||
            r.kind == Region::Kind::Difference) {
            Built a = revolveRegion(r.a, n, xf, mat);
            Built b = revolveRegion(r.b, n, xf, mat);
            if (r.kind == Region::Kind::Union) {
                if (a.kind != Built::Kind::Node) return b;
                if (b.kind != Built::Kind::Node) return a;
                return Built::of(scene_.tree.combine(Op::Union, a.node, b.node));
            }
            if (a.kind != Built::Kind::Node) return Built::empty();
            if (b.kind != Built::Kind::Node)
                return r.kind == Region::Kind::Difference ? a : Built::empty();
            return Built::of(scene_.tree.combine(
                r.kind == Region::Kind::Intersection ? Op::Intersection : Op::Difference, a.node,
                b.node));
        }
        if (r.kind == Region::Kind::Disk) return revolveDisk(r, n, xf, mat);
        return revolvePiece(r.piece, xf, mat, r.pos);
    }

    /// A disk revolved about the profile's y axis: a circle or an ellipse with its axes along x
    /// and y centred on the axis makes a sphere or an ellipsoid; a circle off the axis a torus.
    /// Only the part at x >= 0 revolves (the whole region lies there, but a subtracted disk may
    /// cross the axis: its sweep is a spindle torus's outer solid, not a torus's, and is refused).
    Built revolveDisk(const Region& r, const Node& n, const Transform& xf, int mat) {
        const glm::dmat3& d = r.disk;
        const double ex = std::hypot(d[0][0], d[0][1]), ey = std::hypot(d[1][0], d[1][1]);
        const double cx = d[2][0], cy = d[2][1];
        // A circle: the unit disk's axes stay orthogonal and of one length (to rounding, after
        // rotations in the plane).
        const double tol = 1e-12 * std::max(ex, ey);
        const bool circle =
            std::abs(ex - ey) <= tol && std::abs(d[0][0] * d[1][0] + d[0][1] * d[1][1]) <= tol * ex;
        const bool aligned = d[1][0] == 0.0 && d[0][1] == 0.0;
        if (std::abs(cx) <= tol && (circle || aligned)) {
            const double rx = circle ? ex : std::abs(d[0][0]), ry = circle ? ex : std::abs(d[1][1]);
            ++counts_.spheres;
            return place(Sphere{Vec3(0.0), 1.0},
                         xf * Transform::translate({0.0, 0.0, cy}) * Transform::scale({rx, rx, ry}),
                         mat, r.pos, "rotate_extrude()");
        }
        if (!circle)
            src_.fail(n.pos, "rotate_extrude() of the ellipse at " + src_.where(r.pos) +
                                 " off the axis sweeps a ring of elliptic section, which Lancer "
                                 "does not model (circles off the axis make tori)");
        const double R = std::abs(cx), rad = 0.5 * (ex + ey);
        if (cx <= -rad) return Built::empty();  // wholly at x < 0: nothing revolves
        if (cx < 0.0 || R < rad * (1.0 - 1e-12))
            src_.fail(n.pos, "rotate_extrude() of the circle at " + src_.where(r.pos) +
                                 " (centre x = " + std::to_string(cx) + ", radius " +
                                 std::to_string(rad) +
                                 ") crosses the axis; as in OpenSCAD, all of it must lie on one "
                                 "side of x = 0");
        ++counts_.tori;
        return place(Torus{std::max(R, rad), rad}, xf * Transform::translate({0.0, 0.0, cy}), mat,
                     r.pos, "rotate_extrude()");
    }

    /// A convex piece a x + b y <= c (x the radius, y the height) revolved: each side with a > 0
    /// keeps the inside of a cone (radius (c - b z) / a), each with a < 0 the outside of one,
    /// each with a = 0 a height already bounded by the piece's extent.
    Built revolvePiece(const ConvexPiece& pc, const Transform& xf, int mat, size_t pos) {
        // The part at x >= 0 gives the height range (a piece of a subtracted region may cross
        // the axis; its sides need no clipping, the radius is never negative).
        std::vector<Vec2> v;
        const std::vector<Vec2>& in = pc.vertices;
        for (size_t i = 0; i < in.size(); ++i) {
            const Vec2 &p = in[i], &q = in[(i + 1) % in.size()];
            if (p.x >= 0.0) v.push_back(p);
            if ((p.x < 0.0) != (q.x < 0.0))
                v.push_back({0.0, p.y + (q.y - p.y) * (-p.x / (q.x - p.x))});
        }
        if (v.size() < 3) return Built::empty();
        double z0 = kInf, z1 = -kInf;
        for (const Vec2& p : v) z0 = std::min(z0, p.y), z1 = std::max(z1, p.y);
        if (!(z1 > z0)) return Built::empty();
        double margin = 0.05 * (z1 - z0);
        std::vector<int> inside, outside;
        for (const HalfPlane& s : pc.sides) {
            if (s.a == 0.0) continue;
            // The radius f(z) = (c - b z) / a over the height range (widened for a subtracted
            // cone, so that its caps stay clear of the piece's own).
            double lo = s.a > 0.0 ? z0 : z0 - margin, hi = s.a > 0.0 ? z1 : z1 + margin;
            auto f = [&](double z) { return (s.c - s.b * z) / s.a; };
            double fl = f(lo), fh = f(hi);
            if (fl <= 0.0 && fh <= 0.0) {
                if (s.a > 0.0) return Built::empty();
                continue;  // r >= a non-positive radius holds everywhere
            }
            double zr = s.c / s.b;  // where the radius is zero (b != 0 when f changes sign)
            if (fl < 0.0) lo = zr, fl = 0.0;
            if (fh < 0.0) hi = zr, fh = 0.0;
            if (!(hi > lo)) {
                if (s.a > 0.0) return Built::empty();
                continue;
            }
            ++(fl == fh ? counts_.cylinders : counts_.cones);
            Built c =
                place(Cone{fl, fh, hi - lo, false}, shiftedZ(xf, lo), mat, pos, "rotate_extrude()");
            (s.a > 0.0 ? inside : outside).push_back(c.node);
        }
        if (inside.empty()) return Built::empty();
        int solid = scene_.tree.balanced(Op::Intersection, inside);
        if (!outside.empty())
            solid = scene_.tree.combine(Op::Difference, solid,
                                        scene_.tree.balanced(Op::Union, outside));
        return Built::of(solid);
    }

    // ---- polyhedron and hull ----

    /// polyhedron()'s points (in the node's frame) and faces (index lists), checked.
    void polyhedronMesh(const Node& n, std::vector<Vec3>& pts, std::vector<std::vector<int>>& faces,
                        size_t& facesPos) {
        Args a(src_, n, {"points", "faces", "convexity"}, {"triangles"});
        if (!n.children.empty())
            src_.fail(n.children.front().pos, "polyhedron() takes no children");
        const Value* p = a.get("points");
        const Value* f = a.get("faces") ? a.get("faces") : a.get("triangles");
        if (!p || p->kind != Value::Kind::Vector)
            src_.fail(p ? p->pos : n.pos,
                      "expected a list of [x, y, z] points for 'points' of "
                      "polyhedron()");
        if (!f || f->kind != Value::Kind::Vector)
            src_.fail(f ? f->pos : n.pos,
                      "expected a list of index lists for 'faces' of "
                      "polyhedron()");
        if (p->items.size() > 100000 || f->items.size() > 100000)
            src_.fail(n.pos, "polyhedron() has more than 100000 points or faces");
        for (const Value& v : p->items) pts.push_back(a.vec3(v, "a polyhedron point"));
        facesPos = f->pos;
        for (const Value& face : f->items) {
            if (face.kind != Value::Kind::Vector)
                src_.fail(face.pos, "expected a list of point indices for a polyhedron face");
            std::vector<int> q;
            for (const Value& iv : face.items) {
                double i = a.number(iv, "a point index");
                if (i < 0 || i >= double(pts.size()) || i != std::floor(i))
                    src_.fail(iv.pos, "a polyhedron face index must be a whole number from 0 to " +
                                          std::to_string(pts.size() - 1));
                if (q.empty() || q.back() != int(i)) q.push_back(int(i));
            }
            while (q.size() > 1 && q.front() == q.back()) q.pop_back();
            if (q.size() < 3)
                src_.fail(face.pos, "a polyhedron face needs at least three distinct points");
            faces.push_back(std::move(q));
        }
    }

    /// polyhedron() as the convex polytope of its face planes when it is convex and its faces
    /// flat; otherwise as a closed mesh (meshNode: its faces cut into triangles, the solid cut
    /// into convex pieces). An open mesh (an edge not shared by exactly two faces) is refused.
    Built polyhedron(const Node& n, const Transform& xf, int mat) {
        std::vector<Vec3> pts;
        std::vector<std::vector<int>> faces;
        size_t facesPos = n.pos;
        polyhedronMesh(n, pts, faces, facesPos);
        if (faces.empty()) return emptyPrimitive();
        std::map<std::pair<int, int>, int> uses;
        for (const auto& f : faces)
            for (size_t e = 0; e < f.size(); ++e) ++uses[std::minmax(f[e], f[(e + 1) % f.size()])];
        for (const auto& [e, c] : uses)
            if (c != 2)
                src_.fail(facesPos, "polyhedron() is not a closed mesh: the edge from point " +
                                        std::to_string(e.first) + " to point " +
                                        std::to_string(e.second) + " belongs to " +
                                        std::to_string(c) + " face" + (c == 1 ? "" : "s") +
                                        " (two in a closed mesh); open meshes are not supported");
        Vec3 centre(0.0);
        Box3 box;
        double mag = 0.0;
        for (const Vec3& p : pts) {
            centre += p;
            box.expand(p);
            mag = std::max({mag, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        }
        centre /= double(pts.size());
        const double tol = 1e-9 * std::max(mag, 1e-300);
        Polytope pt;
        for (size_t fi = 0; fi < faces.size(); ++fi) {
            const auto& f = faces[fi];
            Vec3 nn(0.0), c(0.0);
            for (size_t i = 0; i < f.size(); ++i) {
                const Vec3 &a = pts[size_t(f[i])], &b = pts[size_t(f[(i + 1) % f.size()])];
                nn += Vec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x),
                           (a.x - b.x) * (a.y + b.y));
                c += a;
            }
            const double len = glm::length(nn);
            if (!(len > 0.0)) continue;  // a face of no area bounds nothing
            nn /= len;
            double w = glm::dot(nn, c / double(f.size()));
            if (glm::dot(nn, centre) > w) nn = -nn, w = -w;
            bool convex = true;
            for (int i : f) convex = convex && std::abs(glm::dot(nn, pts[size_t(i)]) - w) <= tol;
            for (size_t i = 0; i < pts.size(); ++i)
                convex = convex && glm::dot(nn, pts[i]) - w <= tol;
            if (!convex) return polyhedronMeshNode(pts, faces, xf, mat, n.pos);
            bool known = false;
            for (const glm::dvec4& q : pt.planes)
                known = known || (glm::dot(Vec3(q), nn) > 1.0 - 1e-12 && std::abs(q.w - w) <= tol);
            if (!known) pt.planes.push_back(glm::dvec4(nn, w));
        }
        if (pt.planes.size() < 4) return emptyPrimitive();
        if (pt.planes.size() > 255)
            src_.fail(n.pos,
                      "polyhedron() has more than 255 distinct face planes, which Lancer's "
                      "polytope does not hold");
        pt.bounds = padded(box);
        ++counts_.polyhedra;
        return place(std::move(pt), xf, mat, n.pos, "polyhedron()");
    }

    /// A polyhedron that is not convex (or has a face that is not flat) as a closed mesh.
    Built polyhedronMeshNode(const std::vector<Vec3>& pts,
                             const std::vector<std::vector<int>>& faces, const Transform& xf,
                             int mat, size_t pos) {
        TriangleMesh m;
        m.points = pts;
        std::vector<uint32_t> loop;
        for (const auto& f : faces) {
            loop.assign(f.begin(), f.end());
            m.addPolygon(loop);
        }
        return meshNode(std::move(m), xf, mat, pos, "polyhedron() (its faces cut into triangles)");
    }

    /// A computed box grown by a hair, so that a solid bounded by exact planes stays inside.
    static Box3 padded(Box3 b) {
        Vec3 pad = 1e-9 * (glm::abs(b.lo) + glm::abs(b.hi)) + Vec3(1e-300);
        b.lo -= pad;
        b.hi += pad;
        return b;
    }

    /// What hull() wraps: corner points (cubes, polyhedra) and balls (spheres), in the hull's
    /// frame.
    struct HullInput {
        std::vector<Vec3> points;
        std::vector<Vec3> centres;
        std::vector<double> radii;
        std::vector<size_t> ballPos;
        bool ellipsoid = false;  ///< a sphere under a transform that is not a similarity
        /// OpenSCAD's facets of the curved children (spheres, cylinders, cones), and how far the
        /// farthest strays inside its exact surface (in the hull's frame).
        std::vector<Vec3> facetPoints;
        double facetError = 0.0;
        int curved = 0;  ///< cylinders and cones
    };

    [[noreturn]] void refuseInHull(const Node& n, const Node& hull) {
        src_.fail(n.pos, "'" + n.name + "' inside hull() at " + src_.where(hull.pos) +
                             " is not supported: Lancer takes the hull of cubes, polyhedra, "
                             "spheres and cylinders (and their groups and transforms)");
    }

    void gatherHull(const Node& n, const Transform& t, const Node& hull, HullInput& in) {
        if (n.disable || n.background) {
            ++counts_.leftOut;
            return;
        }
        const std::string& k = n.name;
        if (k == "group" || k == "union" || k == "render" || k == "color") {
            if (k == "render")
                Args(src_, n, {"convexity"}, {});
            else if (k == "color")
                color(n, 0);  // checked; the hull takes the colour of its own context
            else
                Args(src_, n, {}, {});
            for (const Node& c : n.children) gatherHull(c, t, hull, in);
            return;
        }
        if (k == "multmatrix" || k == "translate" || k == "rotate" || k == "scale" ||
            k == "mirror") {
            ++counts_.transforms;
            Transform u = t * transform(n);
            for (const Node& c : n.children) gatherHull(c, u, hull, in);
            return;
        }
        if (k == "polyhedron") {
            std::vector<Vec3> pts;
            std::vector<std::vector<int>> faces;
            size_t fp = 0;
            polyhedronMesh(n, pts, faces, fp);
            for (const Vec3& p : pts) in.points.push_back(t.point(p));
            return;
        }
        if (k == "cube" || k == "sphere" || k == "cylinder") {
            if (!n.children.empty()) src_.fail(n.children.front().pos, k + "() takes no children");
            Transform local;
            std::optional<Shape> s = primitiveShape(n, local);
            if (!s) return;
            const Transform tl = t * local;
            if (!std::holds_alternative<Block>(*s)) {
                // OpenSCAD's facets of it, should the hull not be the exact one of equal balls.
                const FragmentRule rule = fragmentRule(n);
                std::vector<Vec3> f;
                double err = 0.0;
                const Sphere* round = std::get_if<Sphere>(&*s);
                const Cone* cone = std::get_if<Cone>(&*s);
                const int kf = rule.fragments(round ? round->r : std::max(cone->r1, cone->r2));
                // Refused before the points are made: a sphere of n fragments has n (n + 1) / 2.
                const double more = round ? double(kf) * double((kf + 1) / 2) : 2.0 * kf;
                if (double(in.facetPoints.size() + in.points.size()) + more >
                    double(kMaxHullPoints))
                    src_.fail(n.pos, "hull() at " + src_.where(hull.pos) + " of more than " +
                                         std::to_string(kMaxHullPoints) +
                                         " points (its curved children's facets) is not "
                                         "supported");
                if (const Sphere* sp = round) {
                    const int k2 = kf;
                    f = spherePoints(sp->r, k2);
                    err = sphereFacetError(sp->r, k2);
                } else {
                    const Cone& c = *cone;
                    const int k2 = kf;
                    f = cylinderPoints(c.r1, c.r2, c.h, k2);
                    err = sagitta(std::max(c.r1, c.r2), k2);
                    ++in.curved;
                }
                for (const Vec3& p : f) in.facetPoints.push_back(tl.point(p));
                in.facetError = std::max(in.facetError, err * stretch(tl));
                if (std::holds_alternative<Cone>(*s)) return;
            }
            if (const Block* b = std::get_if<Block>(&*s)) {
                for (int c = 0; c < 8; ++c)
                    in.points.push_back(
                        tl.point({c & 1 ? b->hi.x : b->lo.x, c & 2 ? b->hi.y : b->lo.y,
                                  c & 4 ? b->hi.z : b->lo.z}));
                return;
            }
            const Sphere& sp = std::get<Sphere>(*s);
            // A ball stays a ball only under a similarity: orthogonal axes of one length.
            const Vec3 c0 = tl.vector({1, 0, 0}), c1 = tl.vector({0, 1, 0}),
                       c2 = tl.vector({0, 0, 1});
            const double l = glm::length(c0), e = 1e-12 * l * l;
            if (std::abs(glm::dot(c0, c1)) > e || std::abs(glm::dot(c0, c2)) > e ||
                std::abs(glm::dot(c1, c2)) > e || std::abs(glm::dot(c1, c1) - l * l) > e ||
                std::abs(glm::dot(c2, c2) - l * l) > e)
                in.ellipsoid = true;
            in.centres.push_back(tl.point(sp.c));
            in.radii.push_back(sp.r * l);
            in.ballPos.push_back(n.pos);
            return;
        }
        refuseInHull(n, hull);
    }

    /// hull(): of corner points, the convex polytope of their hull; of balls of one radius r,
    /// the hull of their centres grown by r, exactly the union of that hull, a slab over each
    /// face, a cylinder along each edge and a ball at each vertex. Of anything else curved
    /// (spheres of different radii, ellipsoids, cylinders, cones, round children beside
    /// corners; and every round child with --facets openscad), the polytope of the corners and
    /// OpenSCAD's facets of the curved children at their $fn, $fa, $fs, as OpenSCAD takes it;
    /// its error is the facets' (OpenScadCounts::facetError).
    Built hullNode(const Node& n, const Transform& xf, int mat) {
        Args(src_, n, {}, {});
        ++counts_.operators;
        HullInput in;
        for (const Node& c : n.children) gatherHull(c, Transform(), n, in);
        bool exactBalls =
            !in.centres.empty() && in.points.empty() && !in.curved && !in.ellipsoid && !facets_;
        for (size_t i = 1; exactBalls && i < in.radii.size(); ++i)
            exactBalls = std::abs(in.radii[i] - in.radii[0]) <= 1e-12 * in.radii[0];
        if (!exactBalls && !in.facetPoints.empty()) {
            in.points.insert(in.points.end(), in.facetPoints.begin(), in.facetPoints.end());
            in.centres.clear();
            counts_.facetError = std::max(counts_.facetError, in.facetError * stretch(xf));
            counts_.facetedShapes += 1;
        }
        const bool balls = !in.centres.empty();
        std::vector<Vec3>& pts = balls ? in.centres : in.points;
        if (pts.empty()) return Built::empty();
        const double r = balls ? in.radii[0] : 0.0;
        {
            std::sort(pts.begin(), pts.end(), [](const Vec3& a, const Vec3& b) {
                return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
            });
            pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
        }
        if (pts.size() > kMaxHullPoints)
            src_.fail(n.pos, "hull() of more than " + std::to_string(kMaxHullPoints) +
                                 " points is not supported");
        ConvexHull3 h = convexHull3(pts);
        ++counts_.hulls;
        std::vector<int> items;
        auto polytope = [&](std::vector<glm::dvec4> planes, const std::vector<Vec3>& corners) {
            Polytope pt;
            pt.planes = std::move(planes);
            Box3 b;
            for (const Vec3& p : corners) b.expand(p);
            pt.bounds = padded(b);
            ++counts_.polytopes;
            items.push_back(place(std::move(pt), xf, mat, n.pos, "hull()").node);
        };
        if (h.dim == 3 && h.planes.size() > 255 && !balls) return wedgedHull(h, xf, mat, n.pos);
        if (h.dim == 3 && h.planes.size() > 255)
            src_.fail(n.pos,
                      "hull() has more than 255 faces, which Lancer's polytope does not "
                      "hold");
        if (h.dim == 3) polytope(h.planes, h.vertices);
        if (!balls) {
            if (items.empty()) return emptyPrimitive();  // a flat hull has no volume
            return Built::of(items[0]);
        }
        // Slabs over the faces (both sides of a flat hull's one face).
        for (size_t f = 0; f < h.faces.size(); ++f) {
            const Vec3 nn(h.planes[f]);
            const double w = h.planes[f].w;
            std::vector<glm::dvec4> planes = {
                glm::dvec4(nn, w + r), h.dim == 2 ? glm::dvec4(-nn, r - w) : glm::dvec4(-nn, -w)};
            std::vector<Vec3> corners;
            const auto& face = h.faces[f];
            for (size_t e = 0; e < face.size(); ++e) {
                const Vec3 &a = h.vertices[size_t(face[e])],
                           &b = h.vertices[size_t(face[(e + 1) % face.size()])];
                const Vec3 m = glm::normalize(glm::cross(b - a, nn));
                planes.push_back(glm::dvec4(m, glm::dot(m, a)));
                corners.push_back(a + r * nn);
                corners.push_back(a - (h.dim == 2 ? r : 0.0) * nn);
            }
            polytope(std::move(planes), corners);
        }
        for (const auto& [i, j] : h.edges) {
            const Vec3 &a = h.vertices[size_t(i)], &b = h.vertices[size_t(j)];
            ++counts_.cylinders;
            items.push_back(place(Cone{r, r, glm::length(b - a), false},
                                  xf * Transform::alongAxis(a, glm::normalize(b - a)), mat, n.pos,
                                  "hull()")
                                .node);
        }
        for (const Vec3& v : h.vertices) {
            ++counts_.spheres;
            items.push_back(place(Sphere{v, r}, xf, mat, n.pos, "hull()").node);
        }
        return Built::of(scene_.tree.balanced(Op::Union, items));
    }

    /// A convex hull of more faces than a polytope holds (a hull of facets), cut into wedges
    /// about the vertical line through its vertices' mean: each wedge the polytope of its two
    /// planes through the line and of the hull's faces that may meet it (a face with a vertex
    /// on the inner side of each wedge plane; every face that meets the wedge has), which bound
    /// the hull within the wedge exactly. Neighbouring wedges share a plane negated to the bit.
    Built wedgedHull(const ConvexHull3& h, const Transform& xf, int mat, size_t pos) {
        Vec3 c(0.0);
        for (const Vec3& v : h.vertices) c += v;
        c /= double(h.vertices.size());
        // How far the line through c runs inside the hull (the wedges' common edge).
        double t0 = -kInf, t1 = kInf;
        for (const glm::dvec4& q : h.planes) {
            const double room = q.w - glm::dot(Vec3(q), c);
            if (q.z > 0.0) t1 = std::min(t1, room / q.z);
            if (q.z < 0.0) t0 = std::max(t0, room / q.z);
        }
        for (int wedges = std::max(3, int(h.planes.size() / 200) + 1);; wedges *= 2) {
            std::vector<Polytope> parts;
            // Each side's outward normal, the wedge s between sides s and s + 1 (the last side
            // the first one negated).
            std::vector<Vec3> side(static_cast<size_t>(wedges));
            for (int s = 0; s < wedges; ++s) {
                const double a = 2.0 * M_PI * s / wedges;
                side[size_t(s)] = Vec3(std::sin(a), -std::cos(a), 0.0);
            }
            auto inside = [&](const Vec3& p, const Vec3& nn) {
                return glm::dot(nn, p - c) <= 1e-9 * glm::length(p - c);
            };
            bool fits = true;
            for (int s = 0; s < wedges && fits; ++s) {
                const Vec3 n0 = side[size_t(s)], n1 = -side[size_t((s + 1) % wedges)];
                Polytope pt;
                for (size_t f = 0; f < h.faces.size(); ++f) {
                    bool in0 = false, in1 = false;
                    for (int v : h.faces[f]) {
                        in0 = in0 || inside(h.vertices[size_t(v)], n0);
                        in1 = in1 || inside(h.vertices[size_t(v)], n1);
                    }
                    if (in0 && in1) pt.planes.push_back(h.planes[f]);
                }
                pt.planes.push_back(glm::dvec4(n0, glm::dot(n0, c)));
                pt.planes.push_back(glm::dvec4(n1, glm::dot(n1, c)));
                if (pt.planes.size() > 255) {
                    fits = false;
                    break;
                }
                // Its corners: hull vertices inside it, hull edges crossing its sides, and the
                // ends of its edge on the line.
                Box3 box;
                box.expand(c + Vec3(0.0, 0.0, t0));
                box.expand(c + Vec3(0.0, 0.0, t1));
                for (const Vec3& v : h.vertices)
                    if (inside(v, n0) && inside(v, n1)) box.expand(v);
                for (const auto& [i, j] : h.edges) {
                    const Vec3 &u = h.vertices[size_t(i)], &v = h.vertices[size_t(j)];
                    for (int k = 0; k < 2; ++k) {
                        const Vec3& nk = k ? n1 : n0;
                        const double du = glm::dot(nk, u - c), dv = glm::dot(nk, v - c);
                        if ((du < 0.0) == (dv < 0.0)) continue;
                        const Vec3 p = u + (v - u) * (du / (du - dv));
                        if (inside(p, k ? n0 : n1)) box.expand(p);
                    }
                }
                pt.bounds = padded(box);
                parts.push_back(std::move(pt));
            }
            if (!fits) continue;
            std::vector<int> items;
            for (Polytope& pt : parts) {
                ++counts_.polytopes;
                items.push_back(place(std::move(pt), xf, mat, pos, "hull()").node);
            }
            return Built::of(scene_.tree.balanced(Op::Union, items));
        }
    }

    [[noreturn]] void refuse(const Node& n) {
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
        Transform local;
        std::optional<Shape> shape = primitiveShape(n, local);
        if (!shape) return emptyPrimitive();
        if (facets_ && !std::holds_alternative<Block>(*shape))
            return facetedPrimitive(n, *shape, xf * local, mat);
        Primitive p = makePrimitive(std::move(*shape), xf * local, mat);
        if (!p.worldBox.isBounded())
            src_.fail(n.pos, n.name + "() is too large: its bounds overflow a double");
        p.origin = src_.where(n.pos);
        scene_.prims.push_back(std::move(p));
        return Built::of(scene_.tree.leaf(uint32_t(scene_.prims.size() - 1)));
    }

    // ---- OpenSCAD's facets (--facets openscad) ----

    /// The node's $fn, $fa, $fs (OpenSCAD's defaults when absent), checked as OpenSCAD needs
    /// them to count fragments.
    FragmentRule fragmentRule(const Node& n) const {
        FragmentRule f{special(n, "$fn", 0.0), special(n, "$fa", 12.0), special(n, "$fs", 2.0)};
        if (!(f.fa > 0.0 && f.fs > 0.0))
            src_.fail(n.pos, n.name + "() needs $fa > 0 and $fs > 0 to count its facets");
        if (f.fn > double(kMaxFragments))
            src_.fail(n.pos, n.name + "() with $fn = " + twistText(f.fn) +
                                 ": Lancer makes at most " + std::to_string(kMaxFragments) +
                                 " facets of a circle");
        return f;
    }

    /// The most a 2D affine map stretches a length.
    static double planeStretch(const glm::dmat3& af) {
        Transform t;
        t.m = Mat4(1.0);
        t.m[0] = {af[0][0], af[0][1], 0.0, 0.0};
        t.m[1] = {af[1][0], af[1][1], 0.0, 0.0};
        return stretch(t);
    }

    /// Folds the faceted circles of a profile just read into the model's facet error, in model
    /// units: stretched by the extrusion's transform and its largest scale `grow`.
    void noteProfileFacets(const Transform& xf, double grow) {
        counts_.facetError = std::max(counts_.facetError, profileSagitta_ * stretch(xf) * grow);
        profileSagitta_ = 0.0;
    }

    /// One band of a faceted solid of revolution about z: the `n`-gon of radius r0 at z0 below
    /// the one of radius r1 at z1 (their corners at the same angles; a radius of 0 is an apex),
    /// as OpenSCAD's polyhedron has it: a convex polytope of its n side planes and two caps, cut
    /// into sectors by planes through the axis when that is over the 255 planes of a polytope.
    /// Returns the smallest distance of a side plane from the origin.
    double facetBand(double r0, double z0, double r1, double z1, int n, const Transform& xf,
                     int mat, size_t pos, const std::string& what, std::vector<int>& items) {
        const std::vector<Vec2> lo = circlePolygon(r0, n), hi = circlePolygon(r1, n);
        std::vector<glm::dvec4> sides(static_cast<size_t>(n));
        double nearest = kInf;
        for (int j = 0; j < n; ++j) {
            const int k = (j + 1) % n;
            const Vec3 p0(lo[size_t(j)], z0), p1(lo[size_t(k)], z0), q0(hi[size_t(j)], z1),
                q1(hi[size_t(k)], z1);
            // The plane through the wider ring's edge and the other ring's corner.
            Vec3 nn = r0 >= r1 ? glm::cross(p1 - p0, q0 - p0) : glm::cross(q1 - q0, p0 - q0);
            const Vec2 mid = lo[size_t(j)] + lo[size_t(k)] + hi[size_t(j)] + hi[size_t(k)];
            if (glm::dot(Vec2(nn), mid) < 0.0) nn = -nn;
            nn = glm::normalize(nn);
            sides[size_t(j)] = glm::dvec4(nn, glm::dot(nn, r0 >= r1 ? p0 : q0));
            nearest = std::min(nearest, sides[size_t(j)].w);
        }
        const int sectors = n + 2 <= 255 ? 1 : std::max(3, (n + 249) / 250);
        for (int s = 0; s < sectors; ++s) {
            const int j0 = int(int64_t(s) * n / sectors), j1 = int(int64_t(s + 1) * n / sectors);
            Polytope pt;
            Box3 box;
            for (int j = j0; j < j1; ++j) pt.planes.push_back(sides[size_t(j)]);
            for (int j = j0; j <= j1; ++j) {
                box.expand(Vec3(lo[size_t(j % n)], z0));
                box.expand(Vec3(hi[size_t(j % n)], z1));
            }
            if (sectors > 1) {
                // Through the axis at the sector's first and last corner (shared planes are
                // negated exactly, so neighbouring sectors meet to the bit).
                const double a0 = 360.0 * j0 / n, a1 = 360.0 * (j1 % n) / n;
                pt.planes.push_back({sinDegrees(a0), -cosDegrees(a0), 0.0, 0.0});
                pt.planes.push_back({-sinDegrees(a1), cosDegrees(a1), 0.0, 0.0});
                box.expand(Vec3(0.0, 0.0, z0));
                box.expand(Vec3(0.0, 0.0, z1));
            }
            pt.planes.push_back({0.0, 0.0, -1.0, -z0});
            pt.planes.push_back({0.0, 0.0, 1.0, z1});
            pt.bounds = padded(box);
            ++counts_.polytopes;
            items.push_back(place(std::move(pt), xf, mat, pos, what).node);
        }
        return nearest;
    }

    /// sphere() or cylinder() as OpenSCAD's polyhedron of it (facetBand per band between two
    /// rings), its sagitta recorded in OpenScadCounts::facetError.
    Built facetedPrimitive(const Node& n, const Shape& shape, const Transform& xf, int mat) {
        const FragmentRule rule = fragmentRule(n);
        std::vector<int> items;
        double error = 0.0;
        const std::string what = n.name + "()";
        if (const Sphere* s = std::get_if<Sphere>(&shape)) {
            const int k = rule.fragments(s->r);
            if (double(k) * double((k + 1) / 2) > kMaxSphereFacets)
                src_.fail(n.pos, "sphere() of " + std::to_string(k) +
                                     " fragments: Lancer makes at most " +
                                     twistText(kMaxSphereFacets) + " facets of a sphere");
            const SphereRings rings = sphereRings(s->r, k);
            double nearest = rings.z.front();  // the caps
            for (size_t i = 0; i + 1 < rings.z.size(); ++i)
                nearest = std::min(nearest,
                                   facetBand(rings.radius[i + 1], rings.z[i + 1], rings.radius[i],
                                             rings.z[i], rings.n, xf, mat, n.pos, what, items));
            error = s->r - nearest;  // every corner lies on the sphere
        } else {
            const Cone& c = std::get<Cone>(shape);
            const int k = rule.fragments(std::max(c.r1, c.r2));
            facetBand(c.r1, 0.0, c.r2, c.h, k, xf, mat, n.pos, what, items);
            error = sagitta(std::max(c.r1, c.r2), k);
        }
        ++counts_.facetedShapes;
        counts_.facetError = std::max(counts_.facetError, error * stretch(xf));
        return Built::of(scene_.tree.balanced(Op::Union, items));
    }

    /// cube(), sphere() or cylinder() as a shape placed by `local` in the node's frame; nothing
    /// when OpenSCAD makes nothing of it (a zero size).
    std::optional<Shape> primitiveShape(const Node& n, Transform& local) {
        const std::string& k = n.name;
        Shape shape;
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
            if (size.x == 0.0 || size.y == 0.0 || size.z == 0.0) return std::nullopt;
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
            if (r == 0.0) return std::nullopt;
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
            if (h == 0.0 || (r1 == 0.0 && r2 == 0.0)) return std::nullopt;
            shape = Cone{r1, r2, h, false};
            if (center) local = Transform::translate({0.0, 0.0, -0.5 * h});
            ++(r1 == r2 ? counts_.cylinders : counts_.cones);
        }
        return shape;
    }

    /// text(): its glyphs laid out by text2d.cpp, each glyph's contours cut into pieces.
    Built text(const Node& n, const glm::dmat3& af) {
        Args a(src_, n, {"text", "size", "font"},
               {"direction", "language", "script", "halign", "valign", "spacing"});
        TextParams p;
        auto word = [&](const char* name, std::string& into,
                        std::initializer_list<const char*> allowed) {
            const Value* v = a.get(name);
            if (!v) return;
            if (v->kind != Value::Kind::String)
                src_.fail(v->pos, std::string("expected a string for '") + name + "' of text()");
            into = v->str;
            if (allowed.size() == 0) return;
            std::string list;
            for (const char* w : allowed) {
                if (into == w) return;
                list += std::string(list.empty() ? "" : ", ") + w;
            }
            src_.fail(v->pos, std::string("unknown ") + name + " '" + into +
                                  "' of text() (expected " + list + ")");
        };
        if (const Value* v = a.get("text"); v && v->kind == Value::Kind::Number)
            p.text = twistText(v->number);  // OpenSCAD writes a number as its text
        else
            word("text", p.text, {});
        word("font", p.font, {});
        word("halign", p.halign, {"left", "center", "right"});
        word("valign", p.valign, {"top", "center", "baseline", "bottom"});
        word("direction", p.direction, {"ltr", "rtl", "ttb", "btt", ""});
        word("language", p.language, {});
        word("script", p.script, {});
        if (auto s = a.number("size")) {
            if (!(*s > 0.0) || !std::isfinite(*s))
                src_.fail(a.get("size")->pos, "'size' of text() must be positive");
            p.size = *s;
        }
        if (auto s = a.number("spacing")) {
            if (!std::isfinite(*s))
                src_.fail(a.get("spacing")->pos, "'spacing' of text() is not finite");
            p.spacing = *s;
        }
        // $fn, $fa, $fs decide the curves' segments (OpenSCAD's defaults when absent).
        double fn = 0.0, fa = 12.0, fs = 2.0;
        for (const Arg& arg : n.args) {
            double* into = arg.name == "$fn"   ? &fn
                           : arg.name == "$fa" ? &fa
                           : arg.name == "$fs" ? &fs
                                               : nullptr;
            if (into) *into = a.number(arg.value, "'" + arg.name + "' of text()");
        }
        p.segments = textCurveSegments(p.size, fn, fa, fs);
        TextLayout t;
        try {
            t = layoutText(p);
        } catch (const TextError& e) {
            src_.fail(n.pos, std::string("text(): ") + e.what());
        }
        size_t edges = 0;
        for (const auto& g : t.glyphs)
            for (const auto& c : g) edges += c.size();
        if (edges > 200000)
            src_.fail(n.pos,
                      "text() has more than 200000 outline edges, which Lancer does not cut");
        std::vector<int> items;
        for (auto& g : t.glyphs) {
            for (auto& c : g)
                for (Vec2& q : c) q = Vec2(af * glm::dvec3(q, 1.0));
            Built b = pieces(g, n.pos);
            if (b.kind == Built::Kind::Node) items.push_back(b.node);
        }
        if (items.empty()) return emptyPrimitive();
        return Built::of(regionOp(Region::Kind::Union, items, n.pos));
    }

    Built emptyPrimitive() {
        ++counts_.empty;
        return Built::empty();
    }

    const SourceText& src_;
    Scene& scene_;
    OpenScadCounts& counts_;
    const bool facets_;  ///< --facets openscad: round shapes as OpenSCAD's polygons and polyhedra
    const int twistParts_;  ///< ReadOptions::twistParts
    /// The largest sagitta of the faceted circles of the profile being read (2D units).
    double profileSagitta_ = 0.0;
    std::map<std::tuple<double, double, double>, int> materialOf_;
    std::vector<Region> regions_;
    /// The paths (even-odd) of the regions that pieces() made, by region: their outlines, for
    /// offset(delta).
    std::map<int, std::vector<std::vector<Vec2>>> outlines_;
    const Node* first2D_ = nullptr;  ///< the first 2D node met among solids
};

}  // namespace

void buildModel(const SourceText& src, const std::vector<Node>& top, Scene& scene,
                OpenScadCounts& counts, const ReadOptions& options) {
    scene.materials[0].color = hexColor(kDefaultColor);
    scene.tree.root = Builder(src, scene, counts, options).model(top);
}

}  // namespace lancer::openscad

namespace lancer {

const std::vector<std::string>& openScadSupportedNodes() {
    static const std::vector<std::string> nodes = {
        "group",     "union",      "difference",     "intersection",   "render", "multmatrix",
        "translate", "rotate",     "scale",          "mirror",         "color",  "cube",
        "sphere",    "cylinder",   "linear_extrude", "rotate_extrude", "square", "circle",
        "polygon",   "polyhedron", "hull",           "text",           "import", "surface"};
    return nodes;
}

}  // namespace lancer
