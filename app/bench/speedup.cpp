#include "app/bench/speedup.h"

#include <algorithm>

namespace lancer::bench {

namespace {

double testsPerRay(const RenderStats& s) {
    return s.counters.rays ? double(s.counters.primTests) / double(s.counters.rays) : 0.0;
}

/// Pixels of a width x height image that `lattice` renders.
size_t latticePixels(int width, int height, const PassLattice& lattice) {
    const int rowEnd = lattice.rowEnd < 0 ? height : std::min(lattice.rowEnd, height);
    size_t n = 0;
    for (int y = std::max(0, lattice.rowBegin); y < rowEnd; ++y)
        for (int x = 0; x < width; ++x) n += lattice.contains(x, y);
    return n;
}

}  // namespace

double Speedup::ratio() const {
    return brute.renderMs > 0.0 && scheme.renderMs > 0.0 ? brute.renderMs / scheme.renderMs : 0.0;
}

double Speedup::bruteTestsPerRay() const { return testsPerRay(brute); }

double Speedup::schemeTestsPerRay() const { return testsPerRay(scheme); }

SpeedupBaseline::SpeedupBaseline(const Scene& scene, const Accelerator& brute,
                                 const RenderOptions& opt, PassLattice lattice, Image& reference,
                                 const std::atomic<bool>* cancel)
    : scene_(scene), opt_(opt), lattice_(lattice), cancel_(cancel) {
    pixels_ = latticePixels(opt.width, opt.height, lattice);
    brute_ = render(scene, brute, opt, reference, lattice, cancel);
}

Speedup SpeedupBaseline::measure(const Accelerator& accel, Image& img) const {
    return against(render(scene_, accel, opt_, img, lattice_, cancel_));
}

Speedup SpeedupBaseline::against(const RenderStats& other) const {
    Speedup s;
    s.brute = brute_;
    s.scheme = other;
    s.pixels = pixels_;
    return s;
}

}  // namespace lancer::bench
