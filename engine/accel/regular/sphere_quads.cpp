// The sphere quads (docs/regular.md, "Sphere quads: a leaf's spheres four at a time"): the
// grid's primitive lists once more, as floats four entries at a time, for the walk's first look
// at a union-only leaf's spheres (RegularGrid::hitInSphereLeaf, regular_walk.h).
#include <bit>
#include <limits>

#include "engine/accel/regular/regular_grid.h"
#include "engine/util/huge_pages.h"

namespace lancer {

void RegularGrid::makeSphereQuads() {
    const Scene& scene = *scene_;
    // The world's largest coordinate in the grid (the quads test world points): the largest of
    // its corners' coordinates, which along the world's axes is the box's own.
    quadScale_ = 0.0;
    for (int c = 0; c < 8; ++c) {
        const Vec3 w = glm::abs(frame_.toWorld(boxCorner(clipBox_, c)));
        quadScale_ = std::max({quadScale_, w.x, w.y, w.z});
    }
    // A centre and the walk's point in floats are each off by 2^-24 of the largest coordinate:
    // the radius is grown by ten times their sum, and by ten times the floats' relative
    // rounding of the comparison.
    const double grow = 1e-6 * quadScale_;
    bool spheres = false;
    reserveHuge(quads_, (primList_.size() + 3) / 4);
    quads_.assign((primList_.size() + 3) / 4, SphereQuad{});
    for (size_t i = 0; i < primList_.size(); ++i) {
        const uint32_t p = primList_[i];
        SphereQuad& q = quads_[i / 4];
        const size_t j = i % 4;
        const bool packed = p < scene.packedSpheres.size() && scene.packedSpheres[p].r >= 0.0;
        if (!packed) {
            q.x[j] = q.y[j] = q.z[j] = 0.0f;
            q.r[j] = std::numeric_limits<float>::infinity();
            continue;
        }
        const PackedSphere& s = scene.packedSpheres[p];
        spheres = true;
        q.x[j] = float(s.c.x), q.y[j] = float(s.c.y), q.z[j] = float(s.c.z);
        const double r = s.r * (1.0 + 4e-6) + grow;
        // The next float up, as std::nextafter toward infinity gives it for a finite r >= 0
        // (its bits plus one; a call per sphere was a tenth of the quads' instructions).
        const float f = float(r);
        q.r[j] = f < std::numeric_limits<float>::infinity()
                     ? std::bit_cast<float>(std::bit_cast<uint32_t>(f) + 1u)
                     : f;
    }
    if (!spheres) quads_.clear();
}

}  // namespace lancer
