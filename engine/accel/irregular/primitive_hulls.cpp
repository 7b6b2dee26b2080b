#include "engine/accel/irregular/primitive_hulls.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "engine/accel/build_guard.h"
#include "engine/accel/irregular/screen_bsp.h"
#include "engine/util/huge_pages.h"

namespace lancer {

namespace {

/// A convex polygon being clipped, each vertex with the corner of its box it is (-1: a point
/// clipping made): a quad cut by at most 15 planes has at most 19 vertices.
struct Poly {
    std::array<Vec3, 24> v;
    std::array<int, 24> corner;
    int n = 0;
};

/// Keeps the part of `in` where n . x <= d (Sutherland-Hodgman), in `out` or, when it keeps every
/// vertex, in `in` itself: the polygon returned holds the result. Each vertex's n . x - d is
/// computed once, a corner's taken from cornerDist (null: computed), and a polygon wholly within
/// or wholly beyond the plane is not walked: the same vertices, in the same order, as the walk.
Poly* clip(Poly* in, Poly* out, const Vec3& n, double d, const double* cornerDist) {
    double dist[24];
    int within = 0, beyond = 0;
    for (int i = 0; i < in->n; ++i) {
        dist[i] = cornerDist && in->corner[i] >= 0 ? cornerDist[in->corner[i]]
                                                   : glm::dot(n, in->v[i]) - d;
        within += dist[i] <= 0.0;
        beyond += dist[i] > 0.0;
    }
    if (within == in->n) return in;
    out->n = 0;
    if (beyond == in->n) return out;
    for (int i = 0; i < in->n; ++i) {
        const int j = i + 1 == in->n ? 0 : i + 1;
        const double da = dist[i], db = dist[j];
        if (da <= 0.0) {
            out->v[out->n] = in->v[i];
            out->corner[out->n++] = in->corner[i];
        }
        if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
            const double s = da / (da - db);
            out->v[out->n] = in->v[i] + s * (in->v[j] - in->v[i]);
            out->corner[out->n++] = -1;
        }
    }
    return out;
}

/// Face f of a box with corners `corner` (f / 2 its axis, the high side when f is odd), its
/// vertices counterclockwise from its lowest corner as seen from outside.
template <class Corners>
void boxFace(const Corners& corner, int f, Poly& out) {
    const int axis = f / 2;
    const int u = 1 << ((axis + 1) % 3), v = 1 << ((axis + 2) % 3);
    const int base = (f % 2) << axis;
    const int c[4] = {base, base | u, base | u | v, base | v};
    out.n = 4;
    for (int i = 0; i < 4; ++i) {
        out.v[i] = corner[c[i]];
        out.corner[i] = c[i];
    }
}

/// Clips `in` by the box `other`'s planes, along each axis its high one then its low one (`spare`:
/// scratch); returns the polygon holding the result.
template <class Solid>
Poly* clipByBox(const Solid& other, Poly* in, Poly* spare) {
    auto by = [&](const Vec3& n, double d) {
        Poly* r = clip(in, spare, n, d, nullptr);
        if (r != in) spare = in, in = r;
    };
    for (int k = 0; k < 3 && in->n; ++k) {
        by(other.axis[k], other.hi[k]);
        if (!in->n) break;
        by(-other.axis[k], -other.lo[k]);
    }
    return in;
}

/// The frame of a flat primitive (a triangle or a polygon) whose plane is turned off the
/// world's axes: its first edge, the normal (Newell's sum over its world vertices) and their
/// cross product. None for other shapes and for planes along the world's axes, whose world box
/// is already as flat.
std::optional<GridFrame> flatFrame(const Primitive& prim) {
    std::vector<Vec3> v;
    if (const Triangle* t = std::get_if<Triangle>(&prim.shape))
        v.assign(t->p, t->p + 3);
    else if (const Polygon* g = std::get_if<Polygon>(&prim.shape))
        v = g->p;
    else
        return std::nullopt;
    if (prim.hasXf)
        for (Vec3& q : v) q = prim.xf.point(q);
    Vec3 n(0.0);
    for (size_t i = 0; i < v.size(); ++i) n += glm::cross(v[i], v[(i + 1) % v.size()]);
    const double ln = glm::length(n);
    const Vec3 e = v[1] - v[0];
    const double le = glm::length(e);
    if (!(ln > 0.0) || !(le > 0.0) || !std::isfinite(ln) || !std::isfinite(le)) return std::nullopt;
    n /= ln;
    const Vec3 a = glm::abs(n);
    if (std::max({a.x, a.y, a.z}) > 1.0 - 1e-9) return std::nullopt;  // along the world's axes
    const Vec3 u = glm::normalize(e - glm::dot(e, n) * n);
    return GridFrame::fromAxes(Mat3(u, glm::cross(n, u), n));
}

/// The column's planes n . x <= d (depthIn): the rectangle [lo, hi] swept along z (its four
/// sides, x >= lo.x, x <= hi.x, y >= lo.y, y <= hi.y), or the rays from the eye through it
/// (u0 <= x / z <= u1 .. for z > 0) and z >= zNear. Returns how many (4 or 5).
int columnPlanes(ZoneColumn column, glm::dvec2 lo, glm::dvec2 hi, double zNear,
                 std::array<Vec3, 5>& cn, std::array<double, 5>& cd) {
    if (column == ZoneColumn::Parallel) {
        cn = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 1, 0), Vec3(0)};
        cd = {-lo.x, hi.x, -lo.y, hi.y, 0.0};
        return 4;
    }
    cn = {Vec3(-1, 0, lo.x), Vec3(1, 0, -hi.x), Vec3(0, -1, lo.y), Vec3(0, 1, -hi.y),
          Vec3(0, 0, -1)};
    cd = {0.0, 0.0, 0.0, 0.0, -zNear};
    return 5;
}

}  // namespace

