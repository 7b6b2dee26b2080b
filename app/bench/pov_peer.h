// POV-Ray 3.7 as a peer in the report, on the CSG scenes (and any other): the scene written by
// writePov (pov_export.h) with the same camera, rendered by the `povray` executable when one is
// on the PATH, with POV-Ray's own parse and trace times. Its hits are compared through its depth
// image (a second render in which every surface emits its distance): the silhouette, and the
// distance to the 1/65535 of the scene's depth range.
#pragma once

#include <cstdint>
#include <string>

#include "app/bench/image_error.h"
#include "engine/render/renderer.h"

namespace lancer::bench {

/// One render of the peer.
struct PovRun {
    std::string failure;    ///< why it did not render (empty when it did)
    double parseMs = 0.0;   ///< POV-Ray's parse and bounding time
    double traceMs = 0.0;   ///< POV-Ray's trace time (its threads at work)
    double wallMs = 0.0;    ///< the povray process from start to end
    uint64_t rays = 0;      ///< its rays (primary, reflected, refracted) and shadow ray tests
    bool compared = false;  ///< `error` measured against the reference
    ImageError error;
    std::string errorNote;  ///< what `error` measures
};

class PovPeer {
  public:
    /// True when a `povray` executable is on the PATH (or $LANCER_POVRAY names one).
    static bool available();
    /// Its first line of `povray --version` ("POV-Ray 3.7.0.10.unofficial"); empty if none.
    static std::string version();
    /// The executable run.
    static std::string executable();

    /// Write the scene (and its depth variant) into OUT/povray/, as `name`.pov and
    /// `name`.depth.pov, for renders at `opt`'s size, threads and bounces.
    PovPeer(const Scene& scene, const RenderOptions& opt, const std::string& outDir,
            const std::string& name);

    /// Render the scene once, timed; with `ref`, also render its depth image and compare it
    /// with `ref`'s primary hits.
    PovRun render(const Image* ref) const;

  private:
    std::string dir_, name_;
    int width_, height_, threads_;
    double depthRange_;
};

/// POV-Ray's depth image (a 16-bit PNG of 1 - distance / range, black on a miss) against the
/// reference's primary hits: a pixel differs when one hits and the other misses, or when the
/// distances differ by more than one step of the image (range / 65535) and 1e-6 of the distance.
/// `maxDepthDiff` is over the pixels both hit. Returns false (and `why`) if it cannot be read.
bool comparePovDepth(const std::string& png, double range, const Image& ref, ImageError& out,
                     std::string& why);

}  // namespace lancer::bench
