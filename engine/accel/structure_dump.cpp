#include "engine/accel/structure_dump.h"

#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string_view>

namespace lancer {

namespace {

/// JSON written straight into a buffer flushed to the stream by the megabyte: balls4's regular
/// dump has some 10^5 leaves, and a document tree of them would cost more than the build.
class Writer {
  public:
    explicit Writer(std::ostream& out) : out_(out) { buf_.reserve(kChunk + 4096); }
    ~Writer() { flush(); }

    void raw(std::string_view s) {
        buf_ += s;
        if (buf_.size() >= kChunk) flush();
    }
    void num(double v) {
        if (!std::isfinite(v)) return raw("null");
        char b[32];
        auto r = std::to_chars(b, b + sizeof b, v);
        raw({b, size_t(r.ptr - b)});
    }
    void num(int64_t v) {
        char b[24];
        auto r = std::to_chars(b, b + sizeof b, v);
        raw({b, size_t(r.ptr - b)});
    }
    void num(uint64_t v) {
        char b[24];
        auto r = std::to_chars(b, b + sizeof b, v);
        raw({b, size_t(r.ptr - b)});
    }
    void num(int v) { num(int64_t(v)); }
    void num(uint32_t v) { num(uint64_t(v)); }
    void str(std::string_view s) { raw(nlohmann::json(std::string(s)).dump()); }
    /// "key":
    void key(std::string_view k) {
        raw("\"");
        raw(k);
        raw("\":");
    }
    void vec(const Vec3& v) {
        raw("[");
        num(v.x);
        raw(",");
        num(v.y);
        raw(",");
        num(v.z);
        raw("]");
    }
    void vec(glm::dvec2 v) {
        raw("[");
        num(v.x);
        raw(",");
        num(v.y);
        raw("]");
    }
    void box(const Box3& b) {
        raw("[");
        vec(b.lo);
        raw(",");
        vec(b.hi);
        raw("]");
    }
    void ids(std::span<const uint32_t> v) {
        raw("[");
        for (size_t i = 0; i < v.size(); ++i) {
            if (i) raw(",");
            num(v[i]);
        }
        raw("]");
    }
    void flush() {
        out_.write(buf_.data(), std::streamsize(buf_.size()));
        buf_.clear();
    }

