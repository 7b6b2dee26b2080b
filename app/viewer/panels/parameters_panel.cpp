#include <imgui.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty
#include <imgui_stdlib.h>

#include <algorithm>
#include <cstdio>

#include "app/viewer/panels/panels.h"
#include "app/viewer/panels/widgets.h"
#include "engine/scene/builtin_scenes.h"

namespace lancer::viewer {

namespace {

std::string humanBytes(size_t b) {
    char buf[64];
    if (b < 10 * 1024)
        std::snprintf(buf, sizeof buf, "%zu B", b);
    else if (b < 10 * 1024 * 1024)
        std::snprintf(buf, sizeof buf, "%.1f KiB", double(b) / 1024.0);
    else
        std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / (1024.0 * 1024.0));
    return buf;
}

/// "builtin:NAME[:SIZE]" split into its name and size (-1: none); false for a file path.
bool parseBuiltin(const std::string& spec, std::string& name, int& size) {
    if (spec.rfind("builtin:", 0) != 0) return false;
    std::string rest = spec.substr(8);
    size = -1;
    size_t colon = rest.find(':');
    if (colon != std::string::npos) {
        try {
            size = std::stoi(rest.substr(colon + 1));
        } catch (...) {
            size = -1;
        }
        rest = rest.substr(0, colon);
    }
    name = rest;
    return true;
}

const BuiltinInfo* findBuiltin(const std::string& name) {
    for (const BuiltinInfo& b : builtinScenes())
        if (name == b.name) return &b;
    return nullptr;
}

}  // namespace

void parametersPanel(ViewerState& st) {
    ViewerSettings& s = st.settings();
    PanelNotes& notes = st.notes();
    ImGui::SetNextWindowPos(ImVec2(8, 28), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(330, 430), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Parameters", &s.showParameters)) {
        ImGui::End();
        return;
    }
    bool rebuild = false, rerender = false;

    // Scene: a built-in (with its size) or a file.
    std::string bname;
    int bsize = -1;
    const bool isBuiltin = parseBuiltin(s.scene, bname, bsize);
    const BuiltinInfo* info = isBuiltin ? findBuiltin(bname) : nullptr;
    if (ImGui::BeginCombo("built-in", info ? info->name : "(file)")) {
        for (const BuiltinInfo& b : builtinScenes()) {
            if (ImGui::Selectable(b.name, info == &b))
                st.openScene(std::string("builtin:") + b.name);
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", b.description);
        }
        ImGui::EndCombo();
    }
    if (info && info->maxSize > info->minSize) {
        if (notes.builtinSize < 0) notes.builtinSize = bsize >= 0 ? bsize : info->defaultSize;
        ImGui::SliderInt("size", &notes.builtinSize, info->minSize,
                         std::min(info->maxSize, info->minSize + 64));
        if (ImGui::IsItemDeactivatedAfterEdit())
            st.openScene("builtin:" + std::string(info->name) + ":" +
                         std::to_string(notes.builtinSize));
    }
    ImGui::InputText("file", &notes.pathInput);
    ImGui::SameLine();
    if (ImGui::Button("Open") && !notes.pathInput.empty()) st.openScene(notes.pathInput);
    hintText("or drop a .json / .nff / .csg file on the window");
    errorText(st.error());

    ImGui::Separator();
    ImGui::TextUnformatted("Subdivision");
    rebuild |= enumCombo("scheme", s.build.scheme, 3, schemeName);
    if (ImGui::InputInt("max-level", &s.build.maxLevel)) {
        s.build.maxLevel = std::clamp(s.build.maxLevel, 0, 48);
        rebuild = true;
    }
    if (ImGui::InputInt("max-objects", &s.build.maxObjects)) {
        s.build.maxObjects = std::clamp(s.build.maxObjects, 1, 1000000);
        rebuild = true;
    }
    rebuild |= enumCombo("split axes", s.build.splitAxes, 2, splitAxesName);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "Regular: cycle cuts x, y, z in turn (the report's); cost picks each\n"
            "level's axis by an area estimate (cells stay about cubic)");
    rebuild |= enumCombo("step", s.build.step, 2, stepName);
    if (s.build.step == StepMethod::Push) {
        double d = s.build.delta;
        if (ImGui::InputDouble("delta", &d, 0.0, 0.0, "%.3e",
                               ImGuiInputTextFlags_EnterReturnsTrue) &&
            d >= 1e-15 && d <= 0.5) {
            s.build.delta = d;
            rebuild = true;
        }
    }
    rebuild |= enumCombo("BSP heuristic", s.build.heuristic, 3, heuristicName);
    rebuild |= ImGui::Checkbox("mailboxes", &s.build.mailboxes);
    ImGui::SameLine();
    rebuild |= ImGui::Checkbox("light buffer", &s.build.lightBuffer);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Shadow rays stop where the light's depth map says nothing is left");
    if (const std::shared_ptr<const SceneBuild>& b = st.sceneBuild()) {
        const AccelInfo& ai = b->accel->info();
        ImGui::Text("on screen: %s, built in %.1f ms", schemeName(b->accel->params().scheme),
                    ai.buildMs);
        ImGui::Text("regions %zu, memory %s", ai.regions, humanBytes(ai.memoryBytes).c_str());
        ImGui::Text("%zu primitives (%d dropped by minimization)", b->scene->prims.size(),
                    b->scene->droppedPrims);
    }
    if (st.building())
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "building in the background...");

    ImGui::Separator();
    ImGui::TextUnformatted("Rendering");
    int maxThreads = effectiveThreads(0);
    rerender |= ImGui::SliderInt("threads", &s.threads, 0, std::max(maxThreads, 1),
                                 s.threads ? "%d" : "all");
    rerender |= ImGui::Checkbox("shadows", &s.shading.shadows);
    ImGui::SameLine();
    rerender |= ImGui::Checkbox("reflection", &s.shading.reflections);
    ImGui::SameLine();
    rerender |= ImGui::Checkbox("refraction", &s.shading.refractions);
    rerender |= ImGui::SliderInt("bounces", &s.shading.bounces, 0, 10);
    ImGui::End();

    if (rebuild) {
        ImGui::MarkIniSettingsDirty();
        st.requestBuild(false, "subdivision parameter");
    }
    if (rerender) {
        ImGui::MarkIniSettingsDirty();
        st.markRender("shading parameter");
    }
}

}  // namespace lancer::viewer
