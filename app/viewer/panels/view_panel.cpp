#include <imgui.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/viewer/panels/panels.h"

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
        colourBar(st.heatScale(), s.mode, s.logScale);
    }
    // The pixel under the cursor, from the same per-pixel counters as --stats.
    const Image& shown = st.shown();
    if (!io.WantCaptureMouse && shown.width > 0) {
        int x = int(io.MousePos.x * io.DisplayFramebufferScale.x),
            y = int(io.MousePos.y * io.DisplayFramebufferScale.y);
        if (x >= 0 && y >= 0 && x < shown.width && y < shown.height) {
            size_t i = shown.index(x, y);
            ImGui::Text("pixel %d %d: %u prim tests, %u regions, %.1f us", x, y, shown.primTests[i],
                        shown.regionVisits[i], double(shown.timeUs[i]));
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
