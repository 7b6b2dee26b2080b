// The axis planner of --split-axes cost (docs/regular.md, "Axis order"), and what it and the
// builder both weigh: each primitive's test, and the cells every box covers.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "engine/accel/regular/directory.h"
#include "engine/geometry/geometry.h"

namespace lancer {

class BuildGuard;  // engine/accel/build_guard.h
struct Scene;

namespace regular_build {

/// A cell inside every one of its primitives' boxes: every sub-cell would hold the same
/// primitives, hence the same tree, so it is not split.
inline bool coveredByAll(const std::vector<Box3>& boxes, std::span<const uint32_t> prims,
                         const Box3& cell) {
    for (uint32_t p : prims) {
        const Box3& b = boxes[p];
        if (!(b.lo.x <= cell.lo.x && b.lo.y <= cell.lo.y && b.lo.z <= cell.lo.z &&
              b.hi.x >= cell.hi.x && b.hi.y >= cell.hi.y && b.hi.z >= cell.hi.z))
            return false;
    }
    return true;
}

/// What testing each primitive costs, in sphere tests: a polygon's inside test loops over its
/// edges, so it weighs 1 + vertices / 4 (on gears, whose faces have up to 144 vertices, weighing
/// every test alike made the planner cut x and y first, for 34% more instructions than x, y, z in
/// turn). Floats: 1 + n / 4 is exact in one, and half the bytes of a double are read at random
/// (and touched first) for each of up to a million primitives.
std::vector<float> testWeights(const Scene& scene);

/// testWeights() in quarters of a test, as integers: every weight is a multiple of a quarter
/// (4 + vertices quarters, or a float of 2^21 or more, a whole number), so their sums are
/// exact in a double, and an integer sum divided by 4 is the double sum bit for bit. The loops
/// over references sum integers, whose additions do not wait on a double's latency.
std::vector<uint32_t> testQuarters(const std::vector<float>& weights);

/// The axes of --split-axes cost, planned level by level over the primitives' minimized boxes
/// alone (no CSG restriction, so a little pessimistic). Every cell of a level has the same
/// surface area A(axis) once cut on `axis`, so with the surface area heuristic the next level
/// costs A(axis) x (2 visits + the tests of the primitive references) per cut cell; the cheapest
/// axis is cut, ties going to x, then y; a test weighs as testWeights() says (`quarters`:
/// testQuarters()). Cells stop as in the build: at most max-objects primitives, or covered by
/// all their boxes. On a cube of evenly spread primitives this is the report's x, y, z; on a flat
/// scene (balls4: 24 x 24 x 1.5) it cuts x and y until the cells are about cubes, where the
/// report's order makes them 16 times flatter than wide.
AxisSchedule planSchedule(const std::vector<Box3>& primBoxes, const Box3& box,
                          const std::vector<uint32_t>& live, const std::vector<uint32_t>& quarters,
                          int maxLevel, int maxObjects, const BuildGuard& guard);

}  // namespace regular_build

}  // namespace lancer
