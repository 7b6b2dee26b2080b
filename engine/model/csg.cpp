#include "engine/model/csg.h"

#include <algorithm>
#include <functional>

namespace lancer {

const char* opName(Op op) {
    switch (op) {
        case Op::Primitive:
            return "primitive";
        case Op::Union:
            return "union";
        case Op::Intersection:
            return "intersection";
        case Op::Difference:
            return "difference";
    }
    return "?";
}

Vec3 Primitive::normal(const Vec3& p, uint8_t part) const {
    if (!hasXf) return glm::normalize(shapeNormal(shape, p, part));
    return xf.normalOf(shapeNormal(shape, xf.toLocal({p, Vec3(0.0)}).o, part));
}

std::string Primitive::toString() const {
    std::string s = std::string(shapeName(shape)) + " " + worldBox.toString();
    if (!origin.empty()) s += " from " + origin;
    return s;
}

Primitive makePrimitive(Shape shape, const Transform& xf, int material) {
    Primitive p;
    p.shape = std::move(shape);
    p.hasXf = !xf.isIdentity();
    p.xf = xf;
    p.material = material;
    p.worldBox = p.hasXf ? xf.box(shapeBounds(p.shape)) : shapeBounds(p.shape);
    return p;
}

int CsgTree::leaf(uint32_t prim) {
    nodes.push_back({Op::Primitive, -1, -1, prim});
    return int(nodes.size()) - 1;
}

int CsgTree::combine(Op op, int a, int b) {
    nodes.push_back({op, a, b, kNoPrim});
    return int(nodes.size()) - 1;
}

int CsgTree::balanced(Op op, const std::vector<int>& items) {
    if (items.empty()) return -1;
    std::function<int(size_t, size_t)> build = [&](size_t lo, size_t hi) -> int {
        if (hi - lo == 1) return items[lo];
        size_t mid = lo + (hi - lo) / 2;
        int a = build(lo, mid);
        int b = build(mid, hi);
        return combine(op, a, b);
    };
    return build(0, items.size());
}

bool CsgTree::unionOnly() const {
    return std::all_of(nodes.begin(), nodes.end(),
                       [](const CsgNode& n) { return n.op == Op::Primitive || n.op == Op::Union; });
}

int CsgTree::depth() const {
    // Iterative: a recursion through std::function took 35 M instructions on a union of
    // 600,000 primitives, and a chain of thousands of operations could overflow the stack.
    if (root < 0) return 0;
    int deepest = 0;
    std::vector<std::pair<int, int>> stack{{root, 1}};
    while (!stack.empty()) {
        const auto [n, d] = stack.back();
        stack.pop_back();
        const CsgNode& x = nodes[size_t(n)];
        deepest = std::max(deepest, d);
        if (x.op != Op::Primitive) {
            stack.push_back({x.right, d + 1});
            stack.push_back({x.left, d + 1});
        }
    }
    return deepest;
}

std::vector<uint32_t> CsgTree::primitives(int from) const {
    std::vector<uint32_t> out;
    if (from < 0) return out;
    std::vector<int> stack{from};
    while (!stack.empty()) {
        int n = stack.back();
        stack.pop_back();
        const CsgNode& x = nodes[n];
        if (x.op == Op::Primitive) {
            out.push_back(x.prim);
        } else {
            stack.push_back(x.right);
            stack.push_back(x.left);
        }
    }
    return out;
}

std::string CsgTree::toString() const {
    if (root < 0) return "∅";
    std::function<std::string(int)> s = [&](int n) -> std::string {
        const CsgNode& x = nodes[n];
        if (x.op == Op::Primitive) {
            std::string out = "p";
            return out.append(std::to_string(x.prim));
        }
        const char* sym = x.op == Op::Union ? " ∪ " : x.op == Op::Intersection ? " ∩ " : " − ";
        std::string out = "(";
        return out.append(s(x.left)).append(sym).append(s(x.right)).append(")");
    };
    return s(root);
}

Box3 nodeBox(const CsgTree& tree, int node, const std::vector<Box3>& primBox) {
    const CsgNode& x = tree.nodes[node];
    switch (x.op) {
        case Op::Primitive:
            return primBox[x.prim];
        case Op::Union:
            return hull(nodeBox(tree, x.left, primBox), nodeBox(tree, x.right, primBox));
        case Op::Intersection:
            return overlap(nodeBox(tree, x.left, primBox), nodeBox(tree, x.right, primBox));
        case Op::Difference:
            return nodeBox(tree, x.left, primBox);
    }
    return Box3::empty();
}

MinimizedBoxes minimizeBoxes(const CsgTree& tree, const std::vector<Primitive>& prims) {
    std::vector<Box3> start(prims.size());
    for (size_t i = 0; i < prims.size(); ++i) start[i] = prims[i].worldBox;
    return minimizeBoxes(tree, std::move(start));
}

MinimizedBoxes minimizeBoxes(const CsgTree& tree, std::vector<Box3> start) {
    MinimizedBoxes r;
    r.box = std::move(start);
    if (tree.root < 0) return r;

    std::vector<Box3> nb(tree.nodes.size());
    // Bottom-up node boxes (children precede parents is not guaranteed, so recurse).
    std::function<Box3(int)> up = [&](int n) -> Box3 {
        const CsgNode& x = tree.nodes[n];
        Box3 b;
        switch (x.op) {
            case Op::Primitive:
                b = r.box[x.prim];
                break;
            case Op::Union: {
                Box3 a = up(x.left);
                b = hull(a, up(x.right));
                break;
            }
            case Op::Intersection: {
                Box3 a = up(x.left);
                b = overlap(a, up(x.right));
                break;
            }
            case Op::Difference: {
                b = up(x.left);
                up(x.right);
                break;
            }
        }
        return nb[n] = b;
    };
    // Top-down: clip every primitive under `n` to `clip`.
    bool changed = false;
    std::function<void(int, const Box3&)> down = [&](int n, const Box3& clip) {
        const CsgNode& x = tree.nodes[n];
        switch (x.op) {
            case Op::Primitive: {
                Box3 c = overlap(r.box[x.prim], clip);
                if (!(c == r.box[x.prim])) r.box[x.prim] = c, changed = true;
                break;
            }
            case Op::Union:
                down(x.left, clip);
                down(x.right, clip);
                break;
            case Op::Intersection:
                down(x.left, overlap(clip, nb[x.right]));
                down(x.right, overlap(clip, nb[x.left]));
                break;
            case Op::Difference:
                down(x.left, clip);
                down(x.right, overlap(clip, nb[x.left]));
                break;
        }
    };
    do {
        changed = false;
        up(tree.root);
        down(tree.root, nb[tree.root]);
        ++r.iterations;
    } while (changed && r.iterations < 64);
    // Primitives reachable from the tree but with an empty box are dropped.
    for (uint32_t p : tree.primitives())
        if (r.box[p].isEmpty()) ++r.dropped;
    return r;
}

std::string checkSurfacesUnderUnions(const CsgTree& tree, const std::vector<Primitive>& prims) {
    if (tree.root < 0) return "";
    std::string err;
    std::function<void(int, int)> walk = [&](int n, int badAncestor) {
        if (!err.empty()) return;
        const CsgNode& x = tree.nodes[n];
        if (x.op == Op::Primitive) {
            if (badAncestor >= 0 && prims[x.prim].isSurface()) {
                const Primitive& p = prims[x.prim];
                err = std::string("a ") + shapeName(p.shape) +
                      (p.origin.empty() ? "" : " (" + p.origin + ")") +
                      " is a surface with no inside; it may appear only under unions, not under "
                      "the " +
                      opName(tree.nodes[badAncestor].op) + " node";
            }
            return;
        }
        int bad = x.op == Op::Union ? badAncestor : n;
        walk(x.left, bad);
        walk(x.right, bad);
    };
    walk(tree.root, -1);
    return err;
}

}  // namespace lancer
