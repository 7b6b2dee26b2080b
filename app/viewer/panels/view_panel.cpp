#include <imgui.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "app/viewer/panels/panels.h"
#include "app/viewer/panels/widgets.h"

namespace lancer::viewer {

namespace {

/// The colour bar: the stops of the shader's map, value 0 on the left, `scale` on the right
/// (and, on a log scale, the value in the middle).
void colourBar(float scale, ViewMode mode, bool logScale) {
    ImVec2 p = ImGui::GetCursorScreenPos();
    const float w = ImGui::GetContentRegionAvail().x, h = 16.0f;
    const auto& stops = colormapStops();
    ImDrawList* dl = ImGui::GetWindowDrawList();
    const int segs = int(stops.size()) - 1;
    for (int i = 0; i < segs; ++i) {
        auto col = [](const glm::vec3& c) {
            return ImGui::ColorConvertFloat4ToU32(ImVec4(c.x, c.y, c.z, 1.0f));
        };
        float x0 = p.x + w * float(i) / float(segs), x1 = p.x + w * float(i + 1) / float(segs);
        dl->AddRectFilledMultiColor(ImVec2(x0, p.y), ImVec2(x1, p.y + h), col(stops[size_t(i)]),
                                    col(stops[size_t(i) + 1]), col(stops[size_t(i) + 1]),
                                    col(stops[size_t(i)]));
    }
    ImGui::Dummy(ImVec2(w, h));
    ImGui::Text("0");
    if (logScale) {
        char mid[32];
        std::snprintf(mid, sizeof mid, "%.3g", double(std::expm1(0.5f * std::log1p(scale))));
        ImGui::SameLine(std::max(0.0f, 0.5f * (w - ImGui::CalcTextSize(mid).x)));
        ImGui::TextUnformatted(mid);
    }
    char right[32];
    std::snprintf(right, sizeof right, "%.6g %s", double(scale),
                  mode == ViewMode::TimeUs ? "us" : "");
    ImGui::SameLine(std::max(0.0f, w - ImGui::CalcTextSize(right).x));
    ImGui::TextUnformatted(right);
}

/// The diverging colour bar of an A/B difference: old - new, -scale (red: the new structure does
/// more work) on the left, 0 (no change) in the middle, +scale (blue: less work) on the right.
void divergingBar(float scale, ViewMode mode, bool logScale) {
    ImGui::TextUnformatted("old - new");
    ImGui::SameLine();
    ImGui::TextDisabled("red: new does more, blue: less");
    ImVec2 p = ImGui::GetCursorScreenPos();
    const float w = ImGui::GetContentRegionAvail().x, h = 16.0f;
    const auto& stops = divergingStops();
    ImDrawList* dl = ImGui::GetWindowDrawList();
    const int segs = int(stops.size()) - 1;
    auto col = [](const glm::vec3& c) {
        return ImGui::ColorConvertFloat4ToU32(ImVec4(c.x, c.y, c.z, 1.0f));
    };
    for (int i = 0; i < segs; ++i) {
        float x0 = p.x + w * float(i) / float(segs), x1 = p.x + w * float(i + 1) / float(segs);
        dl->AddRectFilledMultiColor(ImVec2(x0, p.y), ImVec2(x1, p.y + h), col(stops[size_t(i)]),
                                    col(stops[size_t(i) + 1]), col(stops[size_t(i) + 1]),
                                    col(stops[size_t(i)]));
    }
    ImGui::Dummy(ImVec2(w, h));
    const char* unit = mode == ViewMode::TimeUs ? " us" : "";
    char left[40], right[40];
    std::snprintf(left, sizeof left, "-%.4g%s", double(scale), unit);
    std::snprintf(right, sizeof right, "+%.4g%s", double(scale), unit);
    ImGui::TextUnformatted(left);
    ImGui::SameLine(std::max(0.0f, 0.5f * (w - ImGui::CalcTextSize("0").x)));
    ImGui::TextUnformatted("0");
    ImGui::SameLine(std::max(0.0f, w - ImGui::CalcTextSize(right).x));
    ImGui::TextUnformatted(right);
    if (logScale) ImGui::TextDisabled("log scale: sign(d) log(1 + |d|)");
}

/// "12.3M", "45.6k", "789": a count that fits a table cell.
std::string shortCount(double v) {
    char buf[32];
    const double a = std::abs(v);
    if (a >= 1e9)
        std::snprintf(buf, sizeof buf, "%.3gG", v / 1e9);
    else if (a >= 1e6)
        std::snprintf(buf, sizeof buf, "%.3gM", v / 1e6);
    else if (a >= 1e4)
        std::snprintf(buf, sizeof buf, "%.3gk", v / 1e3);
    else if (a >= 100.0 || v == std::floor(v))
        std::snprintf(buf, sizeof buf, "%.0f", v);
    else
        std::snprintf(buf, sizeof buf, "%.3g", v);
    return buf;
}

/// One row of the A/B table: old, new, old - new, new / old.
void abRow(const char* name, double a, double b, const char* fmt = nullptr) {
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::TextUnformatted(name);
    auto cell = [&](double v) {
        ImGui::TableNextColumn();
        if (fmt)
            ImGui::Text(fmt, v);
        else
            ImGui::TextUnformatted(shortCount(v).c_str());
    };
    cell(a);
    cell(b);
    cell(a - b);
    ImGui::TableNextColumn();
    if (a > 0.0)
        ImGui::Text("%.2f", b / a);
    else
        ImGui::TextDisabled("-");
}

/// The A/B of the last rebuild: which image the heat map shows, what A and B are, and their
/// totals over the rows compared.
void abSection(ViewerState& st) {
    using compare::AbView;
    ImGui::Separator();
    int ab = int(st.abView());
    ImGui::TextUnformatted("Rebuild A/B (B flips old and new)");
    ImGui::RadioButton("new (B)", &ab, int(AbView::New));
    ImGui::SameLine();
    ImGui::RadioButton("old (A)", &ab, int(AbView::Old));
    ImGui::SameLine();
    ImGui::RadioButton("old - new", &ab, int(AbView::Diff));
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "Per pixel, the old structure's count minus the new one's (B flips "
            "between old and new)");
    if (ab != int(st.abView())) st.setAbView(AbView(ab));
    const compare::AbStatus& status = st.abStatus();
    const compare::CounterImage* old = st.abOld();
    if (old && status.comparable)
        ImGui::TextWrapped("A -> B: %s",
                           compare::paramChanges(old->params, st.shownParams()).c_str());
    if (!status.note.empty()) hintText(status.note.c_str());
    if (!status.comparable || status.rows == 0) return;
    const AbTotals& t = st.abTotals();
    if (ImGui::BeginTable(
            "ab", 5,
            ImGuiTableFlags_SizingFixedFit | ImGuiTableFlags_RowBg | ImGuiTableFlags_NoPadOuterX)) {
        for (const char* h : {"", "A (old)", "B (new)", "A - B", "B/A"}) ImGui::TableSetupColumn(h);
        ImGui::TableHeadersRow();
        abRow("prim tests", double(t.a.primTests), double(t.b.primTests));
        abRow("regions", double(t.a.regionVisits), double(t.b.regionVisits));
        if (t.complete && t.aCounters.rays > 0 && t.bCounters.rays > 0) {
            // Per ray, every ray of the image (primary, shadow, secondary).
            const double ra = double(t.aCounters.rays), rb = double(t.bCounters.rays);
            abRow("tests/ray", double(t.a.primTests) / ra, double(t.b.primTests) / rb, "%.2f");
            abRow("regions/ray", double(t.a.regionVisits) / ra, double(t.b.regionVisits) / rb,
                  "%.2f");
        } else if (t.a.pixels > 0) {
            const double n = double(t.a.pixels);
            abRow("tests/pixel", double(t.a.primTests) / n, double(t.b.primTests) / n, "%.2f");
            abRow("regions/pixel", double(t.a.regionVisits) / n, double(t.b.regionVisits) / n,
                  "%.2f");
        }
        abRow("pixels ms", t.a.timeUs / 1e3, t.b.timeUs / 1e3);
        if (t.complete) abRow("render ms", t.aRenderMs, t.bRenderMs);
        ImGui::EndTable();
    }
    if (t.complete)
        hintText("pixels ms: the pixels' own times added up (all threads); render ms: wall time");
}

}  // namespace

