#include "engine/accel/structure_view.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace lancer {

namespace {

std::array<Vec3, 8> boxCorners(const Box3& b) {
    std::array<Vec3, 8> c;
    for (int i = 0; i < 8; ++i)
        c[i] = {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
    return c;
}

template <class... Ts>
struct Overloaded : Ts... {
    using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;  // clang 14 lacks C++20 aggregate deduction

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

const char* treeNodeKindName(TreeNodeKind k) {
    switch (k) {
        case TreeNodeKind::Cell:
            return "cell";
        case TreeNodeKind::Leaf:
            return "leaf";
        case TreeNodeKind::Table:
            return "table";
        case TreeNodeKind::Entry:
            return "entry";
        case TreeNodeKind::Cut:
            return "cut";
        case TreeNodeKind::Zone:
            return "zone";
        case TreeNodeKind::Slab:
            return "slab";
        case TreeNodeKind::BvhInner:
            return "node";
        case TreeNodeKind::BvhLeaf:
            return "leaf node";
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
            const IrregularRegion& R = s_->regions()[r];
            out.push_back({r, R.zlo, R.zhi, s_->heldPrimitives(r)});
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

std::pair<uint32_t, uint32_t> ZoneFrameView::zoneRegions(uint32_t z0, uint32_t z1) const {
    if (kind_ == ZoneFrameKind::Camera) {
        const std::vector<uint32_t>& first = s_->zoneFirstRegion();
        return {first[z0], first[z1]};
    }
    const std::vector<uint32_t>& first = s_->projective().zoneFirst();
    return {first_ + first[z0], first_ + first[z1]};
}

std::pair<uint32_t, uint32_t> ZoneFrameView::zoneSpan(int32_t ref) const {
    if (ref < 0) return {uint32_t(~ref), uint32_t(~ref)};
    std::call_once(spans_->once, [&] {
        // Children before parents: a node's span joins its children's.
        const ScreenBsp& bsp = *bsp_;
        std::vector<std::pair<uint32_t, uint32_t>>& out = spans_->node;
        out.assign(bsp.nodes.size(), {0u, 0u});
        std::vector<std::pair<int32_t, bool>> stack;
        if (bsp.root >= 0) stack.push_back({bsp.root, false});
        while (!stack.empty()) {
            const auto [n, childrenDone] = stack.back();
            stack.pop_back();
            const ScreenBsp::Node& node = bsp.nodes[size_t(n)];
            if (!childrenDone) {
                stack.push_back({n, true});
                for (int32_t c : node.child)
                    if (c >= 0) stack.push_back({c, false});
                continue;
            }
            auto span = [&](int32_t c) {
                return c < 0 ? std::pair{uint32_t(~c), uint32_t(~c)} : out[size_t(c)];
            };
            const auto a = span(node.child[0]), b = span(node.child[1]);
            out[size_t(n)] = {std::min(a.first, b.first), std::max(a.second, b.second)};
        }
    });
    return spans_->node[size_t(ref)];
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

namespace {

/// Region i of the projective structure `pz` (the eye's or a light's), whose ids start at
/// `base`: a slab (by increasing depth) of a zone, or the near region last.
RegionInfo projectiveRegion(const ProjectiveZones& pz, size_t base, uint32_t i, RegionInfo r) {
    const uint32_t slabs = pz.zoneFirst().back();
    r.pool = &pz.treePool();
    for (int a = 0; a < 2; ++a) r.lo[a] = r.hi[a] = kNotLinked;
    if (i == slabs) {
        r.kind = RegionKind::NearRegion;
        r.frameBox = {Vec3(pz.rectLo(), 0.0), Vec3(pz.rectHi(), pz.zNear())};
        r.prims = pz.nearPrimitives();
        r.root = pz.nearRoot();
        r.lo[2] = kNoNeighbour;
        r.hi[2] = kNotLinked;  // the first slab of the ray's zone
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

}  // namespace

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
    const RegionInfo r = region(id);
    const CameraFrame& f = r.light >= 0 ? s->lights()[size_t(r.light)].frame() : s->frame();
    std::array<Vec3, 8> c;
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
        r.frameBox = s->regionBox(uint32_t(id));
        r.zone = R.zone;
        r.slab = id - s->zoneFirstRegion()[R.zone];
        r.prims = s->heldPrimitives(uint32_t(id));
        r.pool = &s->treePool();
        r.root = R.root;
        for (int a = 0; a < 3; ++a) {
            r.lo[a] = s->pointer(uint32_t(id), a, false);
            r.hi[a] = s->pointer(uint32_t(id), a, true);
        }
        return r;
    }
    const ProjectiveZones* pz = &s->projective();
    size_t first = base;
    if (id >= base + pz->regionCount()) {
        const std::vector<uint32_t>& lf = s->lightFirstRegion();
        if (lf.empty() || id >= lf.back())
            throw std::out_of_range("no region " + std::to_string(id));
        const auto it = std::upper_bound(lf.begin(), lf.end(), id) - 1;
        r.light = int(it - lf.begin());
        pz = &s->lights()[size_t(r.light)];
        first = *it;
    }
    return projectiveRegion(*pz, first, uint32_t(id - first), r);
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

// ---------------------------------------------------------------------------------------------
// Trees

std::vector<StructureTree> StructureView::trees() const {
    std::vector<StructureTree> out;
    std::visit(
        Overloaded{
            [](const BruteForce&) {},
            [&](const RegularGrid& g) {
                const uint32_t lo[3] = {0, 0, 0};
                const uint32_t hi[3] = {g.cells(0), g.cells(1), g.cells(2)};
                out.push_back(
                    {TreeKind::RegularBsp, ZoneFrameKind::Camera, "BSP", regularCell(lo, hi, 0)});
                if (g.directory().tableCount() > 0)
                    out.push_back({TreeKind::Directory, ZoneFrameKind::Camera, "directory",
                                   directoryTable(0, lo, hi, 0)});
            },
            [&](const IrregularSubdivision&) {
                for (ZoneFrameKind k : {ZoneFrameKind::Projective, ZoneFrameKind::Camera}) {
                    const ZoneFrameView* f = frame(k);
                    if (!f || f->zoneCount() == 0) continue;
                    out.push_back({TreeKind::ScreenBsp, k,
                                   k == ZoneFrameKind::Projective ? "screen BSP (projective)"
                                                                  : "screen BSP (camera frame)",
                                   screenRef(*f, f->bsp().root, 0)});
                }
            },
            [&](const Bvh& b) {
                if (!b.nodes().empty())
                    out.push_back({TreeKind::Bvh, ZoneFrameKind::Camera, "BVH", bvhNode(0)});
            },
        },
        accel_->impl());
    return out;
}

TreeNode StructureView::regularCell(const uint32_t lo[3], const uint32_t hi[3], int depth) const {
    const RegularGrid& g = *regular();
    TreeNode n;
    n.tree = TreeKind::RegularBsp;
    n.depth = depth;
    std::copy_n(lo, 3, n.lo);
    std::copy_n(hi, 3, n.hi);
    const uint32_t first = g.directory().lookup(lo[0], lo[1], lo[2]);
    const RegularLeaf& L = g.leaves()[first];
    if (std::equal(lo, lo + 3, L.lo) && std::equal(hi, hi + 3, L.hi)) {
        n.kind = TreeNodeKind::Leaf;
        n.region = first;
        n.prims = L.prims;
        n.ranged = true;
        n.regionLo = first;
        n.regionHi = first + 1;
        return n;
    }
    // Leaves are numbered depth first, the low half first: a cell's leaves run from the one at
    // its low corner to the one at its high corner.
    n.kind = TreeNodeKind::Cell;
    n.axis = g.schedule().axis(depth);
    n.children = 2;
    n.ranged = true;
    n.regionLo = first;
    n.regionHi = g.directory().lookup(hi[0] - 1, hi[1] - 1, hi[2] - 1) + 1;
    return n;
}

TreeNode StructureView::directoryTable(uint32_t table, const uint32_t lo[3], const uint32_t hi[3],
                                       int depth) const {
    const RegularGrid& g = *regular();
    TreeNode n;
    n.tree = TreeKind::Directory;
    n.kind = TreeNodeKind::Table;
    n.depth = depth;
    n.index = table;
    std::copy_n(lo, 3, n.lo);
    std::copy_n(hi, 3, n.hi);
    n.children = g.directory().tableSize(table);
    // A table stores a BSP node's cell: its leaves are consecutive (regularCell).
    n.ranged = true;
    n.regionLo = g.directory().lookup(lo[0], lo[1], lo[2]);
    n.regionHi = g.directory().lookup(hi[0] - 1, hi[1] - 1, hi[2] - 1) + 1;
    return n;
}

TreeNode StructureView::directoryEntry(uint32_t table, const uint32_t origin[3], size_t i,
                                       int depth) const {
    const RegularGrid& g = *regular();
    uint32_t lo[3], hi[3], value = 0;
    bool sub = false;
    g.directory().tableEntry(table, origin, i, lo, hi, sub, value);
    if (sub) return directoryTable(value, lo, hi, depth);
    TreeNode n;
    n.tree = TreeKind::Directory;
    n.kind = TreeNodeKind::Entry;
    n.depth = depth;
    n.index = uint32_t(i);
    std::copy_n(lo, 3, n.lo);
    std::copy_n(hi, 3, n.hi);
    n.region = value;
    n.prims = g.leaves()[value].prims;
    n.ranged = true;
    n.regionLo = value;
    n.regionHi = value + 1;
    return n;
}

TreeNode StructureView::screenRef(const ZoneFrameView& f, int32_t ref, int depth) const {
    const ScreenBsp& bsp = f.bsp();
    TreeNode n;
    n.tree = TreeKind::ScreenBsp;
    n.frame = f.kind();
    n.depth = depth;
    const auto [z0, z1] = f.zoneSpan(ref);
    const auto [r0, r1] = f.zoneRegions(z0, z1 + 1);
    n.ranged = true;
    n.regionLo = r0;
    n.regionHi = r1;
    if (ref >= 0) {
        const ScreenBsp::Node& node = bsp.nodes[size_t(ref)];
        n.kind = TreeNodeKind::Cut;
        n.index = uint32_t(ref);
        n.axis = node.axis;
        n.value = node.value;
        n.children = 2;
        return n;
    }
    n.kind = TreeNodeKind::Zone;
    n.index = z0;
    n.prims = int64_t(f.zonePrims(z0).size());
    n.children = r1 - r0;
    return n;
}

TreeNode StructureView::bvhNode(uint32_t id) const {
    const BvhNode& b = bvh()->nodes()[id];
    TreeNode n;
    n.tree = TreeKind::Bvh;
    n.kind = b.leaf ? TreeNodeKind::BvhLeaf : TreeNodeKind::BvhInner;
    n.depth = b.depth;
    n.index = id;
    n.region = id;
    n.children = b.leaf ? 0 : 2;
    if (b.leaf) n.prims = b.count;
    return n;
}

TreeNode StructureView::treeChild(const TreeNode& node, size_t i) const {
    if (i >= node.children) throw std::out_of_range("tree node has no child " + std::to_string(i));
    switch (node.kind) {
        case TreeNodeKind::Cell: {
            const int a = node.axis;
            const uint32_t mid = (node.lo[a] + node.hi[a]) / 2;
            uint32_t lo[3], hi[3];
            std::copy_n(node.lo, 3, lo);
            std::copy_n(node.hi, 3, hi);
            (i == 0 ? hi : lo)[a] = mid;
            return regularCell(lo, hi, node.depth + 1);
        }
        case TreeNodeKind::Table:
            return directoryEntry(node.index, node.lo, i, node.depth + 1);
        case TreeNodeKind::Cut: {
            const ZoneFrameView& f = *frame(node.frame);
            return screenRef(f, f.bsp().nodes[node.index].child[i], node.depth + 1);
        }
        case TreeNodeKind::Zone: {
            TreeNode n;
            n.tree = TreeKind::ScreenBsp;
            n.frame = node.frame;
            n.kind = TreeNodeKind::Slab;
            n.depth = node.depth + 1;
            n.index = uint32_t(i);
            const uint32_t id = node.regionLo + uint32_t(i);
            n.region = id;
            n.ranged = true;
            n.regionLo = id;
            n.regionHi = id + 1;
            const RegionInfo r = region(id);
            n.prims = int64_t(r.prims.size());
            n.value = r.frameBox.lo.z;
            n.value2 = r.frameBox.hi.z;
            return n;
        }
        case TreeNodeKind::BvhInner:
            return bvhNode(bvh()->nodes()[node.index].first + uint32_t(i));
        case TreeNodeKind::Leaf:
        case TreeNodeKind::Entry:
        case TreeNodeKind::Slab:
        case TreeNodeKind::BvhLeaf:
            break;
    }
    throw std::logic_error("tree node without children");
}

std::optional<std::vector<size_t>> StructureView::treePath(const StructureTree& tree,
                                                           uint32_t id) const {
    if (id >= regionCount()) return std::nullopt;
    std::vector<size_t> path;
    switch (tree.kind) {
        case TreeKind::RegularBsp: {
            const RegularLeaf& L = regular()->leaves()[id];
            TreeNode n = tree.root;
            while (n.kind == TreeNodeKind::Cell) {
                const uint32_t mid = (n.lo[n.axis] + n.hi[n.axis]) / 2;
                const size_t side = L.lo[n.axis] >= mid ? 1 : 0;
                path.push_back(side);
                n = treeChild(n, side);
            }
            if (n.region != int64_t(id)) return std::nullopt;
            return path;
        }
        case TreeKind::Directory: {
            const RegularLeaf& L = regular()->leaves()[id];
            TreeNode n = tree.root;
            while (n.kind == TreeNodeKind::Table) {
                const size_t i = regular()->directory().tableEntryAt(n.index, n.lo, L.lo);
                path.push_back(i);
                n = treeChild(n, i);
            }
            if (n.region != int64_t(id)) return std::nullopt;
            return path;
        }
        case TreeKind::ScreenBsp: {
            const RegionInfo r = region(id);
            const bool inFrame = tree.frame == ZoneFrameKind::Camera
                                     ? r.kind == RegionKind::Slab
                                     : r.kind == RegionKind::ProjectiveSlab && r.light < 0;
            if (!inFrame || r.zone < 0) return std::nullopt;  // a light's regions: no frame's
            const ZoneFrameView& f = *frame(tree.frame);
            const uint32_t z = uint32_t(r.zone);
            const glm::dvec2 c = 0.5 * (f.zoneLo(z) + f.zoneHi(z));
            TreeNode n = tree.root;
            while (n.kind == TreeNodeKind::Cut) {
                const size_t side = c[n.axis] >= n.value ? 1 : 0;
                path.push_back(side);
                n = treeChild(n, side);
            }
            if (n.index != z) return std::nullopt;
            path.push_back(r.slab);
            return path;
        }
        case TreeKind::Bvh: {
            // Parents are not stored: walk down from the root, depth first, to the node.
            const std::vector<BvhNode>& nodes = bvh()->nodes();
            std::vector<std::pair<uint32_t, std::vector<size_t>>> stack{{0u, {}}};
            while (!stack.empty()) {
                auto [node, p] = std::move(stack.back());
                stack.pop_back();
                if (node == id) return p;
                const BvhNode& b = nodes[node];
                if (b.leaf) continue;
                for (size_t side : {size_t(1), size_t(0)}) {
                    std::vector<size_t> q = p;
                    q.push_back(side);
                    stack.push_back({b.first + uint32_t(side), std::move(q)});
                }
            }
            return std::nullopt;
        }
    }
    return std::nullopt;
}

std::string StructureView::describe(const TreeNode& n) const {
    static const char* kAxis = "xyz";
    char buf[160];
    switch (n.kind) {
        case TreeNodeKind::Cell:
            std::snprintf(buf, sizeof buf, "L%d cut %c", n.depth, kAxis[n.axis]);
            break;
        case TreeNodeKind::Leaf:
            std::snprintf(buf, sizeof buf, "leaf %lld L%d", static_cast<long long>(n.region),
                          n.depth);
            break;
        case TreeNodeKind::Table: {
            const int bits = std::countr_zero(uint32_t(n.children));
            std::snprintf(buf, sizeof buf, "%s %u: 2^%d", n.depth == 0 ? "top table" : "table",
                          n.index, bits);
            break;
        }
        case TreeNodeKind::Entry:
            std::snprintf(buf, sizeof buf, "%u: leaf %lld", n.index,
                          static_cast<long long>(n.region));
            break;
        case TreeNodeKind::Cut:
            std::snprintf(buf, sizeof buf, "%c=%.4g d%d", kAxis[n.axis], n.value, n.depth);
            break;
        case TreeNodeKind::Zone:
            std::snprintf(buf, sizeof buf, "zone %u", n.index);
            break;
        case TreeNodeKind::Slab:
            std::snprintf(buf, sizeof buf, "slab %u: %lld", n.index,
                          static_cast<long long>(n.region));
            break;
        case TreeNodeKind::BvhInner:
            std::snprintf(buf, sizeof buf, "node %u d%d", n.index, n.depth);
            break;
        case TreeNodeKind::BvhLeaf:
            std::snprintf(buf, sizeof buf, "leaf %u d%d", n.index, n.depth);
            break;
    }
    return buf;
}

}  // namespace lancer