PrimitiveHulls PrimitiveHulls::make(const Scene& scene, const CameraFrame& frame,
                                    const FrameChoice& turned, const std::vector<uint32_t>& live,
                                    double pad, const BuildGuard* guard, size_t maxFaceBytes) {
    PrimitiveHulls h;
    // A box along the world-frame axes `axes` (columns) in the camera frame: a rotation keeps it
    // a box, its planes along the camera images of those axes, offset by the eye's position.
    auto solid = [&](const Box3& b, const Mat3& axes) {
        Solid s;
        const Box3 w{b.lo - Vec3(pad), b.hi + Vec3(pad)};
        for (int a = 0; a < 3; ++a) {
            s.axis[a] = frame.vector(axes[a]);
            const double o = glm::dot(axes[a], frame.origin);
            s.lo[a] = w.lo[a] - o;
            s.hi[a] = w.hi[a] - o;
        }
        for (int c = 0; c < 8; ++c) s.corner[c] = frame.point(axes * boxCorner(w, c));
        return s;
    };
    // A frame along the world's axes (each axis one world axis, either way: a light's frame)
    // keeps a world box a box along its own axes.
    auto worldAxis = [](const Vec3& a) {
        const Vec3 m = glm::abs(a);
        return (m.x == 1.0 && m.y == 0.0 && m.z == 0.0) ||
               (m.x == 0.0 && m.y == 1.0 && m.z == 0.0) || (m.x == 0.0 && m.y == 0.0 && m.z == 1.0);
    };
    const bool alongWorld = worldAxis(frame.x) && worldAxis(frame.y) && worldAxis(frame.z);
    h.index_.assign(scene.prims.size(), -1);
    // One hull a live primitive, in one buffer written once (grown by doubling, each copy was
    // fresh pages: PrimitiveHulls::make took 41% of the irregular build's page faults on
    // balls4; docs/irregular.md, "Freed memory kept, and the hulls in one buffer").
    reserveHuge(h.hulls_, live.size());
    size_t made = 0;
    bool keep = maxFaceBytes > 0;  // faces clipped by the other box are still kept
    for (uint32_t p : live) {
        // About a microsecond a primitive: balls:5's 66,430 took a cancellation past 100 ms.
        if (guard && (made++ & 1023) == 0) guard->poll();
        if (scene.minBox[p].isEmpty()) continue;
        Hull hull;
        if (turned.frame.turned && !turned.boxes[p].isEmpty()) {
            hull.turned = solid(turned.boxes[p], turned.frame.axes);
        } else if (const std::optional<GridFrame> own = flatFrame(scene.prims[p])) {
            // A flat primitive along its own plane: a box as thin as its vertices lie, widened
            // by twice that thickness, since a polygon's hits lie on its fitted plane, which its
            // rounded vertices (an NFF file's few digits) leave by up to that much, and its
            // inside test projects along a world axis (at most sqrt(3) times it in the plane).
            const Box3 b = frameBoxOf(scene.prims[p], *own, 0.0);
            const double thick = 2.0 * (b.hi.z - b.lo.z);
            hull.turned = solid({b.lo - Vec3(thick), b.hi + Vec3(thick)}, own->axes);
        } else {
            // Its world box alone: seen from a camera off the world's axes, a box's depths over
            // a small zone are much narrower than over the whole box (a gear's flat face seen
            // obliquely).
            hull.single = true;
        }
        hull.world = solid(scene.minBox[p], Mat3(1.0));
        if (hull.single && alongWorld) {
            hull.aligned = true;
            for (const Vec3& q : hull.world.corner) hull.box.expand(q);
        }
        // A box of its own within the world box (a turned scene's bar, whose world box is its
        // bound) is the hull alone: the two boxes' common part is it, up to the padding, by
        // which its corners may leave the world box (padded along other axes); taken alone,
        // its ranges are wider than the common part's by at most that.
        if (!hull.single) {
            bool within = true;
            for (const Vec3& q : hull.turned.corner)
                for (int a = 0; a < 3 && within; ++a) {
                    const double x = glm::dot(hull.world.axis[size_t(a)], q);
                    within = x >= hull.world.lo[a] - 2.0 * pad && x <= hull.world.hi[a] + 2.0 * pad;
                }
            if (within) {
                hull.world = hull.turned;
                hull.single = true;
            }
        }
        // An aligned hull's outline is its box's, tested in closed form (touches).
        std::vector<glm::dvec2> flat, eye;
        bool front = !hull.aligned;
        for (const Vec3& c : (hull.single ? hull.world : hull.turned).corner) {
            if (hull.aligned) break;
            flat.push_back({c.x, c.y});
            front = front && c.z > 0.0;
            if (front) eye.push_back({c.x / c.z, c.y / c.z});
        }
        for (int c = 0; c < 2; ++c) {
            std::vector<glm::dvec2> o;
            if (c == 0 && !hull.aligned) o = convexHull2(flat);
            if (c == 1 && front) o = convexHull2(eye);
            hull.outlineSize[c] = int(o.size());  // the hull of 8 points: at most 8
            std::copy(o.begin(), o.end(), hull.outline[c].begin());
            hull.outlineLo[c] = glm::dvec2(kInf);
            hull.outlineHi[c] = glm::dvec2(-kInf);
            for (glm::dvec2 q : o) {
                hull.outlineLo[c] = glm::min(hull.outlineLo[c], q);
                hull.outlineHi[c] = glm::max(hull.outlineHi[c], q);
            }
        }
        // Two boxes: each face of one clipped by the other is the same for every zone (depthIn
        // clips it by the zone's column after), so it is clipped once here, and kept while the
        // kept faces stay within maxFaceBytes (checked before they are added, the vector's
        // doubling counted).
        if (!hull.single && keep) {
            Poly face[12], spare;
            size_t count = 0;
            for (int f = 0; f < 12; ++f) {
                boxFace((f < 6 ? hull.world : hull.turned).corner, f % 6, face[f]);
                const Poly* r = clipByBox(f < 6 ? hull.turned : hull.world, &face[f], &spare);
                if (r != &face[f]) face[f] = *r;
                count += size_t(face[f].n);
            }
            if (2 * (h.faceVerts_.size() + count) * sizeof(FaceVertex) <= maxFaceBytes) {
                hull.faceFirst = uint32_t(h.faceVerts_.size());
                for (int f = 0; f < 12; ++f) {
                    hull.faceSize[size_t(f)] = uint8_t(face[f].n);
                    for (int i = 0; i < face[f].n; ++i)
                        h.faceVerts_.push_back({face[f].v[size_t(i)], face[f].corner[size_t(i)]});
                }
                ++h.keptFaces_;
            } else {
                keep = false;
            }
        }
        h.index_[p] = int32_t(h.hulls_.size());
        h.hulls_.push_back(std::move(hull));
    }
    h.faceVerts_.shrink_to_fit();
    for (const Hull& hull : h.hulls_)
        for (int s = 0; s < (hull.single ? 1 : 2); ++s)
            for (const Vec3& q : (s == 0 ? hull.world : hull.turned).corner)
                h.finite_ =
                    h.finite_ && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
    return h;
}

