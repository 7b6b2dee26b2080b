// A scheme's speed against brute force, measured the same way by `lancer bench` and by the
// viewer's Statistics panel: brute force renders the pixels once, then each scheme renders the
// same pixels with the same options, and the speedup is the ratio of their render times.
#pragma once

#include <atomic>
#include <cstddef>

#include "engine/render/renderer.h"

namespace lancer::bench {

/// A render timed against the brute-force render of the same pixels.
struct Speedup {
    RenderStats brute, scheme;
    size_t pixels = 0;  ///< pixels traced by each

    /// Brute-force time over the scheme's (0 when either is missing).
    double ratio() const;
    /// Primitive tests per ray of each render (0 without rays).
    double bruteTestsPerRay() const;
    double schemeTestsPerRay() const;
    /// Either render was cancelled before it finished.
    bool cancelled() const { return brute.cancelled || scheme.cancelled; }
};

/// The brute-force render of a view, timed once, against which schemes are then timed.
class SpeedupBaseline {
  public:
    /// Render the pixels of `lattice` with `brute` into `reference` (its other pixels are left
    /// as they are). `cancel` also stops every later measure().
    SpeedupBaseline(const Scene& scene, const Accelerator& brute, const RenderOptions& opt,
                    PassLattice lattice, Image& reference,
                    const std::atomic<bool>* cancel = nullptr);
    /// Render the same pixels with `accel` into `img`, timed against the baseline.
    Speedup measure(const Accelerator& accel, Image& img) const;
    /// A render made elsewhere (a peer outside the engine) against the baseline.
    Speedup against(const RenderStats& other) const;
    /// The brute-force render.
    const RenderStats& brute() const { return brute_; }
    /// Pixels traced by each render.
    size_t pixels() const { return pixels_; }

  private:
    const Scene& scene_;
    RenderOptions opt_;
    PassLattice lattice_;
    const std::atomic<bool>* cancel_;
    RenderStats brute_;
    size_t pixels_ = 0;
};

}  // namespace lancer::bench
