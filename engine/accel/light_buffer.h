// The light buffer: per point light, a conservative depth map of the scene seen from the light,
// which shortens shadow rays (after Haines and Greenberg's light buffer, 1986).
//
// Each light outside the scene's box looks at it along the axis it lies farthest beyond: depth
// d(p) = s (L[a] - p[a]) > 0, image point (u, v) = the other two coordinates relative to the
// light, over d. Every point of a ray from the light has the same image point. The image is cut
// into bins; a bin keeps the depth ranges [near, far] of the primitives' (CSG-minimized) boxes
// whose images meet it (a box's image lies inside the rectangle of its corners' images), merged
// into at most kSlots intervals (overlapping ranges join; then the two closest ones). In a turned
// scene each box is also bounded by its box along the turned frame (chooseGridFrame's,
// docs/regular.md "Turned scenes"): its image is cut to the convex outline of that box's corners
// and its depths to that box's, where a bar along a diagonal has a world box many times its size.
//
// A shadow ray heads for its light, so its depth falls as t grows, and its image point is that
// of its origin o. A blocker at t > 0 lies nearer the light than o, inside a box whose image
// meets o's bin, so at a depth inside one of the bin's intervals. The ray is walked only over
// those intervals (from o's side, the nearest first); when none lies between o and the light,
// it is unblocked without a walk. Each approximation (rectangles for images, bins, merged
// intervals) can only widen the intervals, never narrow them.
// On balls4, a shadow ray from the floor otherwise crawls along the cells that hold the floor
// polygon until it reaches the spheres: the floor's interval is a single depth, far from theirs.
//
// Only the accelerated schemes use it: brute force stays the unaided reference the others are
// checked against.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <stop_token>
#include <utility>
#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer {

struct Scene;
struct FrameChoice;

class LightBuffer {
  public:
    /// Bins per image axis.
    static constexpr int kBins = 128;
    /// Depth intervals per bin of a light's map (insert() is written for 1 or 2; 3 and 4 gained
    /// under 1% on balls4).
    static constexpr int kSlots = 2;
    /// A box whose image covers more than this share of the scene's is large (a floor): the
    /// bins cover the others' images only.
    static constexpr double kLargeShare = 1.0 / 16.0;

    /// What a buffer answers: shadow rays' stretches (shadowSegments) and nearFrom, or nearFrom
    /// alone (an eye's buffer: its bins keep the least depth only, and boxes that lower none of
    /// their bins' are skipped; shadowSegments says it does not know).
    enum class Use : uint8_t { Shadows, NearOnly };

    LightBuffer() = default;
    /// One depth map per light of the (prepared) scene that lies outside its bounds, kSlots
    /// intervals per bin, the boxes cut by their turned ones (`own`; null: chooseGridFrame's).
    /// A requested `stop` ends the construction early with an empty buffer (the build that
    /// asked for it is being cancelled).
    explicit LightBuffer(const Scene& scene, int bins = kBins, std::stop_token stop = {},
                         const FrameChoice* own = nullptr);
    /// One depth map per point outside `bounds`, of `boxes` (those inside `bounds`; empty
    /// ones are skipped), `slots` intervals per bin (1 to kSlots): the scene's lights, or the
    /// eye of a perspective camera (which needs only the least depth: 1). `own`, when turned:
    /// box i also lies in own->boxes[i] along own->frame's axes.
    LightBuffer(const Box3& bounds, const std::vector<Box3>& boxes, const std::vector<Vec3>& points,
                int bins = kBins, int slots = kSlots, std::stop_token stop = {},
                Use use = Use::Shadows, const FrameChoice* own = nullptr);
    /// The eye buffer of a perspective camera at `eye`: the least depth of each bin (Use::
    /// NearOnly), the scene's boxes cut by their turned ones (`own`; null: none).
    static LightBuffer forEye(const Scene& scene, const Vec3& eye, std::stop_token stop = {},
                              const FrameChoice* own = nullptr);

