#include "app/viewer/overlay/overlay_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/viewer/colormap.h"
#include "app/viewer/gl/transforms.h"
#include "engine/accel/irregular/irregular.h"
#include "engine/accel/regular/regular_grid.h"

namespace lancer::viewer::overlay {

namespace {

glm::vec3 toF(const Vec3& v) { return glm::vec3(v); }
std::array<glm::vec3, 8> toF(const std::array<Vec3, 8>& c) {
    std::array<glm::vec3, 8> f;
    for (size_t i = 0; i < 8; ++i) f[i] = toF(c[i]);
    return f;
}

/// A frame point (x, y) at depth z in world coordinates: the camera frame's (x, y, z), or the
/// projective (u, v, z), the camera point (u z, v z, z).
Vec3 frameToWorld(const CameraFrame& f, ZoneFrameKind kind, double x, double y, double z) {
    return kind == ZoneFrameKind::Camera ? f.toWorld({x, y, z}) : f.toWorld({x * z, y * z, z});
}

/// Whether a volume given by world corners may be seen in the image: its projected corners'
/// bounding rectangle meets the image, or a corner lies behind a perspective eye (kept).
bool mayBeVisible(const gl::ImageProjector& proj, const std::array<Vec3, 8>& c, int w, int h) {
    glm::dvec2 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    for (const Vec3& p : c) {
        const auto q = proj.toImage(p);
        if (!q) return true;
        lo = glm::min(lo, *q);
        hi = glm::max(hi, *q);
    }
    return hi.x >= 0.0 && hi.y >= 0.0 && lo.x <= w && lo.y <= h;
}

/// Entry parameter of a ray into a box (slab test); nothing when it misses.
std::optional<double> entry(const Box3& b, const Ray& r) {
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (r.d[a] == 0.0) {
            if (r.o[a] < b.lo[a] || r.o[a] > b.hi[a]) return std::nullopt;
            continue;
        }
        double ta = (b.lo[a] - r.o[a]) / r.d[a], tb = (b.hi[a] - r.o[a]) / r.d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    if (t0 > t1) return std::nullopt;
    return t0;
}

/// The count a cost colouring of kind `k` gives regions [lo, hi), noted in `g` for the key; 0
/// without counts.
uint64_t costOf(const RegionCosts* c, CostKind k, uint32_t lo, uint32_t hi, OverlayGeometry& g) {
    if (!c || k == CostKind::None || hi > c->regions()) return 0;
    const uint64_t v = k == CostKind::Visits ? c->visits(lo, hi) : c->tests(lo, hi);
    g.costMax = std::max(g.costMax, v);
    return v;
}

/// The depths the irregular frame's lines and fills are drawn at: one depth where every depth
/// projects alike (orthographic camera frame, projective), else the structure's near and far.
struct FrameDepths {
    double near = 1.0, far = 1.0;
    bool two = false;
};

FrameDepths frameDepths(const IrregularSubdivision& s, const ZoneFrameView& fr) {
    const Box3& b = s.bounds();
    FrameDepths d;
    const double lo = std::max(b.lo.z, 0.0), hi = std::max(b.hi.z, lo);
    if (fr.mapsToImage()) {
        d.near = d.far = lo + 0.5 * (hi - lo) > 0.0 ? lo + 0.5 * (hi - lo) : 1.0;
    } else {
        d.near = std::max(lo, 1e-3 * hi);
        d.far = hi;
        d.two = true;
    }
    return d;
}

void irregularLayers(const StructureView& sv, const gl::ImageProjector& proj, int w, int h,
                     const OverlayOptions& o, const RegionCosts* costs, OverlayGeometry& g) {
    const IrregularSubdivision& s = *sv.irregular();
    const ZoneFrameView* fr = overlayFrame(sv, o.projective);
    if (!fr) return;
    const CameraFrame& f = s.frame();
    const FrameDepths d = frameDepths(s, *fr);
    auto world = [&](glm::dvec2 p, double z) {
        return toF(frameToWorld(f, fr->kind(), p.x, p.y, z));
    };
    if (o.bsp) {
        const std::vector<BspCut> cuts = fr->cuts();
        g.cutsTotal = cuts.size();
        for (const BspCut& c : cuts) g.maxCutDepth = std::max(g.maxCutDepth, c.depth);
        g.linesPerCut = d.two ? 2 : 1;
        // Over the cap: the shallowest cuts (they cross the most of the image), still in the
        // order they were made, so the replay stays a replay.
        int deepest = g.maxCutDepth;
        if (cuts.size() > o.cap) {
            std::vector<size_t> perDepth(size_t(g.maxCutDepth) + 1);
            for (const BspCut& c : cuts) ++perDepth[size_t(c.depth)];
            size_t total = 0;
            deepest = -1;
            while (deepest < g.maxCutDepth && total + perDepth[size_t(deepest + 1)] <= o.cap)
                total += perDepth[size_t(++deepest)];
        }
        for (const BspCut& c : cuts) {
            if (c.depth > deepest) continue;
            const glm::vec3 col = levelColor(c.depth);
            g.noteLevel(c.depth);
            g.cuts.line(world(c.a, d.near), world(c.b, d.near), gl::rgba8(col));
            if (d.two) g.cuts.line(world(c.a, d.far), world(c.b, d.far), gl::rgba8(col * 0.6f));
        }
    }
    if (!o.zones && !o.slabs) return;
    // Zones that show in the image, in zone order, up to the cap.
    std::vector<uint32_t> shown;
    std::vector<std::array<glm::dvec2, 2>> rects;  // clipped, frame units
    g.zonesTotal = fr->zoneCount();
    glm::dvec2 clipLo = fr->rectLo(), clipHi = fr->rectHi();
    if (fr->mapsToImage()) {  // the image's rectangle in frame units (y up in the frame)
        const glm::dvec2 a = fr->fromPixel({0.0, 0.0}, w, h), b = fr->fromPixel({w, h}, w, h);
        clipLo = glm::max(clipLo, glm::min(a, b));
        clipHi = glm::min(clipHi, glm::max(a, b));
    }
    // Over the cap: the largest zones first (a zone's area in frame units; the smallest are
    // the ones a pixel or two wide).
    std::vector<uint32_t> order(fr->zoneCount());
    for (uint32_t z = 0; z < order.size(); ++z) order[z] = z;
    if (order.size() > o.cap) {
        auto area = [&](uint32_t z) {
            const glm::dvec2 e = fr->zoneHi(z) - fr->zoneLo(z);
            return e.x * e.y;
        };
        std::nth_element(order.begin(), order.begin() + std::ptrdiff_t(o.cap), order.end(),
                         [&](uint32_t a, uint32_t b) { return area(a) > area(b); });
        order.resize(o.cap);
        std::sort(order.begin(), order.end());
    }
    for (uint32_t z : order) {
        const glm::dvec2 lo = glm::max(fr->zoneLo(z), clipLo), hi = glm::min(fr->zoneHi(z), clipHi);
        if (!(lo.x < hi.x && lo.y < hi.y)) continue;
        if (!fr->mapsToImage()) {
            std::array<Vec3, 8> c;
            for (int i = 0; i < 8; ++i)
                c[size_t(i)] = frameToWorld(f, fr->kind(), (i & 1) ? hi.x : lo.x,
                                            (i & 2) ? hi.y : lo.y, (i & 4) ? d.far : d.near);
            if (!mayBeVisible(proj, c, w, h)) continue;
        }
        shown.push_back(z);
        rects.push_back({lo, hi});
    }
    g.zonesDrawn = shown.size();
    const CostKind zoneCost = costKindOf(o.zoneFill);
    if (o.zones && zoneCost != CostKind::None) {
        // By cost: a zone's slabs' counts; a zone no ray reached is drawn apart from the map.
        g.zoneCost = zoneCost;
        for (size_t i = 0; i < shown.size(); ++i) {
            const auto [lo, hi] = rects[i];
            const glm::vec3 quad[4] = {world(lo, d.near), world({hi.x, lo.y}, d.near),
                                       world(hi, d.near), world({lo.x, hi.y}, d.near)};
            const auto [r0, r1] = fr->zoneRegions(shown[i], shown[i] + 1);
            g.fills.fill(quad, gl::rgba8(costColor(double(costOf(costs, zoneCost, r0, r1, g)))));
        }
    } else if (o.zones) {
        std::vector<size_t> count(shown.size());
        for (size_t i = 0; i < shown.size(); ++i) {
            count[i] = o.zoneFill == ZoneFill::Prims ? fr->zonePrims(shown[i]).size()
                                                     : fr->slabs(shown[i]).size();
        }
        for (size_t i = 0; i < shown.size(); ++i) {
            const auto [lo, hi] = rects[i];
            const glm::vec3 quad[4] = {world(lo, d.near), world({hi.x, lo.y}, d.near),
                                       world(hi, d.near), world({lo.x, hi.y}, d.near)};
            // Empty zones stay clear; the others from the colour map's purple to its yellow.
            if (count[i] == 0) continue;
            g.fills.fill(quad, gl::rgba8(countColor(double(count[i]))));
            g.countMax = std::max(g.countMax, count[i]);
        }
    }
    if (o.slabs) {
        for (uint32_t z : shown) {
            const std::vector<SlabInfo> slabs = fr->slabs(z);
            for (size_t k = 0; k < slabs.size(); ++k) {
                if (!o.only.keeps(slabs[k].region)) continue;
                ++g.regionsTotal;
                if (g.regionsDrawn >= o.cap) break;
                const CostKind cost = costKindOf(o.slabColor);
                if (cost != CostKind::None) {
                    g.slabCost = cost;
                    const uint32_t r = slabs[k].region;
                    g.wires.box(toF(sv.regionCorners(r)),
                                gl::rgba8(costColor(double(costOf(costs, cost, r, r + 1, g)))));
                } else {
                    g.wires.box(toF(sv.regionCorners(slabs[k].region)),
                                gl::rgba8(levelColor(int(k))));
                    g.slabMax = std::max(g.slabMax, int(k));
                }
                ++g.regionsDrawn;
            }
        }
    }
}

void regularLayers(const StructureView& sv, const gl::ImageProjector& proj, int w, int h,
                   const OverlayOptions& o, const RegionCosts* costs, OverlayGeometry& g) {
    const RegularGrid& grid = *sv.regular();
    if (o.leaves) {
        const size_t n = grid.leaves().size();
        std::vector<uint32_t> picked;
        for (uint32_t i = 0; i < n; ++i) {
            const int level = sv.leafLevel(i);
            if (level < o.levelMin || level > o.levelMax || !o.only.keeps(i)) continue;
            ++g.regionsTotal;
            if (picked.size() >= o.cap) {
                g.cameraDependent = true;
                continue;
            }
            if (n > o.cap && !mayBeVisible(proj, sv.regionCorners(i), w, h)) {
                g.cameraDependent = true;
                continue;
            }
            picked.push_back(i);
        }
        const CostKind cost = costKindOf(o.leafColor);
        if (cost != CostKind::None) g.leafCost = cost;
        for (uint32_t i : picked) {
            const std::array<Vec3, 8> wc = sv.regionCorners(i);
            if (cost != CostKind::None) {
                g.wires.box(toF(wc),
                            gl::rgba8(costColor(double(costOf(costs, cost, i, i + 1, g)))));
                continue;
            }
            const glm::vec3 col = o.leafColor == LeafColor::Level
                                      ? levelColor(sv.leafLevel(i))
                                      : countColor(double(grid.leaves()[i].prims));
            if (o.leafColor == LeafColor::Level)
                g.noteLevel(sv.leafLevel(i));
            else
                g.countMax = std::max(g.countMax, size_t(grid.leaves()[i].prims));
            g.wires.box(toF(wc), gl::rgba8(col));
        }
        g.regionsDrawn += picked.size();
    }
    gl::Batch subTables, entries;
    if (o.grid) {
        const std::vector<DirectoryBlock> blocks = sv.directoryBlocks();
        for (const DirectoryBlock& blk : blocks) {
            if (blk.level < o.levelMin || blk.level > o.levelMax) continue;
            ++g.regionsTotal;
            if (g.regionsDrawn >= o.cap) continue;
            // By kind: sub-table blocks in orange, single entries in grey-blue.
            const glm::vec3 col = o.gridColor == GridColor::Level        ? levelColor(blk.level)
                                  : o.gridColor == GridColor::TableDepth ? levelColor(blk.depth)
                                  : blk.subTable ? glm::vec3(1.0f, 0.55f, 0.1f)
                                                 : glm::vec3(0.55f, 0.65f, 0.8f);
            if (o.gridColor == GridColor::Level) g.noteLevel(blk.level);
            if (o.gridColor == GridColor::TableDepth) g.noteLevel(blk.depth);
            (blk.subTable ? subTables : entries)
                .box(toF(sv.gridCorners(blk.lo, blk.hi)), gl::rgba8(col));
            ++g.regionsDrawn;
        }
    }
    // Neighbouring boxes share faces, so most edges lie on others of the same colour: joined
    // once per structure and options, they make far fewer and shorter lines for each redraw of
    // the layer after a camera change, whose cost under llvmpipe is the lines'.
    gl::Batch leaves = gl::mergeCollinearLines(g.wires);
    if (!o.grid) {
        g.wires = std::move(leaves);
        return;
    }
    // Where layers share an edge, one colour is drawn: a sub-table's outline over the leaves'
    // and the entries', a leaf's over an entry's. Drawn over one another, the pale entries
    // (most of the grid's lines lie on leaf faces) hid the leaves' level colours; now an entry
    // line shows only where the table cuts a leaf.
    subTables = gl::mergeCollinearLines(subTables);
    gl::Batch under = leaves;
    under.lines.insert(under.lines.end(), subTables.lines.begin(), subTables.lines.end());
    entries = gl::subtractCovered(gl::mergeCollinearLines(entries), under);
    leaves = gl::subtractCovered(leaves, subTables);
    g.wires = std::move(leaves);
    for (const gl::Batch* b : {&entries, &subTables})
        g.wires.lines.insert(g.wires.lines.end(), b->lines.begin(), b->lines.end());
}

/// The BVH's node boxes ("leaves" layer): every node whose depth lies in the level range, the
/// visible ones first under the cap, coloured by depth or by the primitives a leaf lists.
void bvhLayer(const StructureView& sv, const gl::ImageProjector& proj, int w, int h,
              const OverlayOptions& o, const RegionCosts* costs, OverlayGeometry& g) {
    const Bvh& bvh = *sv.bvh();
    const std::vector<BvhNode>& nodes = bvh.nodes();
    std::vector<uint32_t> picked;
    for (uint32_t i = 0; i < nodes.size(); ++i) {
        const int depth = nodes[i].depth;
        if (depth < o.levelMin || depth > o.levelMax || !o.only.keeps(i)) continue;
        ++g.regionsTotal;
        if (picked.size() >= o.cap) {
            g.cameraDependent = true;
            continue;
        }
        if (nodes.size() > o.cap && !mayBeVisible(proj, sv.regionCorners(i), w, h)) {
            g.cameraDependent = true;
            continue;
        }
        picked.push_back(i);
    }
    const CostKind cost = costKindOf(o.leafColor);
    if (cost != CostKind::None) g.leafCost = cost;
    for (uint32_t i : picked) {
        const BvhNode& n = nodes[i];
        if (cost != CostKind::None) {
            // A node's own count: an inner node is entered (visits) but tests nothing.
            g.wires.box(toF(sv.regionCorners(i)),
                        gl::rgba8(costColor(double(costOf(costs, cost, i, i + 1, g)))));
            continue;
        }
        const glm::vec3 col = o.leafColor == LeafColor::Level
                                  ? levelColor(n.depth)
                                  : countColor(double(n.leaf ? n.count : 0));
        if (o.leafColor == LeafColor::Level)
            g.noteLevel(n.depth);
        else
            g.countMax = std::max(g.countMax, size_t(n.leaf ? n.count : 0));
        g.wires.box(toF(sv.regionCorners(i)), gl::rgba8(col));
    }
    g.regionsDrawn += picked.size();
}

}  // namespace

const ZoneFrameView* overlayFrame(const StructureView& sv, bool projective) {
    if (projective)
        if (const ZoneFrameView* p = sv.frame(ZoneFrameKind::Projective)) return p;
    return sv.frame(ZoneFrameKind::Camera);
}

std::pair<double, double> clipDepths(const StructureView& sv, const Camera& view) {
    const std::array<Vec3, 8> c = sv.structureCorners();
    Vec3 f, r, u;
    view.basis(f, r, u);
    double far = 0.0, near = std::numeric_limits<double>::infinity(), size = 0.0;
    for (const Vec3& p : c) {
        const double z = glm::dot(p - view.from, f);
        far = std::max(far, z);
        near = std::min(near, z);
        size = std::max(size, glm::length(p - c[0]));
    }
    far = far * 1.01 + 1e-6 * size + 1e-9;
    if (view.projection == Projection::Orthographic)
        return {std::min(near, 0.0) - 0.01 * size - 1e-9, far};
    return {std::max(far * 1e-5, 1e-9), far};
}

const char* costKindName(CostKind k) {
    switch (k) {
        case CostKind::None:
            break;
        case CostKind::Visits:
            return "region visits";
        case CostKind::Tests:
            return "prim tests";
    }
    return "";
}

OverlayGeometry buildOverlayGeometry(const StructureView& sv, const Camera& view, int width,
                                     int height, const OverlayOptions& options,
                                     const RegionCosts* costs) {
    OverlayGeometry g;
    if (width <= 0 || height <= 0) return g;
    if (costs && costs->regions() != sv.regionCount()) costs = nullptr;  // another structure's
    g.costsKnown = costs != nullptr;
    const gl::ImageProjector proj(view, width, height);
    if (sv.irregular() && (options.bsp || options.zones || options.slabs))
        irregularLayers(sv, proj, width, height, options, costs, g);
    if (sv.regular() && (options.leaves || options.grid))
        regularLayers(sv, proj, width, height, options, costs, g);
    if (sv.bvh() && options.leaves) bvhLayer(sv, proj, width, height, options, costs, g);
    // The longest lines show the structure's coarse shape: drawn first while the camera moves.
    std::vector<size_t> order(g.wires.lineCount());
    for (size_t k = 0; k < order.size(); ++k) order[k] = k;
    auto length2 = [&](size_t k) {
        const glm::vec3 d = g.wires.lines[2 * k + 1].position - g.wires.lines[2 * k].position;
        return glm::dot(d, d);
    };
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return length2(a) > length2(b); });
    g.wiresLongestFirst.lines.reserve(g.wires.lines.size());
    for (size_t k : order) {
        g.wiresLongestFirst.lines.push_back(g.wires.lines[2 * k]);
        g.wiresLongestFirst.lines.push_back(g.wires.lines[2 * k + 1]);
    }
    return g;
}

