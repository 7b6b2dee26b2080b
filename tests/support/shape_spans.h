// A shape's spans along a ray as one value, for the primitive tests (primitives_test.cpp,
// torus_test.cpp).
#pragma once

#include "engine/model/shapes.h"

namespace lancer::test {

/// The spans shapeSpans gives (at most two) and their count.
struct ShapeSpans {
    int n = 0;
    Span s[2];
};

/// `shape`'s spans along `r`, labelled primitive `prim`.
inline ShapeSpans spansOf(const Shape& shape, const Ray& r, uint32_t prim = 7) {
    ShapeSpans res;
    res.n = shapeSpans(shape, r, prim, res.s);
    return res;
}

}  // namespace lancer::test
