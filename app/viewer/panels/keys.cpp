#include "app/viewer/panels/keys.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace lancer::viewer {

namespace {

std::string number(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

/// Levels lo..hi in the fixed level palette; those from kLevelRamp on share one swatch.
Key levelKey(const std::string& title, int lo, int hi) {
    Key k{title, {}};
    for (int l = std::max(lo, 0); l <= std::min(hi, kLevelRamp - 1); ++l)
        k.swatches.push_back({{}, levelColor(l), std::to_string(l)});
    if (hi >= kLevelRamp)
        k.swatches.push_back({{}, levelColor(kLevelRamp), std::to_string(kLevelRamp).append("+")});
    return k;
}

/// The fixed log scale of counts, in steps of 1, 2, 5 per decade.
Key countKey(const std::string& title) {
    Key k;
    k.title.append(title).append(" (log)");
    double decade = 1.0;
    for (int d = 0; d <= kCountDecades; ++d, decade *= 10.0)
        for (double step : {1.0, 2.0, 5.0}) {
            const double v = step * decade;
            if (d == kCountDecades && step > 1.0) break;
            k.swatches.push_back({{}, countColor(v), number(v) + (d == kCountDecades ? "+" : "")});
        }
    return k;
}

/// The fixed log scale of costs on the structure, by decade, and 0 (no ray) apart.
Key costKey(const std::string& what, overlay::CostKind kind, CostRays rays, bool known) {
    Key k;
    k.title.append(what)
        .append(" by ")
        .append(overlay::costKindName(kind))
        .append(", ")
        .append(costRaysName(rays))
        .append(known ? " (log)" : " (counting...)");
    k.swatches.push_back({{}, costColor(0.0), "0"});
    double decade = 1.0;
    for (int d = 0; d <= kCostDecades; ++d, decade *= 10.0) {
        std::string label = decade >= 1e6   ? number(decade / 1e6) + "M"
                            : decade >= 1e3 ? number(decade / 1e3) + "k"
                                            : number(decade);
        k.swatches.push_back({{}, costColor(decade), label + (d == kCostDecades ? "+" : "")});
    }
    return k;
}

Key heatKey(const KeyInput& in) {
    const float s = in.heatScale > 0.0f ? in.heatScale : 1.0f;
    const char* unit = in.mode == ViewMode::TimeUs ? " us" : "";
    Key k;
    k.title.append(viewModeName(in.mode))
        .append(" per pixel")
        .append(in.diverging ? ", old - new" : "")
        .append(in.logScale ? ", log scale" : ", linear");
    if (in.diverging) {
        for (float f : {-1.0f, -0.5f, 0.0f, 0.5f, 1.0f}) {
            const float d = f * s;
            std::string label(d > 0.0f ? "+" : "");
            label.append(number(double(d))).append(f == 1.0f ? unit : "");
            k.swatches.push_back({{}, divergingColor(diffValue(d, s, in.logScale)), label});
        }
        return k;
    }
    std::vector<float> values{0.0f};
    if (in.logScale) {
        for (float v = 1.0f; v < s; v *= 10.0f) values.push_back(v);
        values.push_back(s);
    } else {
        for (float f : {0.25f, 0.5f, 0.75f, 1.0f}) values.push_back(f * s);
    }
    for (float v : values) {
        std::string label = number(double(v));
        label.append(v == s ? unit : "");
        k.swatches.push_back({{}, colormap(heatValue(v, s, in.logScale)), label});
    }
    return k;
}

ImU32 toU32(const glm::vec3& c) {
    return ImGui::ColorConvertFloat4ToU32(ImVec4(c.x, c.y, c.z, 1.0f));
}

}  // namespace

std::vector<Key> keysFor(const KeyInput& in) {
    std::vector<Key> keys;
    if (in.overlays && in.geometry && in.overlays->any()) {
        const overlay::OverlayOptions& o = *in.overlays;
        const overlay::OverlayGeometry& g = *in.geometry;
        const bool levels = g.levelLo <= g.levelHi;
        if (o.bsp && levels) keys.push_back(levelKey("BSP cut depth", g.levelLo, g.levelHi));
        if (o.zones && g.zoneCost != overlay::CostKind::None)
            keys.push_back(costKey("zones", g.zoneCost, o.costRays, g.costsKnown));
        else if (o.zones)
            keys.push_back(countKey(o.zoneFill == overlay::ZoneFill::Prims ? "primitives per zone"
                                                                           : "slabs per zone"));
        if (o.slabs && g.slabCost != overlay::CostKind::None)
            keys.push_back(costKey("slabs", g.slabCost, o.costRays, g.costsKnown));
        else if (o.slabs && g.slabMax >= 0)
            keys.push_back(levelKey("slab order in depth (0 nearest)", 0, g.slabMax));
        if (o.leaves && g.leafCost != overlay::CostKind::None) {
            keys.push_back(costKey("leaves", g.leafCost, o.costRays, g.costsKnown));
        } else if (o.leaves) {
            if (o.leafColor == overlay::LeafColor::Prims)
                keys.push_back(countKey("primitives per leaf"));
            else if (levels)
                keys.push_back(levelKey("leaf level", g.levelLo, g.levelHi));
        }
        if (o.grid) {
            if (o.gridColor == overlay::GridColor::Kind)
                keys.push_back({"directory blocks",
                                {{{}, glm::vec3(1.0f, 0.55f, 0.1f), "sub-table"},
                                 {{}, glm::vec3(0.55f, 0.65f, 0.8f), "entry"}}});
            else if (levels)
                keys.push_back(levelKey(o.gridColor == overlay::GridColor::Level
                                            ? "directory: BSP level"
                                            : "directory: sub-table depth",
                                        g.levelLo, g.levelHi));
        }
    }
    if (in.mode != ViewMode::Color) keys.push_back(heatKey(in));
    return keys;
}

KeyReport drawKeys(const KeyInput& in) {
    KeyReport report;
    report.keys = keysFor(in);
    if (report.keys.empty() || in.image.empty()) return report;
    constexpr float kInset = 8.0f, kSwatchH = 16.0f;
    const float widest = std::max(120.0f, std::min(in.image.width() - 2.0f * kInset, 380.0f));
    ImGui::SetNextWindowPos(ImVec2(in.image.x0 + kInset, in.image.y1 - kInset), ImGuiCond_Always,
                            ImVec2(0.0f, 1.0f));
    ImGui::SetNextWindowBgAlpha(1.0f);  // opaque: the panel layer copies its rectangle
    const ImGuiWindowFlags flags = ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoInputs |
                                   ImGuiWindowFlags_AlwaysAutoResize |
                                   ImGuiWindowFlags_NoSavedSettings |
                                   ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav;
    if (ImGui::Begin("##colour keys", nullptr, flags)) {
        ImDrawList* dl = ImGui::GetWindowDrawList();
        for (Key& k : report.keys) {
            ImGui::TextUnformatted(k.title.c_str());
            // Swatches in rows no wider than `widest`, each labelled with its value.
            const ImVec2 start = ImGui::GetCursorScreenPos();
            float x = start.x, y = start.y;
            float right = start.x + ImGui::CalcTextSize(k.title.c_str()).x;
            for (KeySwatch& s : k.swatches) {
                const float w = std::max(20.0f, ImGui::CalcTextSize(s.label.c_str()).x + 6.0f);
                if (x > start.x && x + w > start.x + widest) {
                    x = start.x;
                    y += kSwatchH + 2.0f;
                }
                s.rect = {x, y, x + w, y + kSwatchH};
                dl->AddRectFilled(ImVec2(s.rect.x0, s.rect.y0), ImVec2(s.rect.x1, s.rect.y1),
                                  toU32(s.color));
                // Dark text on light colours, light on dark, centred.
                const float luma = 0.3f * s.color.x + 0.59f * s.color.y + 0.11f * s.color.z;
                const ImVec2 ts = ImGui::CalcTextSize(s.label.c_str());
                dl->AddText(ImVec2(std::floor(x + 0.5f * (w - ts.x)),
                                   std::floor(y + 0.5f * (kSwatchH - ts.y))),
                            luma > 0.5f ? IM_COL32(0, 0, 0, 255) : IM_COL32(255, 255, 255, 255),
                            s.label.c_str());
                x += w + 1.0f;
                right = std::max(right, s.rect.x1);
            }
            ImGui::Dummy(ImVec2(right - start.x, y + kSwatchH - start.y));
        }
        const ImVec2 p = ImGui::GetWindowPos(), sz = ImGui::GetWindowSize();
        report.box = {p.x, p.y, p.x + sz.x, p.y + sz.y};
    }
    ImGui::End();
    return report;
}

}  // namespace lancer::viewer