void viewPanel(ViewerState& st) {
    ImGuiIO& io = ImGui::GetIO();
    ViewerSettings& s = st.settings();
    int mode = int(s.mode);
    for (int i = 0; i < kViewModeCount; ++i) {
        if (i) ImGui::SameLine();
        ImGui::RadioButton(i == 0   ? "colour"
                           : i == 1 ? "prim tests"
                           : i == 2 ? "regions"
                                    : "time",
                           &mode, i);
        if (i > 0 && ImGui::IsItemHovered())
            ImGui::SetTooltip(
                "A heat map; after a rebuild it also compares the old and new structures, pixel "
                "by pixel (A/B)");
    }
    if (mode != int(s.mode)) {
        st.setViewMode(ViewMode(mode));
        ImGui::MarkIniSettingsDirty();
    }
    if (s.mode != ViewMode::Color) {
        if (ImGui::Checkbox("auto scale", &s.autoScale)) ImGui::MarkIniSettingsDirty();
        ImGui::SameLine();
        if (s.autoScale) s.heatScale = st.heatScale();
        ImGui::SetNextItemWidth(150.0f);
        if (ImGui::SliderFloat("##scale", &s.heatScale, 1.0f, 1e6f, "%.0f",
                               ImGuiSliderFlags_Logarithmic)) {
            s.autoScale = false;
            ImGui::MarkIniSettingsDirty();
        }
        ImGui::SameLine();
        if (ImGui::Checkbox("log", &s.logScale)) ImGui::MarkIniSettingsDirty();
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip("Colour by log(1 + count): the low counts spread out");
        if (st.heatDiverging())
            divergingBar(st.heatScale(), s.mode, s.logScale);
        else
            colourBar(st.heatScale(), s.mode, s.logScale);
        abSection(st);
    }
    // The pixel under the cursor, from the same per-pixel counters as --stats.
    const Image& shown = st.shown();
    if (!io.WantCaptureMouse && shown.width > 0) {
        const auto px = st.pixelUnderMouse();
        const int x = px ? px->first : -1, y = px ? px->second : -1;
        if (x >= 0 && y >= 0 && x < shown.width && y < shown.height) {
            size_t i = shown.index(x, y);
            ImGui::Text("pixel %d %d: %u prim tests, %u regions, %.1f us", x, y, shown.primTests[i],
                        shown.regionVisits[i], double(shown.timeUs[i]));
            const compare::CounterImage* old = st.abOld();
            if (old && st.abStatus().comparable && st.abView() != compare::AbView::New) {
                if (y < st.abStatus().rows)
                    ImGui::Text("  old: %u prim tests, %u regions, %.1f us", old->primTests[i],
                                old->regionVisits[i], double(old->timeUs[i]));
                else
                    ImGui::TextDisabled("  old: (this row of the new image is not done)");
            }
        } else {
            ImGui::TextDisabled("(the pixel under the cursor)");
        }
    } else {
        ImGui::TextDisabled("(the pixel under the cursor)");
    }
    ImGui::Separator();
    ImGui::Checkbox("3D inspector (I)", &st.settings().showInspector);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("The structure in 3D, with a camera of its own, beside the image");
    PanelNotes& notes = st.notes();
    if (ImGui::Button("Screenshot")) {
        // Taken once this frame is drawn.
        notes.pendingScreenshot =
            "lancer-screenshot-" + std::to_string(++notes.screenshotCount) + ".png";
    }
    if (!notes.screenshotNote.empty()) ImGui::TextWrapped("%s", notes.screenshotNote.c_str());
}

}  // namespace lancer::viewer
