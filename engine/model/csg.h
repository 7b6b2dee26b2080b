// CSG trees of primitives: the scene model and its minimized bounding boxes (report, Fig. 1).
// Their restriction to a set of primitives (report, section 2) is in restriction.h.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/model/shapes.h"

namespace lancer {

enum class Op : uint8_t { Primitive, Union, Intersection, Difference };
const char* opName(Op op);

/// A primitive instance: a shape in its local frame placed by an affine transform.
struct Primitive {
    Shape shape;
    // Next to the shape, before the transform's 300-odd bytes: a hit's shading reads the
    // three together, in one or two cache lines instead of three.
    bool hasXf = false;  ///< false: the shape is already in world coordinates
    int material = 0;    ///< index into Scene::materials
    Transform xf;        ///< local to world
    Box3 worldBox;       ///< bounds of the untrimmed shape
    std::string origin;  ///< where it came from, for messages ("file:line:col")

    bool isSurface() const { return shapeIsSurface(shape); }
    int spans(const Ray& r, uint32_t id, Span* out) const {
        return hasXf ? shapeSpans(shape, xf.toLocal(r), id, out) : shapeSpans(shape, r, id, out);
    }
    /// spans() with the shape's test in single precision (the ray mapped to the shape's frame in
    /// double, then rounded).
    int spansFloat(const Ray& r, uint32_t id, Span* out) const {
        const Ray l = hasXf ? xf.toLocal(r) : r;
        return shapeSpans(shape, RayF{glm::vec3(l.o), glm::vec3(l.d)}, id, out);
    }
    /// Unit world normal at world point p on part `part` (outward for solids).
    Vec3 normal(const Vec3& p, uint8_t part) const;
    std::string toString() const;
};

/// Make a primitive, computing its world box.
Primitive makePrimitive(Shape shape, const Transform& xf, int material = 0);

/// A node: a primitive leaf (`prim`) or an operator over `left` and `right` (node indices).
struct CsgNode {
    Op op = Op::Primitive;
    int left = -1, right = -1;
    uint32_t prim = kNoPrim;
};

/// A binary CSG tree in a flat array. `root` is -1 for the empty tree.
struct CsgTree {
    std::vector<CsgNode> nodes;
    int root = -1;

    bool empty() const { return root < 0; }
    int leaf(uint32_t prim);
    int combine(Op op, int a, int b);
    /// Balanced tree over `items` (node indices) with an associative operator; -1 if none.
    int balanced(Op op, const std::vector<int>& items);
    int depth() const;
    /// Whether every node is a primitive or a union (then every restriction of it is too).
    bool unionOnly() const;
    /// Primitives reachable from the root, in leaf order.
    std::vector<uint32_t> primitives() const { return primitives(root); }
    /// Primitives reachable from node `from` (-1: none), in leaf order.
    std::vector<uint32_t> primitives(int from) const;
    std::string toString() const;
};

/// Result of CSG-driven box minimization.
struct MinimizedBoxes {
    std::vector<Box3> box;  ///< per primitive; empty for dropped primitives
    int iterations = 0;
    int dropped = 0;  ///< primitives whose box emptied (they cannot contribute)
};

/// Boxes of the report's Fig. 1, iterated to a fixed point: under A ∩ B each primitive of A is
/// clipped to box(B) and the reverse; under A − B each primitive of B is clipped to box(A).
MinimizedBoxes minimizeBoxes(const CsgTree& tree, const std::vector<Primitive>& prims);
/// The same fixed point from the boxes `start` (one per primitive, each holding what of its
/// primitive can contribute, in any one frame: the rules hold for boxes along any three axes).
MinimizedBoxes minimizeBoxes(const CsgTree& tree, std::vector<Box3> start);

/// Node boxes bottom-up from primitive boxes: union hull, intersection overlap, difference box(A).
Box3 nodeBox(const CsgTree& tree, int node, const std::vector<Box3>& primBox);

/// Check that surfaces occur only under unions; returns an error naming the node, or "".
std::string checkSurfacesUnderUnions(const CsgTree& tree, const std::vector<Primitive>& prims);

}  // namespace lancer
