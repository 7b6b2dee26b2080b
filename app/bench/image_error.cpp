#include "app/bench/image_error.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <vector>

namespace lancer::bench {

namespace {

/// Both comparisons: `byPrimitive` counts a pixel whose hit primitive differs as a differing
/// hit, and takes a silhouette difference as an infinite depth difference.
ImageError compare(const Image& ref, const Image& img, const PassLattice& on, bool byPrimitive) {
    ImageError e;
    std::vector<uint8_t> a = ref.rgba8(), b = img.rgba8();
    double squares = 0.0, depthSquares = 0.0;
    std::vector<double> depthDiffs;
    for (int y = 0; y < ref.height; ++y)
        for (int x = 0; x < ref.width; ++x) {
            if (!on.contains(x, y)) continue;
            const size_t i = ref.index(x, y);
            ++e.compared;
            const float da = ref.depth[i], db = img.depth[i];
            const bool bothMiss = std::isinf(da) && std::isinf(db);
            const bool silhouette = std::isinf(da) != std::isinf(db);
            const double dd = bothMiss     ? 0.0
                              : silhouette ? kInf
                                           : std::abs(double(da) - double(db));
            e.silhouetteDiff += silhouette;
            if (!bothMiss && !silhouette) {
                depthSquares += dd * dd;
                depthDiffs.push_back(dd);
            }
            if ((byPrimitive && ref.hitPrim[i] != img.hitPrim[i]) ||
                dd > 1e-6 * std::max(1.0, double(da)))
                ++e.hitDiff;
            if (std::isfinite(dd))
                e.maxDepthDiff = std::max(e.maxDepthDiff, dd);
            else if (byPrimitive)
                e.maxDepthDiff = kInf;
            bool differs = false;
            for (int c = 0; c < 3; ++c) {
                const int d = int(a[4 * i + size_t(c)]) - int(b[4 * i + size_t(c)]);
                squares += double(d) * double(d);
                differs = differs || std::abs(d) > 2;
            }
            e.colorDiff += differs;
        }
    if (e.compared) e.colorRmse = std::sqrt(squares / (3.0 * double(e.compared))) / 255.0;
    if (!depthDiffs.empty()) {
        e.rmsDepthDiff = std::sqrt(depthSquares / double(depthDiffs.size()));
        const auto k = depthDiffs.begin() + ptrdiff_t((depthDiffs.size() - 1) * 99 / 100);
        std::nth_element(depthDiffs.begin(), k, depthDiffs.end());
        e.p99DepthDiff = *k;
    }
    return e;
}

}  // namespace

ImageError compareImages(const Image& ref, const Image& img, const PassLattice& on) {
    return compare(ref, img, on, true);
}

ImageError compareSurfaces(const Image& ref, const Image& img) {
    return compare(ref, img, PassLattice{}, false);
}

}  // namespace lancer::bench
