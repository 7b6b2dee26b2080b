#include "engine/accel/structure_view.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>

namespace lancer {

namespace {

std::array<Vec3, 8> boxCorners(const Box3& b) {
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i)
        c[i] = {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
    return c;
}

int64_t ropeNeighbour(uint32_t rope) {
    if (rope == kBorder) return kNoNeighbour;
    if (rope == kSplitFace) return kSeveralNeighbours;
    return rope;
}

}  // namespace

const char* regionKindName(RegionKind k) {
    switch (k) {
        case RegionKind::SceneBox:
            return "scene box";
        case RegionKind::Leaf:
            return "leaf";
        case RegionKind::Slab:
            return "slab";
        case RegionKind::ProjectiveSlab:
            return "projective slab";
        case RegionKind::NearRegion:
            return "near region";
        case RegionKind::BvhInner:
            return "node";
        case RegionKind::BvhLeaf:
            return "bvh leaf";
    }
    return "?";
}

const char* frameUnitsName(FrameUnits u) { return u == FrameUnits::Pixels ? "pixels" : "camera"; }

// ---------------------------------------------------------------------------------------------
// ZoneFrameView

ZoneFrameView::ZoneFrameView(const Scene& scene, const IrregularSubdivision& s, ZoneFrameKind kind)
    : scene_(&scene), s_(&s), kind_(kind) {
    const Camera& cam = scene.camera;
    half_ = cam.projection == Projection::Orthographic ? 0.5 * cam.orthoHeight
                                                       : std::tan(glm::radians(cam.fov) * 0.5);
    if (kind == ZoneFrameKind::Camera) {
        bsp_ = &s.screen();
        lo_ = {s.bounds().lo.x, s.bounds().lo.y};
        hi_ = {s.bounds().hi.x, s.bounds().hi.y};
        first_ = 0;
    } else {
        bsp_ = &s.projective().screen();
        lo_ = s.projective().rectLo();
        hi_ = s.projective().rectHi();
        first_ = uint32_t(s.regions().size());
    }
}

bool ZoneFrameView::mapsToImage() const {
    return kind_ == ZoneFrameKind::Projective ||
           scene_->camera.projection == Projection::Orthographic;
}

size_t ZoneFrameView::slabCount() const {
    return kind_ == ZoneFrameKind::Camera ? s_->regions().size()
                                          : s_->projective().zoneFirst().back();
}

std::vector<BspCut> ZoneFrameView::cuts() const {
    const ScreenBsp& bsp = *bsp_;
    std::vector<BspCut> out(bsp.nodes.size());
    if (bsp.root < 0) return out;
    // Cells and depths from the root down; nodes are stored in the order their cuts were made.
    struct Item {
        int32_t node;
        glm::dvec2 lo, hi;
        int depth;
    };
    std::vector<Item> stack{{bsp.root, lo_, hi_, 0}};
    while (!stack.empty()) {
        Item it = stack.back();
        stack.pop_back();
        const ScreenBsp::Node& n = bsp.nodes[it.node];
        BspCut& c = out[it.node];
        c.node = uint32_t(it.node);
        c.depth = it.depth;
        c.axis = n.axis;
        c.value = n.value;
        c.a = it.lo;
        c.b = it.hi;
        c.a[n.axis] = c.b[n.axis] = n.value;
        glm::dvec2 belowHi = it.hi, aboveLo = it.lo;
        belowHi[n.axis] = n.value;
        aboveLo[n.axis] = n.value;
        if (n.child[0] >= 0) stack.push_back({n.child[0], it.lo, belowHi, it.depth + 1});
        if (n.child[1] >= 0) stack.push_back({n.child[1], aboveLo, it.hi, it.depth + 1});
    }
    return out;
}

std::span<const uint32_t> ZoneFrameView::zonePrims(uint32_t z) const {
    return {bsp_->zonePrims.data() + bsp_->zoneFirst[z],
            bsp_->zonePrims.data() + bsp_->zoneFirst[z + 1]};
}

std::vector<SlabInfo> ZoneFrameView::slabs(uint32_t z) const {
    std::vector<SlabInfo> out;
    if (kind_ == ZoneFrameKind::Camera) {
        const std::vector<uint32_t>& first = s_->zoneFirstRegion();
        for (uint32_t r = first[z]; r < first[z + 1]; ++r) {
            const Box3& b = s_->regions()[r].box;
            out.push_back({r, b.lo.z, b.hi.z, s_->primitives(r)});
        }
    } else {
        const ProjectiveZones& pz = s_->projective();
        const uint32_t last = pz.zoneFirst()[z + 1];
        for (uint32_t i = pz.zoneFirst()[z]; i < last; ++i)
            out.push_back({first_ + i, pz.slabLo(i), i + 1 < last ? pz.slabLo(i + 1) : pz.zFar(),
                           pz.slabPrimitives(i)});
    }
    return out;
}

std::array<Vec3, 8> ZoneFrameView::zoneCorners(uint32_t z) const {
    const bool cam = kind_ == ZoneFrameKind::Camera;
    const double z0 = cam ? s_->bounds().lo.z : s_->projective().zNear();
    const double z1 = cam ? s_->bounds().hi.z : s_->projective().zFar();
    const glm::dvec2 lo = bsp_->zoneLo[z], hi = bsp_->zoneHi[z];
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i) {
        const double x = (i & 1) ? hi.x : lo.x, y = (i & 2) ? hi.y : lo.y, d = (i & 4) ? z1 : z0;
        c[i] = s_->frame().toWorld(cam ? Vec3(x, y, d) : Vec3(x * d, y * d, d));
    }
    return c;
}