glm::dvec2 PrimitiveHulls::alignedDepth(const Box3& b, ZoneColumn column, glm::dvec2 lo,
                                        glm::dvec2 hi, double zNear) {
    constexpr glm::dvec2 kMiss(kInf, -kInf);
    if (column == ZoneColumn::Parallel)
        return b.lo.x > hi.x || b.hi.x < lo.x || b.lo.y > hi.y || b.hi.y < lo.y
                   ? kMiss
                   : glm::dvec2(b.lo.z, b.hi.z);
    // The rays from the eye through [lo, hi] at depth z > 0 cover [lo z, hi z] in x and y: the
    // box's points there, if any, are where lo.x z <= b.hi.x and hi.x z >= b.lo.x (and in y),
    // each a half-line of depths. The extremes are those of the box cut by the column, whose
    // sides are planes: a face of the box or a column side holds them, as clipping finds.
    double z0 = std::max(b.lo.z, zNear), z1 = b.hi.z;
    for (int k = 0; k < 2; ++k) {
        // lo[k] z <= b.hi[k]
        if (lo[k] > 0.0)
            z1 = std::min(z1, b.hi[k] / lo[k]);
        else if (lo[k] < 0.0)
            z0 = std::max(z0, b.hi[k] / lo[k]);
        else if (b.hi[k] < 0.0)
            return kMiss;
        // hi[k] z >= b.lo[k]
        if (hi[k] > 0.0)
            z0 = std::max(z0, b.lo[k] / hi[k]);
        else if (hi[k] < 0.0)
            z1 = std::min(z1, b.lo[k] / hi[k]);
        else if (b.lo[k] > 0.0)
            return kMiss;
    }
    return z0 <= z1 ? glm::dvec2(z0, z1) : kMiss;
}

