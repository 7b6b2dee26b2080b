#include "engine/scene/openscad/dxf.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <unordered_map>

#include "engine/scene/scene.h"
#include "engine/scene/source_text.h"

namespace lancer::openscad {

int Fragments::of(double r) const {
    // Clamped before the cast: a $fn of 1e20 is a count no int holds (the caller refuses it).
    return int(std::min(fragmentsFromR(r, fn, fa, fs), 1e9));
}

namespace {

/// One group of a DXF file: its code, its value line, and where the value starts.
struct Group {
    int code;
    std::string value;
    size_t pos;
};

std::vector<Group> groups(const SourceText& src) {
    const std::string& t = src.text();
    std::vector<Group> out;
    size_t at = 0;
    auto line = [&](size_t& start) {
        start = at;
        size_t end = t.find('\n', at);
        if (end == std::string::npos) end = t.size();
        std::string s = t.substr(at, end - at);
        at = end < t.size() ? end + 1 : end;
        const size_t a = s.find_first_not_of(" \t\r"), b = s.find_last_not_of(" \t\r");
        return a == std::string::npos ? std::string() : s.substr(a, b - a + 1);
    };
    while (at < t.size()) {
        size_t codePos, valuePos;
        const std::string code = line(codePos);
        if (code.empty() && at >= t.size()) break;
        if (at >= t.size()) src.fail(codePos, "a group code without its value (the file ends)");
        const std::string value = line(valuePos);
        int c = 0;
        size_t used = 0;
        try {
            c = std::stoi(code, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != code.size())
            src.fail(codePos, "expected a DXF group code (an integer), found '" + code + "'");
        out.push_back({c, value, valuePos});
        if (c == 0 && value == "EOF") break;
    }
    return out;
}

/// An entity: its type and its groups up to the next entity.
struct Entity {
    std::string type;
    size_t pos;
    std::vector<const Group*> g;
};

/// The most segments one circle or arc is cut into (a polygon's edges are capped at 20,000).
constexpr int kMaxCurveSegments = 20000;

class Reader {
  public:
    Reader(const SourceText& src, const std::string& layer, const Vec2& origin, double scale,
           const Fragments& frag)
        : src_(src), layer_(layer), origin_(origin), scale_(scale), frag_(frag) {}

    double number(const Group& g) const {
        size_t used = 0;
        double v = 0.0;
        try {
            v = std::stod(g.value, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        if (used == 0 || used != g.value.size() || !std::isfinite(v))
            src_.fail(g.pos, "expected a number for DXF group code " + std::to_string(g.code) +
                                 ", found '" + g.value + "'");
        return v;
    }
    double first(const Entity& e, int code, double fallback) const {
        for (const Group* g : e.g)
            if (g->code == code) return number(*g);
        return fallback;
    }
    std::string text(const Entity& e, int code) const {
        for (const Group* g : e.g)
            if (g->code == code) return g->value;
        return "";
    }

    void read(const std::vector<Group>& gs) {
        // Entities, with the section and block they belong to.
        std::string section, block;
        std::vector<Entity> polyline;  // a POLYLINE and its VERTEX entities, until SEQEND
        for (size_t i = 0; i < gs.size();) {
            if (gs[i].code != 0) {
                ++i;  // header variables and table records outside entities
                continue;
            }
            Entity e{gs[i].value, gs[i].pos, {}};
            for (++i; i < gs.size() && gs[i].code != 0; ++i) e.g.push_back(&gs[i]);
            if (e.type == "SECTION") {
                section = text(e, 2);
            } else if (e.type == "ENDSEC") {
                section.clear();
            } else if (section == "BLOCKS" && e.type == "BLOCK") {
                block = text(e, 2);
                blocks_[block];
            } else if (section == "BLOCKS" && e.type == "ENDBLK") {
                block.clear();
            } else if (section == "BLOCKS" || section == "ENTITIES") {
                const bool inBlock = section == "BLOCKS";
                if (inBlock && block.empty()) continue;
                if (e.type == "POLYLINE" || (!polyline.empty() && e.type == "VERTEX")) {
                    polyline.push_back(std::move(e));
                    continue;
                }
                if (e.type == "SEQEND") {
                    if (!polyline.empty()) entity(polyline.front(), &polyline, inBlock, block);
                    polyline.clear();
                    continue;
                }
                entity(e, nullptr, inBlock, block);
            }
        }
    }

    /// Chains the segments into paths by their ends and keeps the closed ones.
    DxfOutlines outlines() {
        DxfOutlines out;
        out.entities = entities_;
        // Ends within 1e-3 are one point (OpenSCAD's GRID_COARSE).
        constexpr double kGrid = 1e-3;
        std::vector<Vec2> pts;
        std::unordered_map<int64_t, std::vector<uint32_t>> cells;
        auto cellKey = [](int64_t x, int64_t y) { return (x << 32) ^ (y & 0xffffffff); };
        auto point = [&](const Vec2& p) {
            const int64_t cx = int64_t(std::floor(p.x / kGrid)),
                          cy = int64_t(std::floor(p.y / kGrid));
            for (int64_t dx = -1; dx <= 1; ++dx)
                for (int64_t dy = -1; dy <= 1; ++dy) {
                    auto it = cells.find(cellKey(cx + dx, cy + dy));
                    if (it == cells.end()) continue;
                    for (uint32_t k : it->second)
                        if (glm::length(pts[k] - p) < kGrid) return k;
                }
            pts.push_back(p);
            cells[cellKey(cx, cy)].push_back(uint32_t(pts.size() - 1));
            return uint32_t(pts.size() - 1);
        };
        std::vector<std::pair<uint32_t, uint32_t>> edges;
        for (const auto& [a, b] : segments_) {
            const uint32_t i = point(a), j = point(b);
            if (i != j) edges.push_back({i, j});
        }
        std::vector<std::vector<uint32_t>> at(pts.size());
        for (uint32_t e = 0; e < edges.size(); ++e) {
            at[edges[e].first].push_back(e);
            at[edges[e].second].push_back(e);
        }
        // Chains start at the ends of open paths (points on one segment) first, as OpenSCAD's
        // DxfData, so that an open path is one chain; what is left forms closed loops.
        std::vector<bool> used(edges.size(), false);
        auto chain = [&](uint32_t s, uint32_t from) {
            used[s] = true;
            std::vector<Vec2> loop{pts[from]};
            uint32_t cur = edges[s].first == from ? edges[s].second : edges[s].first;
            bool closed = false;
            for (;;) {
                if (cur == from) {
                    closed = true;
                    break;
                }
                loop.push_back(pts[cur]);
                uint32_t next = UINT32_MAX;
                for (uint32_t e : at[cur])
                    if (!used[e]) {
                        next = e;
                        break;
                    }
                if (next == UINT32_MAX) break;
                used[next] = true;
                cur = edges[next].first == cur ? edges[next].second : edges[next].first;
            }
            // OpenSCAD closes an open path by its ends ("to be compatible with existing
            // behavior"), so it is kept, closed, and counted.
            if (!closed) ++out.openChains;
            if (loop.size() >= 3) out.loops.push_back(std::move(loop));
        };
        for (uint32_t p = 0; p < pts.size(); ++p)
            if (at[p].size() == 1 && !used[at[p][0]]) chain(at[p][0], p);
        for (uint32_t s = 0; s < edges.size(); ++s)
            if (!used[s]) chain(s, edges[s].first);
        return out;
    }

  private:
    using Segment = std::pair<Vec2, Vec2>;

    /// A polyline's arc segment (its bulge, group 42): OpenSCAD would draw a straight edge.
    [[noreturn]] void refuseBulge(size_t pos) const {
        src_.fail(pos,
                  "a polyline with an arc (bulge) segment is not supported: OpenSCAD reads "
                  "its ends as a straight edge");
    }

    /// An entity's segments, in drawing units: into a block's list, or (on the layer) into the
    /// drawing's, with the origin and scale applied.
    void entity(const Entity& e, const std::vector<Entity>* vertices, bool inBlock,
                const std::string& block) {
        std::vector<Segment> segs;
        const std::string& t = e.type;
        if (t == "LINE") {
            segs.push_back(
                {{first(e, 10, 0.0), first(e, 20, 0.0)}, {first(e, 11, 0.0), first(e, 21, 0.0)}});
        } else if (t == "CIRCLE" || t == "ARC") {
            const Vec2 c(first(e, 10, 0.0), first(e, 20, 0.0));
            const double r = first(e, 40, 0.0);
            double a0 = 0.0, a1 = 360.0;
            int n = frag_.of(r);
            if (t == "ARC") {
                // Angles into [0, 360) (OpenSCAD adds 360 until they are; fmod does it at once).
                a0 = std::fmod(first(e, 50, 0.0), 360.0);
                a1 = std::fmod(first(e, 51, 0.0), 360.0);
                if (a0 < 0.0) a0 += 360.0;
                if (a1 < 0.0) a1 += 360.0;
                if (a0 > a1) a1 += 360.0;
                n = int(std::ceil(std::max(n * (a1 - a0) / 360.0, 1.0)));
            }
            if (n > kMaxCurveSegments)
                src_.fail(e.pos, "a " + t + " of " + std::to_string(n) +
                                     " segments (by $fn, $fa, "
                                     "$fs): Lancer cuts a curve into at most " +
                                     std::to_string(kMaxCurveSegments));
            auto on = [&](int i) {
                const double a = glm::radians(a0 + (a1 - a0) * i / n);
                return c + r * Vec2(std::cos(a), std::sin(a));
            };
            for (int i = 0; i < n; ++i) segs.push_back({on(i), on(i + 1)});
        } else if (t == "LWPOLYLINE" || t == "POLYLINE") {
            std::vector<Vec2> p;
            if (t == "LWPOLYLINE") {
                for (const Group* g : e.g) {
                    if (g->code == 10) p.push_back({number(*g), 0.0});
                    if (g->code == 20 && !p.empty()) p.back().y = number(*g);
                    if (g->code == 42 && number(*g) != 0.0) refuseBulge(g->pos);
                }
            } else {
                for (size_t k = 1; vertices && k < vertices->size(); ++k) {
                    const Entity& v = (*vertices)[k];
                    if (first(v, 42, 0.0) != 0.0) refuseBulge(v.pos);
                    p.push_back({first(v, 10, 0.0), first(v, 20, 0.0)});
                }
            }
            for (size_t k = 0; k + 1 < p.size(); ++k) segs.push_back({p[k], p[k + 1]});
            if ((int(first(e, 70, 0.0)) & 1) && p.size() > 2) segs.push_back({p.back(), p.front()});
        } else if (t == "INSERT") {
            const std::string name = text(e, 2);
            auto it = blocks_.find(name);
            if (it == blocks_.end())
                src_.fail(e.pos,
                          "INSERT of the block '" + name + "', which is not defined before it");
            const Vec2 at(first(e, 10, 0.0), first(e, 20, 0.0));
            const Vec2 s(first(e, 41, 1.0), first(e, 42, 1.0));
            const double a = glm::radians(first(e, 50, 0.0)), c = std::cos(a), sn = std::sin(a);
            auto place = [&](const Vec2& p) {
                const Vec2 q = p * s;
                return at + Vec2(c * q.x - sn * q.y, sn * q.x + c * q.y);
            };
            for (const Segment& g : it->second) segs.push_back({place(g.first), place(g.second)});
        } else {
            return;  // TEXT, DIMENSION, HATCH, ...: OpenSCAD draws no outline of them
        }
        if (inBlock) {
            auto& b = blocks_[block];
            b.insert(b.end(), segs.begin(), segs.end());
            return;
        }
        if (!layer_.empty() && text(e, 8) != layer_) return;
        ++entities_;
        for (const Segment& g : segs)
            segments_.push_back({(g.first - origin_) * scale_, (g.second - origin_) * scale_});
    }

    const SourceText& src_;
    std::string layer_;
    Vec2 origin_;
    double scale_;
    Fragments frag_;
    std::map<std::string, std::vector<Segment>> blocks_;
    std::vector<Segment> segments_;
    int entities_ = 0;
};

}  // namespace

DxfOutlines readDxf(const std::string& path, const std::string& layer, const Vec2& origin,
                    double scale, const Fragments& frag) {
    return readDxfText(SourceText::fromImportedFile(path, "a DXF drawing"), layer, origin, scale,
                       frag);
}

DxfOutlines readDxfText(const SourceText& src, const std::string& layer, const Vec2& origin,
                        double scale, const Fragments& frag) {
    const std::vector<Group> gs = groups(src);
    Reader r(src, layer, origin, scale, frag);
    r.read(gs);
    return r.outlines();
}

}  // namespace lancer::openscad