int64_t ZoneFrameView::zoneAt(glm::dvec2 p) const {
    if (zoneCount() == 0 || !(p.x >= lo_.x && p.x <= hi_.x && p.y >= lo_.y && p.y <= hi_.y))
        return -1;
    return bsp_->locate(p.x, p.y, 0, 0);
}

glm::dvec2 ZoneFrameView::toPixel(glm::dvec2 p, int w, int h) const {
    // Inverse of PrimaryRays: a pixel centre's offset sx = (2 x / w - 1) w / h times half.
    return {(p.x / half_ * h + w) * 0.5, (1.0 - p.y / half_) * h * 0.5};
}

glm::dvec2 ZoneFrameView::fromPixel(glm::dvec2 px, int w, int h) const {
    return {(2.0 * px.x - w) / h * half_, (1.0 - 2.0 * px.y / h) * half_};
}

std::vector<glm::dvec2> ZoneFrameView::zonePolygon(uint32_t z, int w, int h) const {
    glm::dvec2 lo = bsp_->zoneLo[z], hi = bsp_->zoneHi[z];
    if (mapsToImage()) {
        glm::dvec2 a = toPixel(lo, w, h), b = toPixel(hi, w, h);
        lo = glm::max(glm::min(a, b), glm::dvec2(0.0));
        hi = glm::min(glm::max(a, b), glm::dvec2(w, h));
    } else {
        lo = glm::max(lo, lo_);
        hi = glm::min(hi, hi_);
    }
    if (!(lo.x < hi.x && lo.y < hi.y)) return {};
    return {lo, {hi.x, lo.y}, hi, {lo.x, hi.y}};
}

int64_t ZoneFrameView::zoneAtPixel(double x, double y, int w, int h, double depth) const {
    glm::dvec2 p = fromPixel({x, y}, w, h);
    // A perspective camera frame: the pixel's ray at that depth.
    if (!mapsToImage()) p *= depth;
    return zoneAt(p);
}

// ---------------------------------------------------------------------------------------------
// StructureView

StructureView::StructureView(const Scene& scene, const Accelerator& accel)
    : scene_(&scene), accel_(&accel) {
    if (const IrregularSubdivision* s = irregular()) {
        if (!s->regions().empty()) frames_.emplace_back(scene, *s, ZoneFrameKind::Camera);
        if (s->projective().zoneCount() > 0)
            frames_.emplace_back(scene, *s, ZoneFrameKind::Projective);
    } else if (!regular() && !bvh()) {
        live_ = scene.livePrimitives();
        std::sort(live_.begin(), live_.end());
    }
}