bool PrimitiveHulls::touches(uint32_t p, ZoneColumn column, glm::dvec2 lo, glm::dvec2 hi) const {
    if (index_.empty() || index_[p] < 0) return true;
    const Hull& h = hulls_[index_[p]];
    // In front of the eye, the rectangle meets the box's outline where the rays through it meet
    // the box. The quotients' rounding (a few ulps of the depth) is kept on the side of meeting.
    if (h.aligned && (column == ZoneColumn::Parallel || h.box.lo.z > 0.0)) {
        const glm::dvec2 d = alignedDepth(h.box, column, lo, hi, 0.0);
        return d.x <= d.y + 1e-12 * std::abs(d.y);
    }
    const std::array<glm::dvec2, 8>& o = h.outline[int(column)];
    const size_t n = size_t(h.outlineSize[int(column)]);
    if (n < 3) return true;
    // Separating axes of two convex polygons: the rectangle's (its bound against the outline's)
    // and each outline edge's outward normal, the rectangle's nearest corner beyond it.
    const glm::dvec2 olo = h.outlineLo[int(column)], ohi = h.outlineHi[int(column)];
    if (olo.x > hi.x || ohi.x < lo.x || olo.y > hi.y || ohi.y < lo.y) return false;
    return convexMeetsRect(o.data(), n, lo, hi);
}