  private:
    static constexpr size_t kChunk = size_t(1) << 20;
    std::ostream& out_;
    std::string buf_;
};

/// A structure following a turned subtree gives its frame's axes: its bounds and boxes are
/// then coordinates along them (x = dot(axes[0], world point), ...); nothing along the world's.
void writeAxes(Writer& w, const GridFrame& f) {
    if (!f.turned) return;
    w.raw(",\"axes\":[");
    for (int a = 0; a < 3; ++a) {
        if (a) w.raw(",");
        w.vec(f.axes[a]);
    }
    w.raw("]");
}

/// docs/design.md section 6: "bvh": {"bounds", "nodes": [{"id", "depth", "box", "children"} or
/// {"id", "depth", "box", "prims"}]}.
void writeBvh(Writer& w, const Bvh& b, bool summary) {
    w.raw(",\"bvh\":{\"bounds\":");
    w.box(b.box());
    writeAxes(w, b.frame());
    w.raw(",\"node_count\":");
    w.num(uint64_t(b.nodes().size()));
    w.raw(",\"depth\":");
    w.num(uint64_t(b.depth()));
    if (!summary) {
        w.raw(",\"nodes\":[");
        for (uint32_t id = 0; id < b.nodes().size(); ++id) {
            const BvhNode& n = b.nodes()[id];
            if (id) w.raw(",");
            w.raw("{\"id\":");
            w.num(id);
            w.raw(",\"depth\":");
            w.num(uint64_t(n.depth));
            w.raw(",\"box\":");
            w.box(n.box());
            if (n.leaf) {
                w.raw(",\"prims\":");
                w.ids({b.primList().data() + n.first, n.count});
            } else {
                w.raw(",\"children\":[");
                w.num(n.first);
                w.raw(",");
                w.num(n.first + 1);
                w.raw("]");
            }
            w.raw("}");
        }
        w.raw("]");
    }
    w.raw("}");
}

void writeRegular(Writer& w, const StructureView& v, bool summary) {
    const RegularGrid& g = *v.regular();
    w.raw(",\"regular\":{\"bounds\":");
    w.box(g.box());
    writeAxes(w, g.frame());
    w.raw(",\"directory\":[");
    for (int a = 0; a < 3; ++a) {
        if (a) w.raw(",");
        w.num(v.directoryLog2(a));
    }
    w.raw("],\"leaf_count\":");
    w.num(uint64_t(g.leaves().size()));
    if (!summary) {
        w.raw(",\"leaves\":[");
        const std::vector<RegularLeaf>& leaves = g.leaves();
        for (uint32_t id = 0; id < leaves.size(); ++id) {
            const RegularLeaf& L = leaves[id];
            if (id) w.raw(",");
            w.raw("{\"id\":");
            w.num(id);
            w.raw(",\"level\":");
            w.num(v.leafLevel(id));
            w.raw(",\"box\":");
            w.box({{L.plane[0], L.plane[1], L.plane[2]}, {L.plane[3], L.plane[4], L.plane[5]}});
            w.raw(",\"prims\":");
            w.ids({L.primitives(g.primList().data()), L.prims});
            w.raw("}");
        }
        w.raw("]");
    }
    w.raw("}");
}

void writeFrame(Writer& w, const ZoneFrameView& f, const StructureDumpOptions& o, bool summary) {
    const bool px = f.units() == FrameUnits::Pixels;
    auto pt = [&](glm::dvec2 p) { return px ? f.toPixel(p, o.width, o.height) : p; };
    w.raw(f.kind() == ZoneFrameKind::Camera ? ",\"irregular\":{\"frame\":\"camera\""
                                            : ",\"projective\":{\"frame\":\"projective\"");
    w.raw(",\"units\":");
    w.str(frameUnitsName(f.units()));
    // The rectangle the zones tile, in the same units.
    glm::dvec2 a = pt(f.rectLo()), b = pt(f.rectHi());
    w.raw(",\"rect\":[");
    w.vec(glm::min(a, b));
    w.raw(",");
    w.vec(glm::max(a, b));
    w.raw("],\"bsp_node_count\":");
    w.num(uint64_t(f.bsp().nodes.size()));
    w.raw(",\"zone_count\":");
    w.num(uint64_t(f.zoneCount()));
    w.raw(",\"slab_count\":");
    w.num(uint64_t(f.slabCount()));
    if (!summary) {
        w.raw(",\"bsp\":[");
        bool first = true;
        for (const BspCut& c : f.cuts()) {
            if (!first) w.raw(",");
            first = false;
            w.raw("{\"node\":");
            w.num(c.node);
            w.raw(",\"depth\":");
            w.num(c.depth);
            w.raw(",\"segment\":[");
            w.vec(pt(c.a));
            w.raw(",");
            w.vec(pt(c.b));
            w.raw("]}");
        }
        w.raw("],\"zones\":[");
        first = true;
        for (uint32_t z = 0; z < f.zoneCount(); ++z) {
            std::vector<glm::dvec2> poly = f.zonePolygon(z, o.width, o.height);
            if (poly.empty()) continue;  // wholly outside the image
            if (!first) w.raw(",");
            first = false;
            w.raw("{\"id\":");
            w.num(z);
            w.raw(",\"polygon\":[");
            for (size_t i = 0; i < poly.size(); ++i) {
                if (i) w.raw(",");
                w.vec(poly[i]);
            }
            w.raw("],\"prims\":");
            w.ids(f.zonePrims(z));
            w.raw(",\"slabs\":[");
            bool firstSlab = true;
            for (const SlabInfo& s : f.slabs(z)) {
                if (!firstSlab) w.raw(",");
                firstSlab = false;
                w.raw("{\"region\":");
                w.num(s.region);
                w.raw(",\"z0\":");
                w.num(s.z0);
                w.raw(",\"z1\":");
                w.num(s.z1);
                w.raw(",\"prims\":");
                w.ids(s.prims);
                w.raw("}");
            }
            w.raw("]}");
        }
        w.raw("]");
    }
    w.raw("}");
}

}  // namespace

bool dumpIsSummary(const StructureView& view, const StructureDumpOptions& o) {
    return !o.all && view.regionCount() > o.limit;
}

void writeStructureJson(const StructureView& view, const StructureDumpOptions& o,
                        std::ostream& out) {
    const Scene& scene = view.scene();
    const bool summary = dumpIsSummary(view, o);
    Writer w(out);
    w.raw("{\"scheme\":");
    w.str(schemeName(view.scheme()));
    w.raw(",\"width\":");
    w.num(o.width);
    w.raw(",\"height\":");
    w.num(o.height);
    // The sidecar's keys (Camera::toJson, the viewer's Copy JSON) with the image size.
    nlohmann::json cam = nlohmann::json::parse(scene.camera.toJson());
    cam["width"] = o.width;
    cam["height"] = o.height;
    w.raw(",\"camera\":");
    w.raw(cam.dump());
    w.raw(",\"regions\":");
    w.num(uint64_t(view.regionCount()));
    w.raw(",\"summary\":");
    w.raw(summary ? "true" : "false");

    std::vector<char> live(scene.prims.size(), 0);
    for (uint32_t p : scene.livePrimitives()) live[p] = !scene.minBox[p].isEmpty();
    w.raw(",\"primitives\":[");
    for (uint32_t p = 0; p < scene.prims.size(); ++p) {
        if (p) w.raw(",");
        w.raw("{\"id\":");
        w.num(p);
        w.raw(",\"kind\":");
        w.str(shapeName(scene.prims[p].shape));
        w.raw(live[p] ? ",\"live\":true,\"box\":" : ",\"live\":false,\"box\":");
        if (scene.minBox[p].isEmpty())
            w.raw("null");
        else
            w.box(scene.minBox[p]);
        w.raw("}");
    }
    w.raw("]");

    if (view.regular()) writeRegular(w, view, summary);
    if (const Bvh* b = view.bvh()) writeBvh(w, *b, summary);
    for (const ZoneFrameView& f : view.frames()) writeFrame(w, f, o, summary);
    w.raw("}\n");
}

}  // namespace lancer
