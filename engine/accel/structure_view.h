// A description of a built structure, for every scheme, that the overlays, the 3D inspector,
// `lancer structure` and the tests read: regions with their volume as 8 world-space corners,
// primitives, restricted trees and neighbours; the regular scheme's leaves, directory blocks and
// cut planes; the irregular scheme's screen BSPs (camera frame, projective zones), zones and
// slabs. It reads the built structure in place and computes everything on demand: the
// irregular scheme on balls4 has millions of regions, so nothing is stored per region.
//
// Region ids are the ids the walk reports to the observer (observer.h): brute force has one
// region (the scene box); the regular scheme's are its leaves; the BVH's are its nodes, inner
// and leaf; the irregular scheme's are its camera-frame regions, then from
// IrregularSubdivision::regions().size() on the projective slabs in zone order, the near region
// last (projective_zones.h).
#pragma once

#include <array>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "engine/accel/accelerator.h"

namespace lancer {

/// What kind of volume a region is.
enum class RegionKind : uint8_t {
    SceneBox,        ///< brute force: the scene's bounds
    Leaf,            ///< regular: a BSP leaf, a box of the world
    Slab,            ///< irregular: a depth slab of a camera-frame zone, a box of the camera frame
    ProjectiveSlab,  ///< irregular: a depth slab of a projective zone (a piece of a pyramid)
    NearRegion,      ///< irregular: the projective near region, depth [0, zNear] of every pixel
    BvhInner,        ///< BVH: an inner node, a box of the world holding its two children's
    BvhLeaf,         ///< BVH: a leaf, a box of the world listing the primitives meeting it
};
const char* regionKindName(RegionKind k);

/// The irregular scheme's two screen frames (docs/design.md section 4).
enum class ZoneFrameKind : uint8_t {
    Camera,      ///< screen x along R, screen y along U (scene units)
    Projective,  ///< u = x / z, v = y / z (primary rays only)
};
/// Units a frame's 2D coordinates are given in by the dump (docs/design.md section 6): pixels when
/// the frame maps linearly to the image (orthographic camera frame, projective zones), camera
/// units (scene units) for a perspective camera's camera frame.
enum class FrameUnits : uint8_t { Pixels, Camera };
const char* frameUnitsName(FrameUnits u);

/// Neighbour values of RegionInfo::lo / hi besides region ids.
inline constexpr int64_t kNoNeighbour = -1;        ///< the face lies on the structure's border
inline constexpr int64_t kSeveralNeighbours = -2;  ///< regular: several leaves across the face
inline constexpr int64_t kNotLinked = -3;          ///< the scheme keeps no link across this face

/// One region, read from the structure (cheap: no per-region storage is kept).
struct RegionInfo {
    uint32_t id = 0;
    RegionKind kind = RegionKind::SceneBox;
    /// The region's box in its own frame: world (brute force), the grid's (regular), camera frame
    /// (x, y, depth; slabs), projective (u, v, depth; projective slabs and the near region).
    Box3 frameBox;
    int level = -1;  ///< regular: BSP level of the leaf; BVH: the node's depth; -1 otherwise
    uint32_t cellLo[3] = {}, cellHi[3] = {};  ///< regular: directory cells [lo, hi) per axis
    int64_t zone = -1;  ///< irregular: zone in its frame's BSP; -1 for the near region
    /// Irregular projective slabs and near regions: the scene light whose structure holds the
    /// region (its frame is centred on the light; shadow rays walk it toward the light); -1:
    /// the eye's.
    int light = -1;
    uint32_t slab = 0;  ///< irregular: index of the slab in its zone, by increasing depth
    /// Primitives listed in the region (tracer ids), sorted: those whose minimized box (its
    /// bound in the region's frame, irregular) crosses the region; the regular scheme keeps
    /// only those its restricted tree keeps (the others cannot contribute there).
    std::span<const uint32_t> prims;
    const CsgTree* pool = nullptr;  ///< the pool holding the region's restricted tree
    int root = -1;                  ///< restricted tree's root in `pool`; -1: empty
    /// Neighbours across the low and high face of each frame axis: regular ropes (one leaf
    /// covers the face, or kSeveralNeighbours); irregular corner pointers (region.h: the region
    /// just beyond the low / high corner across that face); projective slabs: the previous /
    /// next slab in depth, kNotLinked across screen faces. kNoNeighbour on the border.
    int64_t lo[3] = {kNoNeighbour, kNoNeighbour, kNoNeighbour};
    int64_t hi[3] = {kNoNeighbour, kNoNeighbour, kNoNeighbour};
};

/// Regular scheme: one cut of the BSP, a plane across the cell of an inner node.
struct CutPlane {
    int axis = 0;        ///< 0 x, 1 y, 2 z
    double value = 0.0;  ///< coordinate of the plane in the grid's frame
    int level = 0;       ///< the node's level (the root is level 0)
    Box3 cell;  ///< the node's cell in the grid's frame (the plane's rectangle is its section)
    uint32_t cellLo[3] = {}, cellHi[3] = {};  ///< the cell in directory cells, [lo, hi)
};

/// Regular scheme: one entry of the directory (directory.h): a block of finest cells stored as
/// a single entry naming a leaf, or a block stored as a sub-table of its own.
struct DirectoryBlock {
    uint32_t lo[3] = {}, hi[3] = {};  ///< directory cells [lo, hi) per axis
    bool subTable = false;            ///< true: a sub-table's block; false: one entry
    uint32_t leaf = 0;                ///< the leaf, for an entry
    uint32_t child = 0;               ///< the sub-table storing the block (subTable)
    uint32_t table = 0;               ///< the table holding this entry
    int depth = 0;                    ///< tables above it (0: the top table)
    /// BSP level: an entry's is its leaf's (RegionInfo::level); a sub-table's, the level of the
    /// BSP node whose cell it stores.
    int level = 0;
};

/// Irregular scheme: one node of a screen BSP, in the order the cuts were made.
struct BspCut {
    uint32_t node = 0;
    int depth = 0;  ///< the root is depth 0
    int axis = 0;   ///< 0: the line x = value, 1: the line y = value (frame units)
    double value = 0.0;
    glm::dvec2 a{0.0}, b{0.0};  ///< the cut line clipped to the node's cell, frame units
};

/// Irregular scheme: one depth slab of a zone.
struct SlabInfo {
    uint32_t region = 0;              ///< region id (as the walk reports it)
    double z0 = 0.0, z1 = 0.0;        ///< depth along F, increasing
    std::span<const uint32_t> prims;  ///< its primitives
};

/// One screen frame of the irregular scheme: its 2D BSP, zones and slabs. Coordinates are frame
/// units (camera frame: scene units on R and U; projective: u, v); toPixel maps them to the
/// image when mapsToImage().
class ZoneFrameView {
  public:
    ZoneFrameView(const Scene& scene, const IrregularSubdivision& s, ZoneFrameKind kind);