    /// A stretch [t0, t1] of a shadow ray that boxes may occupy.
    struct Segment {
        double t0, t1;
    };
    /// The stretches of the shadow ray from `o` along `dir` toward light `light`, within
    /// [0, tmax], outside which nothing can block it, in order of t, into `out` (kSlots at
    /// most). Returns how many (0: nothing can block it), or -1 when the buffer does not know
    /// (the light is inside the bounds, or `o` outside them): then the whole ray is to walk.
    int shadowSegments(const Vec3& o, const Vec3& dir, uint32_t light, double tmax,
                       Segment* out) const {
        double d, rate;
        const Slot* bin = shadowBin(o, dir, light, d, rate);
        if (!bin) return -1;
        int count = 0;
        for (int i = maps_[light].fine.k - 1; i >= 0; --i) {  // deepest first: the one nearest o
            if (!(bin[i].near <= bin[i].far)) continue;       // unused
            // Widened by the rounding allowance, in t units.
            const double t0 = std::max(0.0, (d - bin[i].far - hair_) / rate);
            const double t1 = std::min(tmax, (d - bin[i].near + hair_) / rate);
            if (t0 < t1) out[count++] = {t0, t1};
        }
        return count;
    }

    /// For a ray leaving point `point` itself along `dir` (a primary ray from the eye): a t
    /// before which it can meet nothing (+inf: nothing at all). 0 when the buffer does not know.
    double nearFrom(const Vec3& dir, uint32_t point) const {
        if (point >= maps_.size()) return 0.0;
        const Map& m = maps_[point];
        if (m.fine.slots.empty()) return 0.0;
        const double rate = -m.s * dir[m.a];  // depth gained per unit of t
        // The point lies beyond the bounds' face along the map's axis: a ray whose depth does
        // not grow never reaches them.
        if (!(rate > 0.0)) return kInf;
        // One division, not three: the products stray from the quotients by an ulp or two,
        // which the bins' pad and hair_ (far above rounding) cover.
        const double per = 1.0 / rate;
        const double u = dir[m.b] * per, v = dir[m.c] * per;
        // Outside the image of the bounds (the grids cover it, padded), the ray misses them.
        const Slot* bin = m.binWithin(u, v);
        return bin ? std::max(0.0, (bin[0].near - hair_) * per) : kInf;
    }

    bool empty() const { return maps_.empty(); }
    size_t memoryBytes() const;
    /// The most a buffer for `points` lights (or eyes) holds, known before it is built: each
    /// map's fine and coarse bins at their largest (memoryBytes() at most), and while it is
    /// built, the scratch of each map's task.
    static size_t bytesAtMost(size_t points, int bins = kBins, int slots = kSlots);
    /// Lights with a depth map.
    size_t mappedLights() const;