glm::dvec2 PrimitiveHulls::depthIn(uint32_t p, ZoneColumn column, glm::dvec2 lo, glm::dvec2 hi,
                                   double zNear, glm::dvec2 whole) const {
    if (index_.empty() || index_[p] < 0) return whole;
    const Hull& h = hulls_[index_[p]];
    if (h.aligned && (column == ZoneColumn::Parallel || zNear > 0.0)) {
        const glm::dvec2 d = alignedDepth(h.box, column, lo, hi, zNear);
        return {std::max(d.x, whole.x), std::min(d.y, whole.y)};
    }
    std::array<Vec3, 5> cn;
    std::array<double, 5> cd;
    const int planes = columnPlanes(column, lo, hi, zNear, cn, cd);
    // A column plane that every corner of a box lies within cuts nothing from it; one that
    // every corner lies beyond leaves nothing (both boxes are convex). The corners' n . x - d
    // are kept for the clipping below.
    const int solids = h.single ? 1 : 2;
    const Solid* solid[2] = {&h.world, &h.turned};
    std::array<bool, 5> cuts{};
    double cornerDist[2][5][8];
    int beyond[2][5] = {};
    for (int s = 0; s < solids; ++s) {
        const std::array<Vec3, 8>& corner = solid[s]->corner;
        if (!finite_) {
            for (int k = 0; k < planes; ++k)
                for (int c = 0; c < 8; ++c)
                    cornerDist[s][k][c] = glm::dot(cn[k], corner[size_t(c)]) - cd[k];
        } else if (column == ZoneColumn::Parallel) {
            // The planes' products by 0 and 1 written out: glm::dot's sums are these numbers
            // (their signs of zero aside, which only the comparisons below and the clipping's
            // interpolation between distances of opposite signs read), a third of its work.
            for (int c = 0; c < 8; ++c) {
                const Vec3& q = corner[size_t(c)];
                cornerDist[s][0][c] = lo.x - q.x;
                cornerDist[s][1][c] = q.x - hi.x;
                cornerDist[s][2][c] = lo.y - q.y;
                cornerDist[s][3][c] = q.y - hi.y;
            }
        } else {
            for (int c = 0; c < 8; ++c) {
                const Vec3& q = corner[size_t(c)];
                cornerDist[s][0][c] = lo.x * q.z - q.x;
                cornerDist[s][1][c] = q.x - hi.x * q.z;
                cornerDist[s][2][c] = lo.y * q.z - q.y;
                cornerDist[s][3][c] = q.y - hi.y * q.z;
                cornerDist[s][4][c] = zNear - q.z;
            }
        }
        for (int k = 0; k < planes; ++k)
            for (int c = 0; c < 8; ++c) beyond[s][k] += cornerDist[s][k][c] > 0.0;
    }
    for (int k = 0; k < planes; ++k) {
        for (int s = 0; s < solids; ++s) {
            if (beyond[s][k] == 8) return {whole.x, -kInf};
            cuts[k] = cuts[k] || beyond[s][k] > 0;
        }
    }
    if (h.single) return singleBoxDepth(h.world, column, lo, hi, zNear, cornerDist[0], cuts, whole);
    // The extremes in depth of the solid (both boxes and the column) lie on a face of one of
    // the boxes: the column is unbounded in depth (beyond zNear, handled below), so its sides
    // alone hold no extreme. Each face is clipped by the other box (kept from make, or here)
    // and the column.
    glm::dvec2 range(kInf, -kInf);
    Poly a, b;
    const FaceVertex* kept = h.faceFirst == UINT32_MAX ? nullptr : faceVerts_.data() + h.faceFirst;
    for (int s = 0; s < solids; ++s) {
        for (int f = 0; f < 6; ++f) {
            Poly* in = &a;
            Poly* spare = &b;
            if (kept) {
                a.n = h.faceSize[size_t(6 * s + f)];
                for (int i = 0; i < a.n; ++i, ++kept) {
                    a.v[size_t(i)] = kept->p;
                    a.corner[size_t(i)] = kept->corner;
                }
            } else {
                boxFace(solid[s]->corner, f, a);
                if (!h.single) in = clipByBox(*solid[1 - s], &a, &b);
                spare = in == &a ? &b : &a;
            }
            for (int k = 0; k < planes && in->n; ++k) {
                if (!cuts[k]) continue;
                Poly* r = clip(in, spare, cn[k], cd[k], cornerDist[s][k]);
                if (r != in) spare = in, in = r;
            }
            for (int i = 0; i < in->n; ++i) {
                range.x = std::min(range.x, in->v[size_t(i)].z);
                range.y = std::max(range.y, in->v[size_t(i)].z);
            }
        }
    }
    // From the eye, the plane z = zNear closes the column: where the boxes reach in front of
    // it, the solid's nearest points may lie on that plane, inside both boxes.
    if (column == ZoneColumn::FromEye && range.x <= range.y) {
        for (int s = 0; s < solids; ++s)
            for (const Vec3& c : solid[s]->corner)
                if (c.z < zNear) range.x = zNear;
    }
    return {std::max(range.x, whole.x), std::min(range.y, whole.y)};
}