    ZoneFrameKind kind() const { return kind_; }
    /// Pixels when the frame maps linearly to the image, else camera units.
    FrameUnits units() const { return mapsToImage() ? FrameUnits::Pixels : FrameUnits::Camera; }
    /// Orthographic camera frame, or projective zones.
    bool mapsToImage() const;
    /// The screen rectangle the BSP subdivides, frame units.
    glm::dvec2 rectLo() const { return lo_; }
    glm::dvec2 rectHi() const { return hi_; }
    const ScreenBsp& bsp() const { return *bsp_; }
    size_t zoneCount() const { return bsp_->zoneCount(); }
    /// Regions of this frame's slabs (the near region not counted).
    size_t slabCount() const;

    /// Every node with its depth and its cut clipped to the node's cell, in cut order.
    std::vector<BspCut> cuts() const;
    /// Zone z's rectangle, frame units.
    glm::dvec2 zoneLo(uint32_t z) const { return bsp_->zoneLo[z]; }
    glm::dvec2 zoneHi(uint32_t z) const { return bsp_->zoneHi[z]; }
    /// Primitives whose rectangle touches zone z.
    std::span<const uint32_t> zonePrims(uint32_t z) const;
    /// Zone z's slabs, by increasing depth.
    std::vector<SlabInfo> slabs(uint32_t z) const;
    /// The region ids of the slabs of zones [z0, z1): [first, last), zones' slabs being
    /// numbered in zone order.
    std::pair<uint32_t, uint32_t> zoneRegions(uint32_t z0, uint32_t z1) const;
    /// The first and last zone below BSP reference `ref` (a node, or ~zone): the BSP numbers
    /// its zones depth first (screen_bsp.cpp, renumber), so a node's are consecutive. The
    /// nodes' spans are found in one pass on the first call (thread-safe), then read.
    std::pair<uint32_t, uint32_t> zoneSpan(int32_t ref) const;
    /// Zone z's whole column as 8 world corners (the regionCorners order): its rectangle through
    /// the depth of its slabs; a box of the camera frame, or a frustum of the projective frame.
    std::array<Vec3, 8> zoneCorners(uint32_t z) const;
    /// Zone holding the frame point (x, y); -1 outside the rectangle.
    int64_t zoneAt(glm::dvec2 p) const;