double DepthStrip::at(double z) const {
    if (slabs.empty() || !(z > z0())) return 0.0;
    if (!(z < z1())) return 1.0;
    size_t k = 0;
    while (k + 1 < slabs.size() && z > slabs[k].z1) ++k;
    const Slab& s = slabs[k];
    const double in = s.z1 > s.z0 ? std::clamp((z - s.z0) / (s.z1 - s.z0), 0.0, 1.0) : 0.0;
    return (double(k) + in) / double(slabs.size());
}

DepthStrip depthStrip(const ZoneFrameView& fr, uint32_t zone, std::optional<double> depth,
                      std::optional<uint32_t> region) {
    DepthStrip strip;
    if (zone >= fr.zoneCount()) return strip;
    for (const SlabInfo& s : fr.slabs(zone)) {
        if (region ? s.region == *region : depth && *depth >= s.z0 && *depth <= s.z1)
            if (strip.current < 0) strip.current = int(strip.slabs.size());
        strip.slabs.push_back({s.region, s.z0, s.z1, s.prims.size()});
    }
    return strip;
}

std::optional<PickResult> pick(const StructureView& sv, const Camera& view, int width, int height,
                               double x, double y, float depth, bool projective) {
    if (width <= 0 || height <= 0 || x < 0.0 || y < 0.0 || x > width || y > height)
        return std::nullopt;
    const Ray ray = view.primaryRay(x - 0.5, y - 0.5, width, height);
    const bool hit = std::isfinite(depth);
    PickResult out;
    if (const IrregularSubdivision* s = sv.irregular()) {
        const ZoneFrameView* fr = overlayFrame(sv, projective);
        if (fr && fr->kind() == ZoneFrameKind::Projective) {
            // Primary rays walk the projective zones: the zone under the pixel, the slab at the
            // hit's depth (the first one on a miss: where the ray enters).
            const int64_t z = fr->zoneAtPixel(x, y, width, height);
            if (z < 0) return std::nullopt;
            const std::vector<SlabInfo> slabs = fr->slabs(uint32_t(z));
            if (slabs.empty()) return std::nullopt;
            const double dz = hit ? double(depth) * glm::dot(ray.d, s->frame().z) : slabs[0].z0;
            size_t k = 0;
            while (k + 1 < slabs.size() && dz > slabs[k].z1) ++k;
            out.region = slabs[k].region;
            out.zone = z;
            out.frame = ZoneFrameKind::Projective;
            if (hit) out.frameDepth = dz;
            return out;
        }
        const Ray rc = s->frame().ray(ray);
        std::optional<double> t = hit ? std::optional<double>(depth) : entry(s->bounds(), rc);
        if (!t) return std::nullopt;
        out.region = sv.regionAt(ray.at(*t));
        out.zone = sv.region(out.region).zone;
        out.frame = ZoneFrameKind::Camera;
        return out;
    }
    std::optional<double> t = hit ? std::optional<double>(depth) : entry(sv.worldBounds(), ray);
    if (!t) return std::nullopt;
    out.region = sv.regionAt(ray.at(*t));
    return out;
}

}  // namespace lancer::viewer::overlay