glm::dvec2 PrimitiveHulls::singleBoxDepth(const Solid& b, ZoneColumn column, glm::dvec2 lo,
                                          glm::dvec2 hi, double zNear, const double (&dist)[5][8],
                                          const std::array<bool, 5>& cuts, glm::dvec2 whole) {
    // The solid (the box and the column's sides) is convex: its extremes in depth are among its
    // vertices, each where three of the planes meet. Three of the box's: a corner within the
    // column. Two of the box's and a side: a box edge crossing that side, within the others.
    // One of the box's and two sides: a column edge (a line along the column) where it enters
    // or leaves the box. Three sides meet only at the eye, on every column edge. These are the
    // vertices clipping the box's six faces by the column ends with, found without the polygons
    // (about half the instructions on balls4's spheres seen from the eye), equal up to rounding,
    // which the slabs' padding is far above.
    glm::dvec2 range(kInf, -kInf);
    auto take = [&](double z) {
        range.x = std::min(range.x, z);
        range.y = std::max(range.y, z);
    };
    const bool anyCut = cuts[0] || cuts[1] || cuts[2] || cuts[3];
    for (int c = 0; c < 8; ++c) {
        bool within = true;
        for (int k = 0; k < 4 && within; ++k) within = !cuts[k] || dist[k][c] <= 0.0;
        if (within) take(b.corner[size_t(c)].z);
    }
    if (anyCut) {
        // A crossing point within another side up to the rounding of its distance (a vertex on
        // two sides at once is also a column edge's, found below).
        double tol[4];
        for (int k = 0; k < 4; ++k) {
            double m = 0.0;
            for (int c = 0; c < 8; ++c) m = std::max(m, std::abs(dist[k][c]));
            tol[k] = 1e-12 * m;
        }
        for (int a = 0; a < 3; ++a) {
            for (int c0 = 0; c0 < 8; ++c0) {
                if (c0 >> a & 1) continue;
                const int c1 = c0 | 1 << a;
                for (int k = 0; k < 4; ++k) {
                    if (!cuts[k]) continue;
                    const double d0 = dist[k][c0], d1 = dist[k][c1];
                    if (!((d0 < 0.0 && d1 > 0.0) || (d0 > 0.0 && d1 < 0.0))) continue;
                    const double s = d0 / (d0 - d1);
                    bool within = true;
                    for (int j = 0; j < 4 && within; ++j)
                        within = j == k || !cuts[j] ||
                                 dist[j][c0] + s * (dist[j][c1] - dist[j][c0]) <= tol[j];
                    if (within)
                        take(b.corner[size_t(c0)].z +
                             s * (b.corner[size_t(c1)].z - b.corner[size_t(c0)].z));
                }
            }
        }
        // The column's four edges: parallel to z through the rectangle's corners, or from the
        // eye through them; z is the line's parameter either way.
        const bool parallel = column == ZoneColumn::Parallel;
        for (int i = 0; i < 4; ++i) {
            const double u = i & 1 ? hi.x : lo.x, v = i & 2 ? hi.y : lo.y;
            const Vec3 base = parallel ? Vec3(u, v, 0.0) : Vec3(0.0);
            const Vec3 dir = parallel ? Vec3(0.0, 0.0, 1.0) : Vec3(u, v, 1.0);
            double t0 = parallel ? -kInf : 0.0, t1 = kInf;
            for (int a = 0; a < 3 && t0 <= t1; ++a) {
                const double an = glm::dot(b.axis[size_t(a)], dir);
                const double ab = glm::dot(b.axis[size_t(a)], base);
                if (an == 0.0) {
                    if (ab < b.lo[a] || ab > b.hi[a]) t0 = kInf;
                    continue;
                }
                double ta = (b.lo[a] - ab) / an, tb = (b.hi[a] - ab) / an;
                if (ta > tb) std::swap(ta, tb);
                t0 = std::max(t0, ta);
                t1 = std::min(t1, tb);
            }
            if (t0 <= t1) {
                take(t0);
                take(t1);
            }
        }
    }
    // From the eye, the plane z = zNear closes the column (depthIn's clipping): where a corner
    // lies in front of it, the solid's nearest points beyond it are taken to be on it.
    if (column == ZoneColumn::FromEye && cuts[4] && range.x <= range.y) {
        if (range.y < zNear) return {whole.x, -kInf};
        range.x = zNear;
    }
    return {std::max(range.x, whole.x), std::min(range.y, whole.y)};
}