const RegularGrid* StructureView::regular() const {
    return std::get_if<RegularGrid>(&accel_->impl());
}

const IrregularSubdivision* StructureView::irregular() const {
    return std::get_if<IrregularSubdivision>(&accel_->impl());
}

const Bvh* StructureView::bvh() const { return std::get_if<Bvh>(&accel_->impl()); }

const ZoneFrameView* StructureView::frame(ZoneFrameKind kind) const {
    for (const ZoneFrameView& f : frames_)
        if (f.kind() == kind) return &f;
    return nullptr;
}

size_t StructureView::regionCount() const {
    return std::visit([](const auto& s) { return s.regionCount(); }, accel_->impl());
}

std::array<Vec3, 8> StructureView::regionCorners(uint32_t id) const {
    if (const RegularGrid* g = regular()) {
        const RegularLeaf& L = g->leaves().at(id);
        return gridCorners(L.lo, L.hi);
    }
    if (const Bvh* b = bvh()) {
        std::array<Vec3, 8> c = boxCorners(b->nodes().at(id).box());
        for (Vec3& p : c) p = b->frame().toWorld(p);
        return c;
    }
    const IrregularSubdivision* s = irregular();
    if (!s) return boxCorners(scene_->bounds);
    const CameraFrame& f = s->frame();
    std::array<Vec3, 8> c;
    const RegionInfo r = region(id);
    const Box3& b = r.frameBox;
    for (int i = 0; i < 8; ++i) {
        const double x = (i & 1) ? b.hi.x : b.lo.x, y = (i & 2) ? b.hi.y : b.lo.y,
                     z = (i & 4) ? b.hi.z : b.lo.z;
        // Projective: (u, v, depth) is the camera point (u z, v z, z).
        c[i] = r.kind == RegionKind::Slab ? f.toWorld({x, y, z}) : f.toWorld({x * z, y * z, z});
    }
    return c;
}

RegionInfo StructureView::region(uint32_t id) const {
    RegionInfo r;
    r.id = id;
    if (const RegularGrid* g = regular()) {
        const RegularLeaf& L = g->leaves().at(id);
        r.kind = RegionKind::Leaf;
        r.frameBox = {{L.plane[0], L.plane[1], L.plane[2]}, {L.plane[3], L.plane[4], L.plane[5]}};
        r.level = leafLevel(id);
        for (int a = 0; a < 3; ++a) {
            r.cellLo[a] = L.lo[a];
            r.cellHi[a] = L.hi[a];
            r.lo[a] = ropeNeighbour(L.rope[2 * a]);
            r.hi[a] = ropeNeighbour(L.rope[2 * a + 1]);
        }
        r.prims = {L.primitives(g->primList().data()), L.prims};
        r.pool = &g->treePool();
        r.root = L.root;
        return r;
    }
    if (const Bvh* b = bvh()) {
        const BvhNode& n = b->nodes().at(id);
        r.kind = n.leaf ? RegionKind::BvhLeaf : RegionKind::BvhInner;
        r.frameBox = n.box();
        r.level = n.depth;
        for (int a = 0; a < 3; ++a) r.lo[a] = r.hi[a] = kNotLinked;
        if (n.leaf) {
            r.prims = {b->primList().data() + n.first, n.count};
            r.pool = &b->treePool();
            r.root = n.root;
        }
        return r;
    }
    const IrregularSubdivision* s = irregular();
    if (!s) {
        if (id != 0) throw std::out_of_range("brute force has one region, 0");
        r.frameBox = scene_->bounds;
        r.prims = live_;
        r.pool = &scene_->tree;
        r.root = scene_->tree.root;
        return r;
    }
    const size_t base = s->regions().size();
    if (id < base) {
        const IrregularRegion& R = s->regions()[id];
        r.kind = RegionKind::Slab;
        r.frameBox = R.box;
        r.zone = R.zone;
        r.slab = id - s->zoneFirstRegion()[R.zone];
        r.prims = s->primitives(id);
        r.pool = &s->treePool();
        r.root = R.root;
        for (int a = 0; a < 3; ++a) {
            r.lo[a] = R.lo[a];
            r.hi[a] = R.hi[a];
        }
        return r;
    }
    const ProjectiveZones& pz = s->projective();
    if (id >= base + pz.regionCount()) throw std::out_of_range("no region " + std::to_string(id));
    const uint32_t i = uint32_t(id - base);
    const uint32_t slabs = pz.zoneFirst().back();
    r.pool = &pz.treePool();
    for (int a = 0; a < 2; ++a) r.lo[a] = r.hi[a] = kNotLinked;
    if (i == slabs) {
        r.kind = RegionKind::NearRegion;
        r.frameBox = {Vec3(pz.rectLo(), 0.0), Vec3(pz.rectHi(), pz.zNear())};
        r.prims = pz.nearPrimitives();
        r.root = pz.nearRoot();
        r.lo[2] = kNoNeighbour;
        r.hi[2] = kNotLinked;  // the first slab of the pixel's zone
        return r;
    }
    const std::vector<uint32_t>& first = pz.zoneFirst();
    const uint32_t z =
        uint32_t(std::upper_bound(first.begin(), first.end(), i) - first.begin() - 1);
    const ScreenBsp& bsp = pz.screen();
    const bool lastSlab = i + 1 == first[z + 1];
    r.kind = RegionKind::ProjectiveSlab;
    r.frameBox = {Vec3(bsp.zoneLo[z], pz.slabLo(i)),
                  Vec3(bsp.zoneHi[z], lastSlab ? pz.zFar() : pz.slabLo(i + 1))};
    r.zone = z;
    r.slab = i - first[z];
    r.prims = pz.slabPrimitives(i);
    r.root = pz.slabRoot(i);
    r.lo[2] = i > first[z] ? int64_t(base + i - 1)
                           : (pz.hasNearRegion() ? int64_t(base + slabs) : kNoNeighbour);
    r.hi[2] = lastSlab ? kNoNeighbour : int64_t(base + i + 1);
    return r;
}