  private:
    /// A depth interval; unused: near > far. Doubles: a lit floor's shadow ray starts a hair
    /// (1e-9 of the scene) above the floor's depth, which a float could not tell apart.
    struct Slot {
        double near = kInf, far = -kInf;
    };
    /// A box seen from the map's point: the rectangle holding its image, its extent on the two
    /// image axes relative to the point, and its depth range; in a turned scene, the convex
    /// outline of its turned box's image too (the rectangle and depths already cut by it).
    struct BoxImage {
        double u0, u1, v0, v1;
        double b0, b1, c0, c1;
        double dn, df;
        bool large;
        int outlineSize = 0;  ///< points of `outline` (under 3: none)
        std::array<glm::dvec2, 8> outline;
    };
    /// Bins over a rectangle of the image, k intervals each, row by row.
    struct Grid {
        int n = 0, k = 1;
        double u0 = 0.0, v0 = 0.0, su = 0.0, sv = 0.0;
        double pad = 0.0;  ///< added around each image, far above rounding
        /// Per bin, k intervals by increasing depth, disjoint, the unused ones last (the first
        /// holds the bin's least depth); empty: no grid.
        std::vector<Slot> slots;
        void cover(double uLo, double uHi, double vLo, double vHi, int bins, int slotsPerBin);
        // Monotone in x (a difference and a product by a positive constant round monotonically):
        // a point inside a rectangle is in one of the rectangle's bins.
        int index(double x, double origin, double scale) const {
            const double f = (x - origin) * scale;
            return !(f >= 0.0) ? 0 : f >= double(n) ? n - 1 : int(f);
        }
        const Slot* at(int i, int j) const {
            return slots.data() + (size_t(j) * size_t(n) + size_t(i)) * size_t(k);
        }
        Slot* at(int i, int j) { return const_cast<Slot*>(std::as_const(*this).at(i, j)); }
        /// The bin of (u, v), clamped into the rectangle.
        const Slot* clamped(double u, double v) const {
            return at(index(u, u0, su), index(v, v0, sv));
        }
        /// The bin of (u, v); null outside the rectangle.
        const Slot* within(double u, double v) const {
            const double fu = (u - u0) * su, fv = (v - v0) * sv;
            if (!(fu >= 0.0 && fu < double(n) && fv >= 0.0 && fv < double(n))) return nullptr;
            return at(int(fu), int(fv));
        }
        /// Add a box to the bins its image meets (clamped into the grid), each with the depths
        /// at which the bin's cone of sight meets the box. colLo, colHi: scratch. `nearOnly`
        /// (one interval a bin): a box whose nearest depth lowers no bin's is skipped, so the
        /// bins' far ends are left unspecified.
        void add(const struct BoxImage& im, std::vector<double>& colLo, std::vector<double>& colHi,
                 bool nearOnly = false);
    };
    struct Map {
        Vec3 L{0.0};
        int a = 2, b = 0, c = 1;
        double s = 1.0;
        /// Bins over the images of the small boxes, which hold every box meeting them.
        Grid fine;
        /// Bins over the whole image holding the large boxes (the only ones outside `fine`);
        /// empty when `fine` covers the whole image.
        Grid coarse;
        /// The intervals of the bin holding image point (u, v).
        const Slot* bin(double u, double v) const {
            if (const Slot* in = fine.within(u, v)) return in;
            return coarse.slots.empty() ? fine.clamped(u, v) : coarse.clamped(u, v);
        }
        /// The same within the image of the bounds; null outside it.
        const Slot* binWithin(double u, double v) const {
            if (const Slot* in = fine.within(u, v)) return in;
            return coarse.slots.empty() ? nullptr : coarse.within(u, v);
        }
        void project(const Box3& x, double& dNear, double& u0, double& u1, double& v0,
                     double& v1) const;
        /// The rectangle of project() from the box's depths and its extents relative to the
        /// point on the two image axes.
        static void quotients(double dNear, double dFar, double b0, double b1, double c0, double c1,
                              double& u0, double& u1, double& v0, double& v1);
    };
    /// The bin of the shadow ray from `o` along `dir` toward light `light`, with o's depth `d`
    /// and the fall of the depth per unit of t; null when the buffer does not know.
    const Slot* shadowBin(const Vec3& o, const Vec3& dir, uint32_t light, double& d,
                          double& rate) const {
        if (light >= maps_.size() || nearOnly_) return nullptr;
        const Map& m = maps_[light];
        if (m.fine.slots.empty() || !box_.contains(o)) return nullptr;
        d = m.s * (m.L[m.a] - o[m.a]);  // > 0: o is in the box, the light beyond
        rate = m.s * dir[m.a];
        if (!(rate > 0.0)) return nullptr;
        return m.bin((o[m.b] - m.L[m.b]) / d, (o[m.c] - m.L[m.c]) / d);
    }
    /// Map `m` of the light at `point`; false when `stop` ended it.
    bool buildMap(Map& m, const Vec3& point, const std::vector<Box3>& boxes, const FrameChoice* own,
                  int bins, int slots, double side, double largest, const std::stop_token& stop);
    /// The image of box i of `boxes` in map `m` (widened sideways by `side`), cut by its turned
    /// box when `own` has one; false for an empty box.
    static bool image(const Map& m, const std::vector<Box3>& boxes, const FrameChoice* own,
                      size_t i, double side, double largeArea, BoxImage& im);
    /// Cut `im` by the image of `fb`, a box along `axes` (columns: its axes in the world), when
    /// every corner of it lies in front of the map's point.
    static void cutByTurnedBox(const Map& m, const Mat3& axes, const Box3& fb, BoxImage& im);
    /// Add depth interval x to a bin of k (1 or 2) intervals.
    static void insert(Slot* bin, int k, Slot x);
    Box3 box_;               ///< the scene bounds, widened by hair_
    double hair_ = 0.0;      ///< rounding allowance, in scene units
    std::vector<Map> maps_;  ///< per scene light
    bool nearOnly_ = false;  ///< built for Use::NearOnly
};

}  // namespace lancer
