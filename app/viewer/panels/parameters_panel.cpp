#include <imgui.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty
#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>

#include "app/viewer/panels/panels.h"
#include "app/viewer/panels/param_controls.h"
#include "app/viewer/panels/widgets.h"
#include "engine/scene/builtin_scenes.h"
#include "engine/util/format.h"

namespace lancer::viewer {

namespace {

/// The scene spec taken apart when it names a built-in; a malformed size counts as none (the
/// scene's own error says what is wrong with it).
std::optional<BuiltinSpec> builtinOf(const std::string& spec) {
    try {
        return parseBuiltinSpec(spec);
    } catch (const SceneError&) {
        return BuiltinSpec{spec.substr(spec.find(':') + 1, spec.find(':', 8) - 8), std::nullopt};
    }
}

}  // namespace

std::string stopReasonsLine(const nlohmann::json& extra, SchemeKind scheme) {
    const auto it = extra.find("stop_reasons");
    if (it == extra.end() || !it->is_object()) return "";
    std::string out = scheme == SchemeKind::Irregular ? "zones" : "leaves";
    out += " stopped by";
    const char* keys[][2] = {{"max_objects", "max-objects"},
                             {"max_level", "max-level"},
                             {"cost", "cost"},
                             {"memory", "memory"}};
    // Of the cost stops, the cells inside all their primitives' boxes (kept whole by any rule).
    const size_t covered = extra.value(
        scheme == SchemeKind::Irregular ? "covered_zones" : "covered_leaves", size_t(0));
    for (size_t i = 0; i < std::size(keys); ++i) {
        out += std::string(i ? ", " : " ") + keys[i][1] + " " +
               std::to_string(it->value(keys[i][0], size_t(0)));
        if (keys[i][0] == std::string("cost") && covered)
            out += " (" + std::to_string(covered) + " covered)";
    }
    return out;
}

void parametersPanel(ViewerState& st) {
    ViewerSettings& s = st.settings();
    PanelNotes& notes = st.notes();

    // Scene: a built-in (with its size) or a file.
    const std::optional<BuiltinSpec> spec = builtinOf(s.scene);
    const BuiltinInfo* info = spec ? findBuiltin(spec->name) : nullptr;
    if (ImGui::BeginCombo("built-in", info ? info->name : "(file)")) {
        for (const BuiltinInfo& b : builtinScenes()) {
            if (ImGui::Selectable(b.name, info == &b)) st.openScene(builtinSpec(b.name));
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", b.description);
        }
        ImGui::EndCombo();
    }
    if (info && info->maxSize > info->minSize) {
        if (notes.builtinSize < 0) notes.builtinSize = spec->size.value_or(info->defaultSize);
        ImGui::SliderInt("size", &notes.builtinSize, info->minSize,
                         std::min(info->maxSize, info->minSize + 64));
        if (ImGui::IsItemDeactivatedAfterEdit())
            st.openScene(builtinSpec(info->name, notes.builtinSize));
    }
    ImGui::SetNextItemWidth(ImGui::CalcItemWidth() - ImGui::CalcTextSize("Open").x -
                            2.0f * ImGui::GetStyle().FramePadding.x -
                            ImGui::GetStyle().ItemInnerSpacing.x);
    ImGui::InputTextWithHint("##file", ".json / .nff / .csg", &notes.pathInput);
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("or drop a scene file on the window");
    ImGui::SameLine(0.0f, ImGui::GetStyle().ItemInnerSpacing.x);
    if (ImGui::Button("Open") && !notes.pathInput.empty()) st.openScene(notes.pathInput);
    ImGui::SameLine(0.0f, ImGui::GetStyle().ItemInnerSpacing.x);
    ImGui::TextUnformatted("file");
    errorLines(st.error(), 2);

    // The knobs, from the parameter table: a knob the scheme does not read is greyed out.
    const cli::Knobs before = knobsOf(s);
    cli::Knobs k = before;
    const int maxThreads = effectiveThreads(0);
    ImGui::Separator();
    ImGui::TextUnformatted("Subdivision");
    paramControls(cli::ChangeEffect::Rebuild, k, maxThreads);
    if (const std::shared_ptr<const SceneBuild>& b = st.sceneBuild()) {
        const AccelInfo& ai = b->accel->info();
        ImGui::Text("on screen: %s, built in %.1f ms", schemeName(b->accel->params().scheme),
                    ai.buildMs);
        ImGui::Text("regions %zu, memory %s", ai.regions, formatBytes(ai.memoryBytes).c_str());
        if (const std::string why = stopReasonsLine(ai.extra, b->accel->params().scheme);
            !why.empty()) {
            // Short enough for a column at 1280 x 720: "stops: objects 3, level 0, ...".
            std::string shortWhy = why;
            for (const auto& [from, to] :
                 {std::pair<std::string, std::string>{"leaves stopped by", "stops:"},
                  {"zones stopped by", "stops:"},
                  {"max-objects", "objects"},
                  {"max-level", "level"}})
                if (const size_t at = shortWhy.find(from); at != std::string::npos)
                    shortWhy.replace(at, from.size(), to);
            ImGui::TextWrapped("%s", shortWhy.c_str());
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip(
                    "%s.\nWhy each cell was not split: it held at most max-objects primitives, "
                    "it reached max-level, no split would pay (the cost estimate, or a cell "
                    "inside all its primitives' boxes), or the memory budget",
                    why.c_str());
        }
        ImGui::Text("%zu primitives (%d dropped by minimization)", b->scene->prims.size(),
                    b->scene->droppedPrims);
    }
    // The line is there while idle too, so the controls under it do not move.
    ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "%s",
                       st.building() ? "building in the background..." : "");

    ImGui::Separator();
    ImGui::TextUnformatted("Rendering");
    paramControls(cli::ChangeEffect::Rerender, k, maxThreads);

    // What the change asks for is the table's decision (cli::changeEffect, tested without a
    // window): a knob another scheme reads never rebuilds.
    const cli::ChangeEffect effect = cli::changeEffect(before, k);
    if (effect != cli::ChangeEffect::None) {
        setKnobs(s, k);
        ImGui::MarkIniSettingsDirty();
    }
    if (effect == cli::ChangeEffect::Rebuild) st.requestBuild(false, "subdivision parameter");
    if (effect == cli::ChangeEffect::Rerender) st.markRender("shading parameter");
}

}  // namespace lancer::viewer