std::string StructureView::toString(uint32_t id) const {
    const RegionInfo r = region(id);
    if (const RegularGrid* g = regular())
        return g->describeLeaf(id) + " level " + std::to_string(r.level);
    if (const Bvh* b = bvh()) return b->describe(id);
    std::string out = std::string(regionKindName(r.kind)) + " " + std::to_string(id);
    if (r.kind == RegionKind::Slab || r.kind == RegionKind::ProjectiveSlab)
        out += " zone " + std::to_string(r.zone) + " slab " + std::to_string(r.slab);
    switch (r.kind) {
        case RegionKind::Slab:
            out += " camera-frame ";
            break;
        case RegionKind::ProjectiveSlab:
        case RegionKind::NearRegion:
            out += " (u,v,depth) ";
            break;
        default:
            out += " ";
            break;
    }
    return out + r.frameBox.toString() + " " + std::to_string(r.prims.size()) + " prims";
}

uint32_t StructureView::regionAt(const Vec3& world) const {
    if (const RegularGrid* g = regular()) return g->leafAt(world);
    if (const Bvh* b = bvh()) return b->regionCount() ? b->leafAt(world) : 0;
    const IrregularSubdivision* s = irregular();
    if (!s || s->regions().empty()) return 0;
    const Vec3 p = glm::clamp(s->frame().point(world), s->bounds().lo, s->bounds().hi);
    return s->locate(p, Vec3(0.0));
}

std::array<Vec3, 8> StructureView::structureCorners() const {
    if (const RegularGrid* g = regular()) {
        std::array<Vec3, 8> c = boxCorners(g->box());
        for (Vec3& p : c) p = g->frame().toWorld(p);
        return c;
    }
    if (const Bvh* b = bvh()) {
        if (!b->regionCount()) return boxCorners(scene_->bounds);
        std::array<Vec3, 8> c = boxCorners(b->box());
        for (Vec3& p : c) p = b->frame().toWorld(p);
        return c;
    }
    const IrregularSubdivision* s = irregular();
    if (!s) return boxCorners(scene_->bounds);
    std::array<Vec3, 8> c = boxCorners(s->bounds());
    for (Vec3& p : c) p = s->frame().toWorld(p);
    return c;
}

