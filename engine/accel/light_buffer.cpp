#include "engine/accel/light_buffer.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "engine/accel/regular/grid_frame.h"
#include "engine/scene/scene.h"
#include "engine/util/task_fence.h"

namespace lancer {

void LightBuffer::Map::project(const Box3& x, double& dNear, double& uLo, double& uHi, double& vLo,
                               double& vHi) const {
    // Coordinates by coord(): the axes are known at run time only.
    const double la = coord(L, a), lb = coord(L, b), lc = coord(L, c);
    dNear = s > 0.0 ? la - coord(x.hi, a) : coord(x.lo, a) - la;
    const double dFar = s > 0.0 ? la - coord(x.lo, a) : coord(x.hi, a) - la;
    const double b0 = coord(x.lo, b) - lb, b1 = coord(x.hi, b) - lb;
    const double c0 = coord(x.lo, c) - lc, c1 = coord(x.hi, c) - lc;
    quotients(dNear, dFar, b0, b1, c0, c1, uLo, uHi, vLo, vHi);
}

void LightBuffer::Map::quotients(double dNear, double dFar, double b0, double b1, double c0,
                                 double c1, double& uLo, double& uHi, double& vLo, double& vHi) {
    // n / d is monotone in n and in d (d > 0): the extremes are at the box's corners, and which
    // corner is known from the numerator's sign (a correctly rounded division is monotone too):
    // n >= 0 is least over the farthest depth, n < 0 over the nearest. Four divisions instead of
    // eight, the same quotients (a box of 600,000 is projected twice per light).
    if (dNear > 0.0 && dFar >= dNear) {
        uLo = b0 / (b0 >= 0.0 ? dFar : dNear);
        uHi = b1 / (b1 >= 0.0 ? dNear : dFar);
        vLo = c0 / (c0 >= 0.0 ? dFar : dNear);
        vHi = c1 / (c1 >= 0.0 ? dNear : dFar);
        return;
    }
    uLo = vLo = kInf;
    uHi = vHi = -kInf;
    for (double d : {dNear, dFar})
        for (int k = 0; k < 2; ++k) {
            const double u = (k ? b1 : b0) / d;
            const double v = (k ? c1 : c0) / d;
            uLo = std::min(uLo, u), uHi = std::max(uHi, u);
            vLo = std::min(vLo, v), vHi = std::max(vHi, v);
        }
}

namespace {

std::vector<Vec3> positions(const std::vector<Light>& lights) {
    std::vector<Vec3> out;
    for (const Light& l : lights) out.push_back(l.position);
    return out;
}

}  // namespace

LightBuffer::LightBuffer(const Scene& scene, int bins, std::stop_token stop,
                         const FrameChoice* own) {
    const FrameChoice chosen = own ? FrameChoice() : chooseGridFrame(scene);
    *this = LightBuffer(scene.bounds, scene.minBox, positions(scene.lights), bins, kSlots,
                        std::move(stop), Use::Shadows, own ? own : &chosen);
}

LightBuffer LightBuffer::forEye(const Scene& scene, const Vec3& eye, std::stop_token stop,
                                const FrameChoice* own) {
    return LightBuffer(scene.bounds, scene.minBox, {eye}, kBins, 1, std::move(stop), Use::NearOnly,
                       own);
}

/// Add depth interval x to a bin of k intervals (sorted, disjoint, unused ones last): merged
/// with those it overlaps; then, if three remain, the two with the smaller gap are joined (the
/// first pair on a tie).
void LightBuffer::insert(Slot* bin, int k, Slot x) {
    static_assert(kSlots == 2, "insert() merges into one or two intervals");
    if (k == 1 || !(bin[0].near <= bin[0].far)) {  // one slot, or an empty bin
        bin[0].near = std::min(bin[0].near, x.near);
        bin[0].far = std::max(bin[0].far, x.far);
        return;
    }
    Slot& a = bin[0];
    Slot& b = bin[1];
    const bool meetsA = x.near <= a.far && a.near <= x.far;
    if (!(b.near <= b.far)) {  // one interval so far
        if (meetsA)
            a = {std::min(a.near, x.near), std::max(a.far, x.far)};
        else if (x.far < a.near)
            b = a, a = x;
        else
            b = x;
        return;
    }
    const bool meetsB = x.near <= b.far && b.near <= x.far;
    if (meetsA && meetsB) {
        a = {std::min(a.near, x.near), std::max(b.far, x.far)};
        b = Slot{};
    } else if (meetsA) {
        a = {std::min(a.near, x.near), std::max(a.far, x.far)};
    } else if (meetsB) {
        b = {std::min(b.near, x.near), std::max(b.far, x.far)};
    } else if (x.far < a.near) {  // x, a, b
        if (a.near - x.far <= b.near - a.far)
            a.near = x.near;
        else
            b = {a.near, b.far}, a = x;
    } else if (x.near > b.far) {  // a, b, x
        if (b.near - a.far <= x.near - b.far)
            a.far = b.far, b = x;
        else
            b.far = x.far;
    } else {  // a, x, b
        if (x.near - a.far <= b.near - x.far)
            a.far = x.far;
        else
            b.near = x.near;
    }
}

LightBuffer::LightBuffer(const Box3& bounds, const std::vector<Box3>& boxes,
                         const std::vector<Vec3>& points, int bins, int slots, std::stop_token stop,
                         Use use, const FrameChoice* own)
    : nearOnly_(use == Use::NearOnly) {
    if (nearOnly_) slots = 1;
    if (bounds.isEmpty() || !bounds.isBounded() || points.empty()) return;
    // Turned boxes only when there is one per box.
    if (own && !(own->frame.turned && own->boxes.size() == boxes.size())) own = nullptr;
    const Vec3 e = bounds.extent();
    const double largest = std::max({e.x, e.y, e.z});
    const double size = largest + std::max(glm::length(bounds.lo), glm::length(bounds.hi));
    // Depths are compared with an allowance far above their rounding (a few ulps) and far below
    // the tracer's offset of shadow-ray origins (1e-9 of the scene scale), so a lit surface's
    // shadow ray is found unblocked at its origin; boxes are widened sideways by more.
    hair_ = 1e-12 * size;
    const double side = 1e-9 * size;
    box_ = {bounds.lo - Vec3(hair_), bounds.hi + Vec3(hair_)};
    maps_.resize(points.size());
    // The maps are independent: one task each. A light's boxes go into its bins in their
    // order (insert() depends on it), so each map is the same whatever the threads.
    std::atomic<bool> stopped{false};
    TaskFence fence;
    tbb::parallel_for(size_t(0), points.size(), fence.task([&](size_t l) {
        if (!buildMap(maps_[l], points[l], boxes, own, bins, slots, side, largest, stop))
            stopped = true;
    }));
    fence.acquire();
    if (stopped) maps_.clear();
}

bool LightBuffer::buildMap(Map& m, const Vec3& point, const std::vector<Box3>& boxes,
                           const FrameChoice* own, int bins, int slots, double side, double largest,
                           const std::stop_token& stop) {
    m.L = point;
    // The face of the box the light is farthest beyond; a light inside gets no map.
    double gap = 0.0;
    for (int a = 0; a < 3; ++a)
        for (double s : {1.0, -1.0}) {
            const double x = s > 0.0 ? m.L[a] - box_.hi[a] : box_.lo[a] - m.L[a];
            if (x > gap) gap = x, m.a = a, m.s = s;
        }
    // Well outside: a ray from the point that meets the box then runs steeply enough along the
    // axis that rounding of a grazing hit stays inside its box's depth range.
    if (!(gap > 1e-3 * largest) || !std::isfinite(gap)) return true;
    m.b = (m.a + 1) % 3;
    m.c = (m.a + 2) % 3;
    const int n = std::max(1, bins), k = std::clamp(slots, 1, kSlots);
    double dn, u0, u1, v0, v1;
    m.project(box_, dn, u0, u1, v0, v1);
    if (!(u1 > u0) || !(v1 > v0)) return true;
    // The boxes' images. The fine bins cover the rectangle of the small ones (whose image
    // is at most kLargeShare of the scene's): a floor under an object would otherwise
    // stretch the bins over its whole image, the object getting few of them. Outside it,
    // coarse bins over the whole image hold the large boxes. The images are made twice, for
    // the rectangle and then for the bins, rather than kept: on 600,000 spheres a list of them
    // took 50 MB per light, whose first touch cost more than making them again.
    const double largeArea = kLargeShare * (u1 - u0) * (v1 - v0);
    double wu0 = kInf, wu1 = -kInf, wv0 = kInf, wv1 = -kInf;
    bool anyLarge = false;
    for (size_t i = 0; i < boxes.size(); ++i) {
        if ((i & 255) == 0 && stop.stop_requested()) return false;
        BoxImage im;
        if (!image(m, boxes, own, i, side, largeArea, im)) continue;
        anyLarge |= im.large;
        if (!im.large) {
            wu0 = std::min(wu0, im.u0), wu1 = std::max(wu1, im.u1);
            wv0 = std::min(wv0, im.v0), wv1 = std::max(wv1, im.v1);
        }
    }
    const bool window = anyLarge && wu1 > wu0 && wv1 > wv0;
    if (window) {
        m.fine.cover(wu0, wu1, wv0, wv1, n, k);
        m.coarse.cover(u0, u1, v0, v1, std::max(1, n / 4), k);
    } else {
        m.fine.cover(u0, u1, v0, v1, n, k);
    }
    std::vector<double> colLo, colHi;  // scratch of Grid::add
    for (size_t i = 0; i < boxes.size(); ++i) {
        if ((i & 255) == 0 && stop.stop_requested()) return false;
        BoxImage im;
        if (!image(m, boxes, own, i, side, largeArea, im)) continue;
        m.fine.add(im, colLo, colHi, nearOnly_);
        if (window && im.large) m.coarse.add(im, colLo, colHi, nearOnly_);
    }
    return true;
}

bool LightBuffer::image(const Map& m, const std::vector<Box3>& boxes, const FrameChoice* own,
                        size_t i, double side, double largeArea, BoxImage& im) {
    const Box3& mb = boxes[i];
    if (mb.isEmpty()) return false;  // a dropped primitive
    // The box widened across the view axis only, by `side`, seen from the point: what
    // m.project() of the widened box computes, with the differences kept for Grid::add.
    const double la = coord(m.L, m.a), lb = coord(m.L, m.b), lc = coord(m.L, m.c);
    im.dn = m.s > 0.0 ? la - coord(mb.hi, m.a) : coord(mb.lo, m.a) - la;
    im.df = m.s > 0.0 ? la - coord(mb.lo, m.a) : coord(mb.hi, m.a) - la;
    im.b0 = (coord(mb.lo, m.b) - side) - lb, im.b1 = (coord(mb.hi, m.b) + side) - lb;
    im.c0 = (coord(mb.lo, m.c) - side) - lc, im.c1 = (coord(mb.hi, m.c) + side) - lc;
    Map::quotients(im.dn, im.df, im.b0, im.b1, im.c0, im.c1, im.u0, im.u1, im.v0, im.v1);
    im.outlineSize = 0;
    if (own && !own->boxes[i].isEmpty()) cutByTurnedBox(m, own->frame.axes, own->boxes[i], im);
    im.large = (im.u1 - im.u0) * (im.v1 - im.v0) > largeArea;
    return true;
}

void LightBuffer::cutByTurnedBox(const Map& m, const Mat3& axes, const Box3& fb, BoxImage& im) {
    // The primitive lies in both boxes (the turned one widened by chooseGridFrame's hair, far
    // above the rounding of its corners here), so its image lies in the convex hull of the
    // turned box's corner images (a central projection keeps convex hulls of points in front
    // of its centre) and its depths within the corners' range. Either bound alone is valid;
    // where rounding would leave them disjoint, the world box's are kept.
    const double la = coord(m.L, m.a), lb = coord(m.L, m.b), lc = coord(m.L, m.c);
    std::vector<glm::dvec2> pts(8);
    double dn = kInf, df = -kInf;
    for (int c = 0; c < 8; ++c) {
        const Vec3 w = axes * boxCorner(fb, c);
        const double d = m.s > 0.0 ? la - coord(w, m.a) : coord(w, m.a) - la;
        if (!(d > 0.0)) return;  // behind or beside the point: the outline is not convex
        pts[size_t(c)] = {(coord(w, m.b) - lb) / d, (coord(w, m.c) - lc) / d};
        dn = std::min(dn, d), df = std::max(df, d);
    }
    const std::vector<glm::dvec2> hull = convexHull2(std::move(pts));
    if (hull.size() < 3) return;
    glm::dvec2 lo = hull[0], hi = hull[0];
    for (const glm::dvec2& p : hull) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const double u0 = std::max(im.u0, lo.x), u1 = std::min(im.u1, hi.x);
    const double v0 = std::max(im.v0, lo.y), v1 = std::min(im.v1, hi.y);
    const double n = std::max(im.dn, dn), f = std::min(im.df, df);
    if (!(u0 <= u1 && v0 <= v1 && n <= f)) return;
    im.u0 = u0, im.u1 = u1, im.v0 = v0, im.v1 = v1, im.dn = n, im.df = f;
    im.outlineSize = int(hull.size());
    std::copy(hull.begin(), hull.end(), im.outline.begin());
}

void LightBuffer::Grid::cover(double uLo, double uHi, double vLo, double vHi, int bins,
                              int slotsPerBin) {
    n = bins;
    k = slotsPerBin;
    // Padded, so each small image lies strictly inside: no point of it is found outside.
    pad = 1e-9 * std::max(uHi - uLo, vHi - vLo);
    u0 = uLo - 2.0 * pad, v0 = vLo - 2.0 * pad;
    su = double(n) / (uHi - uLo + 4.0 * pad);
    sv = double(n) / (vHi - vLo + 4.0 * pad);
    slots.assign(size_t(n) * size_t(n) * size_t(k), Slot{});
}

namespace {

/// Narrow [lo, hi] to the depths d > 0 at which some u in [ua, ub] has u d in [w0, w1]: where
/// a cone of sight spanning [ua, ub] on one image axis meets a box spanning [w0, w1] on that
/// axis (relative to the point), up to the rounding of a division. False when the cone cannot
/// meet the box at any depth (exact tests); lo > hi may result otherwise.
bool coneDepths(double ua, double ub, double w0, double w1, double& lo, double& hi) {
    if (ua > 0.0)
        hi = std::min(hi, w1 / ua);  // ua d <= w1
    else if (ua < 0.0)
        lo = std::max(lo, w1 / ua);
    else if (w1 < 0.0)
        return false;
    if (ub > 0.0)
        lo = std::max(lo, w0 / ub);  // ub d >= w0
    else if (ub < 0.0)
        hi = std::min(hi, w0 / ub);
    else if (w0 > 0.0)
        return false;
    return true;
}

}  // namespace

void LightBuffer::Grid::add(const BoxImage& im, std::vector<double>& colLo,
                            std::vector<double>& colHi, bool nearOnly) {
    const int i0 = index(im.u0 - pad, u0, su), i1 = index(im.u1 + pad, u0, su);
    const int j0 = index(im.v0 - pad, v0, sv), j1 = index(im.v1 + pad, v0, sv);
    // Every depth the box gives a bin is at least its nearest, im.dn: where each of its bins
    // already holds one as near, it changes no bin's least depth (on balls:6 seen from the
    // camera, 586,117 of 597,872 boxes; the eye's buffer then takes 20-26 ms instead of 28-33).
    if (nearOnly && k == 1) {
        bool lowers = false;
        for (int j = j0; j <= j1 && !lowers; ++j) {
            const Slot* row = at(0, j);
            for (int i = i0; i <= i1 && !lowers; ++i) lowers = row[i].near > im.dn;
        }
        if (!lowers) return;
    }
    // A bin's cone: its image rectangle widened by pad (far above the rounding of the bin a
    // point falls in), the cone's depths widened by 1e-12 of themselves (far above that of the
    // divisions). A bin at the grid's edge also holds the points clamped into it: its cone is
    // unbounded on that side. The constraint of a column of bins is the same on every row.
    const double rel = 1e-12;
    const double du = 1.0 / su, dv = 1.0 / sv;
    // Grown only: every column used is written below (a resize per box, most of them a bin or
    // two wide, was a tenth of the light buffer's instructions).
    if (colLo.size() < size_t(i1 - i0 + 1)) {
        colLo.resize(size_t(i1 - i0 + 1));
        colHi.resize(size_t(i1 - i0 + 1));
    }
    for (int i = i0; i <= i1; ++i) {
        const double ua = i == 0 ? -kInf : u0 + i * du - pad;
        const double ub = i == n - 1 ? kInf : u0 + (i + 1) * du + pad;
        double lo = im.dn, hi = im.df;
        if (!coneDepths(ua, ub, im.b0, im.b1, lo, hi)) lo = kInf, hi = -kInf;
        colLo[size_t(i - i0)] = lo * (1.0 - rel);
        colHi[size_t(i - i0)] = hi * (1.0 + rel);
    }
    for (int j = j0; j <= j1; ++j) {
        const double va = j == 0 ? -kInf : v0 + j * dv - pad;
        const double vb = j == n - 1 ? kInf : v0 + (j + 1) * dv + pad;
        double lo = im.dn, hi = im.df;
        if (!coneDepths(va, vb, im.c0, im.c1, lo, hi)) continue;
        lo = std::max(im.dn, lo * (1.0 - rel));
        hi = std::min(im.df, hi * (1.0 + rel));
        Slot* row = at(0, j);
        // The turned box's outline, against the bins off the grid's edges (those are unbounded
        // outward).
        const bool cut = im.outlineSize >= 3 && j != 0 && j != n - 1;
        for (int i = i0; i <= i1; ++i) {
            if (cut && i != 0 && i != n - 1 &&
                !convexMeetsRect(im.outline.data(), size_t(im.outlineSize), {u0 + i * du - pad, va},
                                 {u0 + (i + 1) * du + pad, vb}))
                continue;
            const Slot depths{std::max(lo, colLo[size_t(i - i0)]),
                              std::min(hi, colHi[size_t(i - i0)])};
            if (depths.near <= depths.far) insert(row + size_t(i) * size_t(k), k, depths);
        }
    }
}

size_t LightBuffer::memoryBytes() const {
    size_t bytes = maps_.size() * sizeof(Map);
    for (const Map& m : maps_)
        bytes += (m.fine.slots.size() + m.coarse.slots.size()) * sizeof(Slot);
    return bytes;
}

size_t LightBuffer::bytesAtMost(size_t points, int bins, int slots) {
    // As buildMap() makes them: n x n fine bins, and max(1, n / 4)^2 coarse ones; a task's
    // scratch is a column of n bins' depths (two doubles each), the points a Vec3 each.
    const size_t n = size_t(std::max(1, bins)), coarse = std::max<size_t>(1, n / 4);
    const size_t k = size_t(std::clamp(slots, 1, kSlots));
    return points * (sizeof(Map) + (n * n + coarse * coarse) * k * sizeof(Slot) +
                     2 * n * sizeof(double) + sizeof(Vec3));
}

size_t LightBuffer::mappedLights() const {
    return size_t(std::count_if(maps_.begin(), maps_.end(),
                                [](const Map& m) { return !m.fine.slots.empty(); }));
}

}  // namespace lancer
