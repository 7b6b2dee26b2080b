// How far an image is from the reference of the same run: the measure of error of `lancer bench`
// (the report and the scale table), on every pixel or on a lattice of them.
#pragma once

#include <cstddef>

#include "engine/render/renderer.h"

namespace lancer::bench {

/// Difference of an image against the reference.
struct ImageError {
    size_t hitDiff = 0;    ///< pixels whose primary hit (primitive or distance) differs
    size_t colorDiff = 0;  ///< pixels whose colour differs by more than 2/255
    double maxDepthDiff = 0.0;
    /// Root mean square of the colour difference, over the three channels of the pixels compared,
    /// on the 8-bit values scaled to 0..1 (what the viewer shows).
    double colorRmse = 0.0;
    size_t compared = 0;        ///< pixels compared
    size_t silhouetteDiff = 0;  ///< pixels hit in one image and missed in the other
    /// Root mean square of the primary hit distance's difference, over the pixels both hit.
    double rmsDepthDiff = 0.0;
    /// The 99th percentile of that difference: what a pixel's depth error is but for the 1% of
    /// pixels on a depth edge (where one image sees past an edge the other does not).
    double p99DepthDiff = 0.0;
};

/// `img` against `ref` on the pixels of `on` (default: every pixel); both are sized alike.
ImageError compareImages(const Image& ref, const Image& img, const PassLattice& on = {});

/// `img` against `ref` by their surfaces alone, for an image of other primitives (a mesh of the
/// same solid): a pixel's hit differs when one hits and the other misses, or when the distances
/// differ by more than 1e-6 of the distance; `maxDepthDiff` is over the pixels both hit.
ImageError compareSurfaces(const Image& ref, const Image& img);

}  // namespace lancer::bench