    /// Frame point to continuous image coordinates of a w x h image (x right from the left edge,
    /// y down from the top edge, pixel (i, j) covering [i, i+1] x [j, j+1]). Only when
    /// mapsToImage().
    glm::dvec2 toPixel(glm::dvec2 p, int w, int h) const;
    glm::dvec2 fromPixel(glm::dvec2 px, int w, int h) const;
    /// Zone z as a convex polygon in the dump's units (units()): clipped to the w x h image in
    /// pixels, or to the frame's rectangle in camera units; vertices (lo, lo), (hi, lo),
    /// (hi, hi), (lo, hi) of those coordinates; empty when nothing of it is left. The zones of
    /// a frame tile its rectangle, so in pixels they tile the part of the image the rectangle
    /// covers (all of it when the structure's rectangle covers the image).
    std::vector<glm::dvec2> zonePolygon(uint32_t z, int w, int h) const;
    /// Zone under the image point (x, y) of a w x h image, continuous coordinates (pixel (i, j)'s
    /// centre is (i + 0.5, j + 0.5)): the zone its primary ray stays in (orthographic camera
    /// frame, projective), or for a perspective camera frame the zone where that ray is at depth
    /// `depth`. -1 outside the frame's rectangle.
    int64_t zoneAtPixel(double x, double y, int w, int h, double depth = 1.0) const;