Box3 StructureView::worldBounds() const {
    Box3 b;
    for (const Vec3& p : structureCorners()) b.expand(p);
    return b;
}

std::array<Vec3, 8> StructureView::gridCorners(const uint32_t lo[3], const uint32_t hi[3]) const {
    const RegularGrid* g = regular();
    if (!g) return {};
    Box3 b;
    for (int a = 0; a < 3; ++a) {
        b.lo[a] = g->plane(a, lo[a]);
        b.hi[a] = g->plane(a, hi[a]);
    }
    std::array<Vec3, 8> c = boxCorners(b);
    for (Vec3& p : c) p = g->frame().toWorld(p);
    return c;
}

int StructureView::directoryLog2(int axis) const {
    const RegularGrid* g = regular();
    return g ? std::countr_zero(g->cells(axis)) : 0;
}

int StructureView::leafLevel(uint32_t leaf) const {
    const RegularGrid* g = regular();
    if (!g) return -1;
    const RegularLeaf& L = g->leaves().at(leaf);
    return cellLevel(L.lo, L.hi);
}

int StructureView::cellLevel(const uint32_t lo[3], const uint32_t hi[3]) const {
    const RegularGrid* g = regular();
    if (!g) return -1;
    // A node at level l spans 2^(n_a - cuts(l, a)) cells on axis a, and the cuts add up to l.
    int level = 0;
    for (int a = 0; a < 3; ++a)
        level += std::countr_zero(g->cells(a)) - std::countr_zero(hi[a] - lo[a]);
    return level;
}

std::vector<CutPlane> StructureView::cutPlanes() const {
    std::vector<CutPlane> out;
    const RegularGrid* g = regular();
    if (!g) return out;
    struct Cell {
        uint32_t lo[3], hi[3];
        int level;
    };
    // Breadth first: by level. A cell is a leaf when the leaf at its low corner covers it.
    std::vector<Cell> queue{{{0, 0, 0}, {g->cells(0), g->cells(1), g->cells(2)}, 0}};
    for (size_t q = 0; q < queue.size(); ++q) {
        const Cell c = queue[q];
        const RegularLeaf& L = g->leaves()[g->directory().lookup(c.lo[0], c.lo[1], c.lo[2])];
        if (std::equal(c.lo, c.lo + 3, L.lo) && std::equal(c.hi, c.hi + 3, L.hi)) continue;
        const int a = g->schedule().axis(c.level);
        if (c.hi[a] - c.lo[a] < 2 || c.level + 1 >= AxisSchedule::kLevels)
            throw std::logic_error("regular: a directory cell is shared by several leaves");
        const uint32_t mid = (c.lo[a] + c.hi[a]) / 2;
        CutPlane p;
        p.axis = a;
        p.value = g->plane(a, mid);
        p.level = c.level;
        for (int b = 0; b < 3; ++b) {
            p.cellLo[b] = c.lo[b];
            p.cellHi[b] = c.hi[b];
            p.cell.lo[b] = g->plane(b, c.lo[b]);
            p.cell.hi[b] = g->plane(b, c.hi[b]);
        }
        out.push_back(p);
        Cell below = c, above = c;
        below.hi[a] = above.lo[a] = mid;
        below.level = above.level = c.level + 1;
        queue.push_back(below);
        queue.push_back(above);
    }
    return out;
}

std::vector<DirectoryBlock> StructureView::directoryBlocks() const {
    std::vector<DirectoryBlock> out;
    const RegularGrid* g = regular();
    if (!g) return out;
    g->directory().forEachEntry([&](const uint32_t lo[3], const uint32_t hi[3], bool sub,
                                    uint32_t value, uint32_t table, int depth) {
        DirectoryBlock b;
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = lo[a];
            b.hi[a] = hi[a];
        }
        b.subTable = sub;
        b.leaf = sub ? 0 : value;
        b.child = sub ? value : 0;
        b.table = table;
        b.depth = depth;
        b.level = sub ? cellLevel(b.lo, b.hi) : leafLevel(value);
        out.push_back(b);
    });
    return out;
}

}  // namespace lancer