std::vector<glm::dvec2> narrowZones(ScreenBsp& bsp, const PrimitiveHulls& hulls, ZoneColumn column,
                                    const std::vector<Box3>& box, double zlo, double zhi,
                                    double pad, const BuildGuard* guard) {
    std::vector<glm::dvec2> depth;
    depth.reserve(bsp.zonePrims.size());
    auto whole = [&](uint32_t p) {
        return glm::dvec2(std::clamp(box[p].lo.z, zlo, zhi), std::clamp(box[p].hi.z, zlo, zhi));
    };
    if (hulls.empty()) {
        for (uint32_t p : bsp.zonePrims) depth.push_back(whole(p));
        return depth;
    }
    size_t kept = 0;
    uint32_t first = 0;
    for (size_t z = 0; z < bsp.zoneCount(); ++z) {
        // Each reference's range clips its boxes' faces: a cancellation must not wait for all.
        if (guard && (z & 255) == 0) guard->poll();
        // The column widened beyond the rounding of where a ray's point falls: the padding in
        // the camera frame, a billionth of the coordinate from the eye.
        glm::dvec2 lo = bsp.zoneLo[z], hi = bsp.zoneHi[z];
        for (int k = 0; k < 2; ++k) {
            const double wl =
                column == ZoneColumn::Parallel ? pad : 1e-9 * std::max(1.0, std::abs(lo[k]));
            const double wh =
                column == ZoneColumn::Parallel ? pad : 1e-9 * std::max(1.0, std::abs(hi[k]));
            lo[k] -= wl;
            hi[k] += wh;
        }
        const uint32_t end = bsp.zoneFirst[z + 1];
        for (uint32_t i = first; i < end; ++i) {
            const uint32_t p = bsp.zonePrims[i];
            glm::dvec2 d = hulls.depthIn(p, column, lo, hi, zlo, whole(p));
            if (!(d.x <= d.y)) continue;  // the hull misses the zone's column
            d = {std::clamp(d.x - pad, zlo, zhi), std::clamp(d.y + pad, zlo, zhi)};
            // Never wider than the box: the hull is within it, the padding is not.
            d = {std::max(d.x, whole(p).x), std::min(d.y, whole(p).y)};
            bsp.zonePrims[kept++] = p;
            depth.push_back(d);
        }
        first = end;
        bsp.zoneFirst[z + 1] = uint32_t(kept);
    }
    bsp.zonePrims.resize(kept);
    return depth;
}

}  // namespace lancer