  private:
    const Scene* scene_;
    const IrregularSubdivision* s_;
    ZoneFrameKind kind_;
    const ScreenBsp* bsp_;
    glm::dvec2 lo_{0.0}, hi_{0.0};
    uint32_t first_ = 0;  ///< region id of the first slab of zone 0
    double half_ = 1.0;   ///< half the image height in frame units (ortho height / 2, tan(fov/2))
    /// Each node's first and last zone (zoneSpan), made on first use.
    struct Spans {
        std::once_flag once;
        std::vector<std::pair<uint32_t, uint32_t>> node;
    };
    std::shared_ptr<Spans> spans_ = std::make_shared<Spans>();
};

/// The trees a structure is made of, as the viewer's tree browser lists them.
enum class TreeKind : uint8_t {
    RegularBsp,  ///< regular: the BSP, from the scene box down to the leaves
    Directory,   ///< regular: the directory's top table, its entries and sub-tables
    ScreenBsp,   ///< irregular: a screen frame's 2D BSP, its zones and their slabs
    Bvh,         ///< BVH: the nodes from the root
};
/// What a node of a structure's tree is.
enum class TreeNodeKind : uint8_t {
    Cell,      ///< regular BSP: an inner node's cell, cut in two
    Leaf,      ///< regular BSP: a leaf (a region)
    Table,     ///< directory: a table (the top one, or a sub-table an entry names)
    Entry,     ///< directory: an entry naming a leaf
    Cut,       ///< screen BSP: an inner node, its line
    Zone,      ///< screen BSP: a zone (a leaf of the 2D BSP), its slabs below it
    Slab,      ///< screen BSP: a slab of a zone (a region)
    BvhInner,  ///< BVH: an inner node (a region)
    BvhLeaf,   ///< BVH: a leaf (a region)
};
const char* treeNodeKindName(TreeNodeKind k);

/// One node of a structure's tree, read from the structure on demand (only the nodes a caller
/// asks for are made, so a tree of millions of nodes costs what is listed). Plain data: what
/// locates the node in its scheme travels with it, for its children.
struct TreeNode {
    TreeKind tree = TreeKind::RegularBsp;
    ZoneFrameKind frame = ZoneFrameKind::Camera;  ///< ScreenBsp: the frame it belongs to
    TreeNodeKind kind = TreeNodeKind::Cell;
    int depth = 0;        ///< the root is 0
    size_t children = 0;  ///< child count (treeChild(node, i) for i < children)
    int64_t region = -1;  ///< the region this node is (a leaf, a slab, a BVH node, an entry's
                          ///< leaf); -1 for a group of regions
    /// The regions under it (itself included) are ids [regionLo, regionHi) when `ranged`: the
    /// regular leaves, the zones' slabs are numbered depth first, so a subtree's are together.
    bool ranged = false;
    uint32_t regionLo = 0, regionHi = 0;
    int64_t prims = -1;  ///< primitives listed (a leaf's, a zone's, a slab's); -1 for none
    uint32_t index = 0;  ///< its number in its scheme: BVH node, screen BSP node, zone, table
    uint32_t lo[3] = {}, hi[3] = {};  ///< regular and directory: directory cells [lo, hi)
    int axis = -1;                    ///< Cell, Cut: the axis cut (Cut: 0 x, 1 y)
    double value = 0.0;               ///< Cut: the line's coordinate; Slab: its near depth
    double value2 = 0.0;              ///< Slab: its far depth
};

/// One tree of a structure: its name for people and its root.
struct StructureTree {
    TreeKind kind = TreeKind::RegularBsp;
    ZoneFrameKind frame = ZoneFrameKind::Camera;
    std::string name;  ///< "BSP", "directory", "screen BSP (projective)", "BVH"
    TreeNode root;
};

/// The description of a built structure; holds references to the scene and the accelerator,
/// which must outlive it.
class StructureView {
  public:
    StructureView(const Scene& scene, const Accelerator& accel);

    SchemeKind scheme() const { return accel_->params().scheme; }
    const Scene& scene() const { return *scene_; }
    const Accelerator& accelerator() const { return *accel_; }

    /// Every region the walk can report, ids [0, regionCount()).
    size_t regionCount() const;
    /// Region `id`'s volume as 8 world-space corners, corner c = i + 2j + 4k with i, j, k the
    /// low (0) or high (1) side along the region's own axes (regular and brute force: x, y, z;
    /// camera frame: R, U, F; projective: u, v, depth), the trace contract's order (docs/design.md
    /// section 6). Regions are finite: every scheme's structure is bounded.
    std::array<Vec3, 8> regionCorners(uint32_t id) const;
    /// Region `id`: kind, frame box, level or zone, primitives, restricted tree, neighbours.
    RegionInfo region(uint32_t id) const;
    /// One line: id, box, level / zone, primitive count (regular: RegularGrid::describeLeaf).
    std::string toString(uint32_t id) const;
    /// The region holding a world point, for picking in 3D (clamped into the structure): brute
    /// force 0, the regular leaf, the irregular camera-frame region (projective regions are
    /// reached from pixels: ZoneFrameView::zoneAtPixel). Needs regionCount() > 0 (an irregular
    /// structure over an empty scene has no region).
    uint32_t regionAt(const Vec3& world) const;
    /// The structure's box in the world: scene bounds, the regular grid's box, the irregular
    /// bounds' box in the world (a box of the camera frame: see structureCorners).
    Box3 worldBounds() const;
    /// The structure's bounds as 8 world corners (the irregular camera frame's bounds are not
    /// axis-aligned in the world).
    std::array<Vec3, 8> structureCorners() const;

