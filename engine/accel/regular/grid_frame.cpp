#include "engine/accel/regular/grid_frame.h"

#include <algorithm>
#include <cmath>

namespace lancer {

namespace {

/// The rotation nearest the linear part `m` of a transform by Gram-Schmidt on its first two
/// columns: exact for a rotation times a scale along the local axes (OpenSCAD's
/// multmatrix(rotate) of a scaled cube). False for a degenerate map, and for a sheared one
/// (columns more than 1e-3 from square): it has no axes of its own, and boxes along the
/// nearest rotation's axes hug a sheared primitive so tightly that its hits, computed through
/// the ill-conditioned map, fell outside them (a cone sheared by 9999: the BVH missed a hit
/// brute force found; tests/fuzz/corpus/pipeline/sheared-cone.csg).
bool orthonormalize(const Mat3& m, Mat3& out) {
    const Vec3 c0 = m[0], c1 = m[1];
    const double n0 = glm::length(c0), l1 = glm::length(c1);
    if (!(n0 > 0.0) || !std::isfinite(n0) || !(l1 > 0.0) || !std::isfinite(l1)) return false;
    for (int i = 0; i < 3; ++i)
        for (int j = i + 1; j < 3; ++j)
            if (!(std::abs(glm::dot(m[i], m[j])) <= 1e-3 * glm::length(m[i]) * glm::length(m[j])))
                return false;
    const Vec3 u0 = c0 / n0;
    const Vec3 v1 = c1 - glm::dot(c1, u0) * u0;
    const double n1 = glm::length(v1);
    if (!(n1 > 1e-9 * l1)) return false;
    const Vec3 u1 = v1 / n1;
    out = Mat3(u0, u1, glm::cross(u0, u1));
    return true;
}

/// Each column of `m` within `tol` of a signed unit axis: `m` permutes and flips the axes.
bool permutesAxes(const Mat3& m, double tol) {
    for (int c = 0; c < 3; ++c) {
        const Vec3 v = glm::abs(m[c]);
        if (!(std::max({v.x, v.y, v.z}) > 1.0 - tol)) return false;
    }
    return true;
}

/// Rotations from transforms built of six-digit matrices (OpenSCAD's .csg) agree to about
/// 1e-6: frames that close are one frame.
constexpr double kSameFrame = 1e-4;
/// Distinct turned rotations kept while counting.
constexpr size_t kMaxDistinct = 16;

/// The frame box of a world box: the hull of its eight corners in the frame.
Box3 frameHull(const Box3& world, const GridFrame& f, double hair) {
    Box3 b;
    for (int c = 0; c < 8; ++c) b.expand(f.toFrame(boxCorner(world, c)));
    return {b.lo - Vec3(hair), b.hi + Vec3(hair)};
}

}  // namespace

GridFrame GridFrame::fromAxes(const Mat3& m) {
    GridFrame f;
    f.axes = m;
    f.toFrameM = glm::transpose(m);
    f.turned = true;
    return f;
}

Box3 frameBoxOf(const Primitive& p, const GridFrame& f, double hair) {
    Box3 b;
    const auto add = [&](const Vec3& local) {
        b.expand(f.toFrame(p.hasXf ? p.xf.point(local) : local));
    };
    if (const Sphere* s = std::get_if<Sphere>(&p.shape); s && !p.hasXf) {
        const Vec3 c = f.toFrame(s->c);
        b = {c - Vec3(s->r), c + Vec3(s->r)};
    } else if (const Triangle* t = std::get_if<Triangle>(&p.shape)) {
        for (const Vec3& v : t->p) add(v);
    } else if (const Polygon* g = std::get_if<Polygon>(&p.shape)) {
        for (const Vec3& v : g->p) add(v);
    } else {
        const Box3 l = shapeBounds(p.shape);
        for (int c = 0; c < 8; ++c) add(boxCorner(l, c));
    }
    return {b.lo - Vec3(hair), b.hi + Vec3(hair)};
}

FrameChoice chooseGridFrame(const Scene& scene) {
    FrameChoice out;
    out.bounds = scene.bounds;
    if (scene.tree.empty()) return out;
    std::vector<uint32_t> live = scene.tree.primitives();
    std::sort(live.begin(), live.end());
    live.erase(std::unique(live.begin(), live.end()), live.end());
    for (uint32_t p : live)
        if (!scene.minBox[p].isEmpty()) out.worldArea += surfaceArea(scene.minBox[p]);
    out.frameArea = out.worldArea;
    if (!std::isfinite(out.worldArea) || !(out.worldArea > 0.0)) return out;

    // Distinct turned rotations among the transforms, counted; past kMaxDistinct distinct ones
    // only the known ones are counted (a scene of randomly turned parts has no frame of its own,
    // and each primitive is compared with at most that many).
    struct Candidate {
        Mat3 axes;
        size_t count;
        size_t first;  ///< its place among the candidates found, for a stable order
    };
    std::vector<Candidate> cands;
    for (uint32_t p : live) {
        const Primitive& prim = scene.prims[p];
        Mat3 r;
        if (!prim.hasXf || !orthonormalize(Mat3(prim.xf.m), r) || permutesAxes(r, 1e-9)) continue;
        auto it = std::find_if(cands.begin(), cands.end(), [&](const Candidate& c) {
            return permutesAxes(glm::transpose(c.axes) * r, kSameFrame);
        });
        if (it != cands.end())
            ++it->count;
        else if (cands.size() < kMaxDistinct)
            cands.push_back({r, 1, cands.size()});
    }
    out.candidates = int(cands.size());
    // By count, then as found (std::sort: no temporary buffer, which a build under a replaced
    // operator new, as the bounds tests', would take from the nothrow form).
    std::sort(cands.begin(), cands.end(), [](const Candidate& a, const Candidate& b) {
        return a.count != b.count ? a.count > b.count : a.first < b.first;
    });
    // Scored: the most frequent, each shared by 1% of the live primitives at least (a score
    // minimizes every box again: on a scene of many parts turned each its own way, one
    // minimization per part would cost more than the build).
    const size_t least = std::max<size_t>(1, live.size() / 100);
    while (!cands.empty() && cands.back().count < least) cands.pop_back();
    if (cands.size() > size_t(kMaxFrameCandidates)) cands.resize(kMaxFrameCandidates);

    // Boxes mapped into a frame round by an ulp or so: each is widened by a hair of the scene's
    // size, so a primitive's surface never lies outside its box in the frame.
    const Box3& sb = scene.bounds;
    const Vec3 e = sb.extent();
    const double hair =
        1e-9 * (std::max({e.x, e.y, e.z}) + std::max(glm::length(sb.lo), glm::length(sb.hi)));
    double best = kTurnedAreaShare * out.worldArea;
    for (const Candidate& c : cands) {
        const GridFrame f = GridFrame::fromAxes(c.axes);
        // Each box starts as the primitive's own bounds in the frame, cut by the frame hull of
        // its world minimized box (both hold what of it can contribute), then minimized again.
        std::vector<Box3> start(scene.prims.size());
        for (uint32_t p : live)
            if (!scene.minBox[p].isEmpty())
                start[p] = overlap(frameBoxOf(scene.prims[p], f, hair),
                                   frameHull(scene.minBox[p], f, hair));
        MinimizedBoxes mb = minimizeBoxes(scene.tree, std::move(start));
        double a = 0.0;
        Box3 bounds = Box3::empty();
        for (uint32_t p : live) {
            if (mb.box[p].isEmpty()) continue;
            a += surfaceArea(mb.box[p]);
            bounds.expand(mb.box[p]);
        }
        if (a < best) {
            best = a;
            out.frame = f;
            out.boxes = std::move(mb.box);
            out.bounds = bounds;
            out.frameArea = a;
        }
    }
    return out;
}

}  // namespace lancer
