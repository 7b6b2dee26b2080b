#include "app/viewer/panels/param_controls.h"

#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <string>

namespace lancer::viewer {

bool paramControl(const cli::ParamDesc& d, cli::Knobs& k, int maxThreads) {
    const bool disabled = !cli::applies(d, k);
    ImGui::BeginDisabled(disabled);
    bool changed = false;
    switch (d.kind) {
        case cli::ParamKind::Int: {
            int v = int(d.get(k));
            const int lo = d.autoWord ? int(d.autoValue) : int(d.lo);
            if (d.autoWord) {
                // Dragged below lo, the automatic value, written as its word (ctrl+click types).
                changed = ImGui::DragInt(d.label, &v, 0.2f, lo, int(d.hi),
                                         v == lo ? d.autoWord : "%d", ImGuiSliderFlags_AlwaysClamp);
            } else if (d.hi - d.lo <= 64 || d.flag == std::string("--threads")) {
                const int hi =
                    d.flag == std::string("--threads") ? std::max(maxThreads, 1) : int(d.hi);
                changed =
                    ImGui::SliderInt(d.label, &v, int(d.lo), hi,
                                     v == 0 && d.flag == std::string("--threads") ? "all" : "%d");
            } else {
                changed = ImGui::InputInt(d.label, &v);
            }
            v = std::clamp(v, lo, int(d.hi));
            changed = changed && double(v) != d.get(k);
            if (changed) d.set(k, double(v));
            break;
        }
        case cli::ParamKind::Real: {
            double v = d.get(k);
            if (ImGui::InputDouble(d.label, &v, 0.0, 0.0, "%.3e",
                                   ImGuiInputTextFlags_EnterReturnsTrue) &&
                v >= d.lo && v <= d.hi && v != d.get(k)) {
                d.set(k, v);
                changed = true;
            }
            break;
        }
        case cli::ParamKind::Enum: {
            const size_t current = size_t(d.get(k));
            if (ImGui::BeginCombo(d.label, d.names[current])) {
                for (size_t i = 0; i < d.names.size(); ++i)
                    if (ImGui::Selectable(d.names[i], i == current) && i != current) {
                        d.set(k, double(i));
                        changed = true;
                    }
                ImGui::EndCombo();
            }
            break;
        }
        case cli::ParamKind::Switch: {
            bool v = d.get(k) != 0.0;
            if (ImGui::Checkbox(d.label, &v)) {
                d.set(k, v ? 1.0 : 0.0);
                changed = true;
            }
            break;
        }
        case cli::ParamKind::Size: {
            // Written as the command line takes it (512M, 2G); applied on Enter, and a value
            // parseValue refuses leaves the knob as it was.
            char buf[32];
            const std::string now = cli::formatValue(d, k);
            std::snprintf(buf, sizeof buf, "%s", now.c_str());
            if (ImGui::InputText(d.label, buf, sizeof buf, ImGuiInputTextFlags_EnterReturnsTrue)) {
                cli::Knobs next = k;
                if (cli::parseValue(d, buf, next) && d.get(next) != d.get(k)) {
                    d.set(k, d.get(next));
                    changed = true;
                }
            }
            break;
        }
        case cli::ParamKind::Path:
            break;  // files are not panel controls (ViewerReach::Startup, BatchOnly)
    }
    ImGui::EndDisabled();
    if (ImGui::IsItemHovered(ImGuiHoveredFlags_AllowWhenDisabled)) {
        std::string tip = d.help;
        if (disabled) tip += "\n(not read by the current scheme or settings)";
        ImGui::SetTooltip("%s", tip.c_str());
    }
    return changed;
}

bool paramControls(cli::ChangeEffect effect, cli::Knobs& k, int maxThreads) {
    bool changed = false;
    // Switches that follow each other go two to a line, the second at the middle: the panel
    // keeps its height at 1280 x 720 as switches are added.
    const float lineStart = ImGui::GetCursorPosX();
    const float middle = lineStart + 0.5f * ImGui::GetContentRegionAvail().x;
    bool rightFree = false;  // the last control was a switch at the start of its line
    for (const cli::ParamDesc& d : cli::paramTable()) {
        if (d.reach != cli::ViewerReach::Panel || d.effect != effect) continue;
        const bool sw = d.kind == cli::ParamKind::Switch;
        if (sw && rightFree) ImGui::SameLine(middle);
        changed |= paramControl(d, k, maxThreads);
        rightFree = sw && !rightFree;
    }
    return changed;
}

}  // namespace lancer::viewer
