#include "tests/support/hexahedron.h"

#include <algorithm>
#include <cmath>

namespace lancer::test {

std::vector<FacePlane> facePlanes(const std::array<Vec3, 8>& c) {
    Vec3 centre(0.0);
    for (const Vec3& q : c) centre += q / 8.0;
    std::vector<FacePlane> planes;
    for (int a = 0; a < 3; ++a) {
        const int b = (a + 1) % 3, d = (a + 2) % 3;
        for (int side = 0; side < 2; ++side) {
            // The face's corners in cyclic order: each corner's neighbours are the previous
            // and the next.
            int idx[4];
            const int bits[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
            for (int k = 0; k < 4; ++k)
                idx[k] = (side << a) | (bits[k][0] << b) | (bits[k][1] << d);
            Vec3 n(0.0), fc(0.0);
            for (int k = 0; k < 4; ++k) {
                const Vec3& u = c[size_t(idx[k])];
                const Vec3 m =
                    glm::cross(c[size_t(idx[(k + 1) % 4])] - u, c[size_t(idx[(k + 3) % 4])] - u);
                if (glm::dot(m, m) > glm::dot(n, n)) n = m;
                fc += u / 4.0;
            }
            const double len = glm::length(n);
            if (!(len > 1e-12 * glm::dot(fc - centre, fc - centre) + 1e-300)) continue;
            n /= len;
            const double towards = glm::dot(n, fc - centre);
            planes.push_back({n, fc, towards > 0.0 ? 1.0 : (towards < 0.0 ? -1.0 : 0.0)});
        }
    }
    return planes;
}

double outside(const std::array<Vec3, 8>& c, const Vec3& p) {
    double worst = 0.0;
    for (const FacePlane& f : facePlanes(c)) {
        const double dist = glm::dot(f.n, p - f.fc);
        worst = std::max(worst, f.outward == 0.0 ? std::abs(dist) : f.outward * dist);
    }
    return worst;
}

double toBoundary(const std::array<Vec3, 8>& c, const Vec3& p) {
    double best = kInf;
    for (const FacePlane& f : facePlanes(c))
        best = std::min(best, std::abs(glm::dot(f.n, p - f.fc)));
    return best;
}

}  // namespace lancer::test