    // Regular scheme (nullptr / empty otherwise). Its boxes, planes and cells are in the grid's
    // frame (RegularGrid::frame(): the world's axes unless the grid follows a turned subtree);
    // corners are the world's.
    const RegularGrid* regular() const;
    /// Directory cells [lo, hi) per axis as 8 world corners (the regionCorners order).
    std::array<Vec3, 8> gridCorners(const uint32_t lo[3], const uint32_t hi[3]) const;
    /// log2 of the directory's size on each axis.
    int directoryLog2(int axis) const;
    /// BSP level of a leaf, from its cell counts and the axis schedule.
    int leafLevel(uint32_t leaf) const;
    /// BSP level of the node whose cell is directory cells [lo, hi) (each axis cut in halves).
    int cellLevel(const uint32_t lo[3], const uint32_t hi[3]) const;
    /// The BSP's cut planes, by level (breadth first), derived from the leaves' cells: a node
    /// is an inner node when the directory does not give one leaf covering exactly its cell.
    std::vector<CutPlane> cutPlanes() const;
    /// The directory's entries and sub-tables, depth first.
    std::vector<DirectoryBlock> directoryBlocks() const;

    // Irregular scheme (nullptr / empty otherwise).
    const IrregularSubdivision* irregular() const;
    // BVH (nullptr otherwise).
    const Bvh* bvh() const;
    /// The screen frames present: the camera frame always, the projective one when primary rays
    /// walk it.
    const std::vector<ZoneFrameView>& frames() const { return frames_; }
    /// The frame of `kind`, or nullptr when absent.
    const ZoneFrameView* frame(ZoneFrameKind kind) const;

    // Trees, for every scheme (brute force has none): read on demand, node by node.
    /// The scheme's trees: regular, the BSP and the directory; irregular, each screen frame's
    /// BSP (projective first when present); BVH, its nodes. A scheme added to Accelerator::Impl
    /// without an answer here does not compile.
    std::vector<StructureTree> trees() const;
    /// Child `i` (< node.children) of `node`, in the scheme's order (low half first; below
    /// the line first; slabs by depth; a table's entries in forEachEntry's order).
    TreeNode treeChild(const TreeNode& node, size_t i) const;
    /// The child indices from `tree`'s root down to the node that is region `id` (for the
    /// directory, the entry holding the leaf's first cell); nullopt when the tree has no node
    /// for it (another frame's slab, the near region).
    std::optional<std::vector<size_t>> treePath(const StructureTree& tree, uint32_t id) const;
    /// A short name for the node, for a narrow column: "L3 cut x" (a BSP cell at level 3),
    /// "leaf 12 L5", "x=0.25 d2" (a screen cut at depth 2), "zone 4", "slab 1: 97" (its region),
    /// "table 2: 2^6" (entries), "5: leaf 9" (entry 5), "node 3 d1", "leaf 8 d3" (BVH).
    std::string describe(const TreeNode& node) const;

  private:
    TreeNode regularCell(const uint32_t lo[3], const uint32_t hi[3], int depth) const;
    TreeNode directoryEntry(uint32_t table, const uint32_t origin[3], size_t i, int depth) const;
    TreeNode directoryTable(uint32_t table, const uint32_t lo[3], const uint32_t hi[3],
                            int depth) const;
    TreeNode screenRef(const ZoneFrameView& f, int32_t ref, int depth) const;
    TreeNode bvhNode(uint32_t node) const;

    const Scene* scene_;
    const Accelerator* accel_;
    std::vector<uint32_t> live_;  ///< brute force: the one region's primitives
    std::vector<ZoneFrameView> frames_;
};

}  // namespace lancer
