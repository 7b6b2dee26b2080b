#include "app/bench/speedup.h"

#include <algorithm>

namespace lancer::bench {

namespace {

double testsPerRay(const RenderStats& s) {
    return s.counters.rays ? double(s.counters.primTests) / double(s.counters.rays) : 0.0;
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
    pixels_ = lattice.pixels(opt.width, opt.height);
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
