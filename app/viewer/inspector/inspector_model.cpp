#include "app/viewer/inspector/inspector_model.h"

#include <algorithm>

#include "app/viewer/gl/transforms.h"

namespace lancer::viewer::inspector {

namespace {

void addLine(gl::Batch& b, const Vec3& p, const Vec3& q, const glm::vec3& color) {
    b.line(glm::vec3(p), glm::vec3(q), gl::rgba8(color));
}

void addVolume(gl::Batch& b, const Corners& c, const glm::vec3& color) {
    b.box(toFloat(c), gl::rgba8(color));
}

}  // namespace

bool maybeVisible(const Camera& cam, int w, int h, const Corners& c) {
    // Outcodes: a volume is out of view when every corner is beyond the same edge.
    const gl::ImageProjector proj(cam, w, h);
    unsigned all = 0x1f;
    for (const Vec3& p : c) {
        unsigned code = 0;
        std::optional<glm::dvec2> q = proj.toImage(p);
        if (!q) {
            code = 0x10;  // behind the eye: its projection is meaningless
        } else {
            code |= q->x < 0.0 ? 1u : 0u;
            code |= q->x > w ? 2u : 0u;
            code |= q->y < 0.0 ? 4u : 0u;
            code |= q->y > h ? 8u : 0u;
        }
        all &= code;
        if (!all) return true;
    }
    return false;
}

namespace {

double valueOf(const RegionView& r, ColorBy by) {
    return by == ColorBy::Prims ? double(r.prims) : double(r.level);
}

/// Keep region `r` when the filters and the view let it be seen. False once the cap is
/// reached: one region beyond it is counted in `kept` and the search stops, so a structure of
/// millions of regions costs the cap, not its size.
bool offer(InspectorModel& m, const InspectorOptions& opt, const InspectorView& insp,
           const RegionView& r) {
    if (!opt.only.keeps(r.id) || !opt.slab.keeps(r.corners)) return true;
    if (!maybeVisible(insp.camera, insp.width, insp.height, r.corners)) return true;
    ++m.kept;
    if (m.regions.size() >= size_t(std::max(opt.cap, 0))) return false;
    m.regions.push_back(r);
    return true;
}

void regularRegions(InspectorModel& m, const StructureView& view, const InspectorOptions& opt,
                    const InspectorView& insp) {
    const RegularGrid& g = *view.regular();
    m.total = g.leaves().size();
    for (uint32_t id = 0; id < g.leaves().size(); ++id)
        m.maxLevel = std::max(m.maxLevel, view.leafLevel(id));
    for (uint32_t id = 0; id < g.leaves().size(); ++id) {
        const int level = view.leafLevel(id);
        if (!inLevelRange(level, opt.levelLo, opt.levelHi)) continue;
        RegionView r;
        r.id = id;
        r.level = level;
        r.prims = g.leaves()[id].prims;
        r.corners = view.regionCorners(id);
        if (!offer(m, opt, insp, r)) break;
    }
}

/// The BVH's nodes in the level range (by depth), leaves and inner nodes alike.
void bvhRegions(InspectorModel& m, const StructureView& view, const InspectorOptions& opt,
                const InspectorView& insp) {
    const Bvh& b = *view.bvh();
    m.total = b.nodes().size();
    m.maxLevel = b.depth();
    for (uint32_t id = 0; id < b.nodes().size(); ++id) {
        const BvhNode& n = b.nodes()[id];
        if (!inLevelRange(n.depth, opt.levelLo, opt.levelHi)) continue;
        RegionView r;
        r.id = id;
        r.level = n.depth;
        r.prims = n.leaf ? n.count : 0;
        r.corners = view.regionCorners(id);
        if (!offer(m, opt, insp, r)) break;
    }
}

/// The frame primary rays walk: the projective zones when present, else the camera frame.
const ZoneFrameView* primaryFrame(const StructureView& view) {
    const ZoneFrameView* f = view.frame(ZoneFrameKind::Projective);
    return f ? f : view.frame(ZoneFrameKind::Camera);
}

void irregularRegions(InspectorModel& m, const StructureView& view, const InspectorOptions& opt,
                      const InspectorView& insp, int64_t selected) {
    const ZoneFrameView* frame = primaryFrame(view);
    if (!frame) return;
    m.total = frame->slabCount();
    int64_t selectedZone = -1;
    if (selected >= 0 && uint64_t(selected) < view.regionCount()) {
        RegionInfo info = view.region(uint32_t(selected));
        // A light's slab is a zone of the light's structure, none of the eye's frames.
        if ((info.kind == RegionKind::Slab || info.kind == RegionKind::ProjectiveSlab) &&
            info.light < 0)
            selectedZone = info.zone;
    }
    size_t columns = 0;
    bool full = false;
    for (uint32_t z = 0; z < frame->zoneCount() && !(full && columns > size_t(opt.cap)); ++z) {
        std::vector<SlabInfo> slabs = frame->slabs(z);
        if (slabs.empty()) continue;
        const Corners column = frame->zoneCorners(z);
        if (opt.zones && opt.slab.keeps(column) &&
            maybeVisible(insp.camera, insp.width, insp.height, column) &&
            columns++ < size_t(std::max(opt.cap, 0)))
            addVolume(m.lines, column, kZoneColor);
        if (full || !opt.regions || (opt.zoneSlabsOnly && int64_t(z) != selectedZone)) continue;
        for (size_t k = 0; k < slabs.size(); ++k) {
            RegionView r;
            r.id = slabs[k].region;
            r.level = int(k);
            r.prims = uint32_t(slabs[k].prims.size());
            r.corners = view.regionCorners(r.id);
            if (!offer(m, opt, insp, r)) {
                full = true;
                break;
            }
        }
    }
}

void directoryBlocks(InspectorModel& m, const StructureView& view, const InspectorOptions& opt,
                     const InspectorView& insp) {
    size_t drawn = 0;
    for (const DirectoryBlock& b : view.directoryBlocks()) {
        // The level range as for the leaves: an entry by its leaf's BSP level, a sub-table by
        // its node's.
        if (!inLevelRange(b.level, opt.levelLo, opt.levelHi)) continue;
        bool single = true;
        for (int a = 0; a < 3; ++a) single = single && b.hi[a] - b.lo[a] == 1;
        const Corners c = view.gridCorners(b.lo, b.hi);
        if (!opt.slab.keeps(c) || !maybeVisible(insp.camera, insp.width, insp.height, c)) continue;
        ++m.blocks;
        if (drawn++ >= size_t(std::max(opt.cap, 0))) continue;
        addVolume(m.lines, c, b.subTable ? kSubTableColor : single ? kCellColor : kBlockColor);
    }
}

}  // namespace

gl::Batch frustumLines(const StructureView& view, const MainView& main) {
    gl::Batch lines;
    const Camera& cam = main.camera;
    double near, far;
    depthRange(cam, view.worldBounds(), near, far);
    far = std::max(far, 1e-6);
    if (cam.projection == Projection::Perspective) {
        // From the eye to the far side of the structure: the eye's rays, then the far face.
        const Corners c = frustumCorners(cam, main.width, main.height, 0.0, far);
        for (int i = 4; i < 8; ++i) addLine(lines, cam.from, c[size_t(i)], kFrustumColor);
        for (const auto& e : cornerEdges())
            if (e[0] & e[1] & 4) addLine(lines, c[size_t(e[0])], c[size_t(e[1])], kFrustumColor);
    } else {
        addVolume(lines, frustumCorners(cam, main.width, main.height, 0.0, far), kFrustumColor);
    }
    const std::array<Vec3, 4> plane = imagePlane(cam, main.width, main.height);
    for (int i = 0; i < 4; ++i)
        addLine(lines, plane[size_t(i)], plane[size_t(i + 1) % 4], kImagePlaneColor);
    // A small triangle on its top edge, as cameras are drawn: which way is up.
    const Vec3 mid = 0.5 * (plane[0] + plane[1]), up = 0.15 * (plane[0] - plane[3]);
    const Vec3 side = 0.15 * (plane[1] - plane[0]);
    addLine(lines, mid - side, mid + up, kImagePlaneColor);
    addLine(lines, mid + up, mid + side, kImagePlaneColor);
    return lines;
}

InspectorModel buildModel(const StructureView& view, const InspectorOptions& opt,
                          const MainView& main, const InspectorView& insp, int64_t selected) {
    InspectorModel m;
    const Scene& scene = view.scene();
    if (view.scheme() == SchemeKind::Regular) {
        if (opt.regions) regularRegions(m, view, opt, insp);
        if (opt.grid) directoryBlocks(m, view, opt, insp);
    } else if (view.scheme() == SchemeKind::Irregular) {
        irregularRegions(m, view, opt, insp, selected);
    } else if (view.scheme() == SchemeKind::Bvh) {
        if (opt.regions) bvhRegions(m, view, opt, insp);
    } else if (opt.regions) {
        RegionView r;
        r.corners = view.regionCorners(0);
        r.prims = uint32_t(view.region(0).prims.size());
        m.total = 1;
        offer(m, opt, insp, r);
    }
    m.top = 1.0;
    for (const RegionView& r : m.regions) m.top = std::max(m.top, valueOf(r, opt.colorBy));
    for (const RegionView& r : m.regions)
        addVolume(m.lines, r.corners, regionColor(valueOf(r, opt.colorBy), opt.colorBy));
    if (opt.boxes) {
        size_t drawn = 0;
        for (const Box3& b : scene.minBox) {
            if (b.isEmpty()) continue;
            const Corners c = boxCorners(b);
            if (!opt.slab.keeps(c)) continue;
            if (drawn++ >= size_t(std::max(opt.cap, 0))) break;
            addVolume(m.lines, c, kBoxColor);
        }
    }
    if (opt.frustum) m.lines.append(frustumLines(view, main));
    if (selected >= 0 && uint64_t(selected) < view.regionCount())
        addVolume(m.selection, view.regionCorners(uint32_t(selected)), kSelectionColor);
    return m;
}

}  // namespace lancer::viewer::inspector
