#include "app/viewer/panels/panels.h"

#include <imgui.h>
#include <imgui_internal.h>  // FindWindowByName: the height a panel asked for

#include <algorithm>
#include <cmath>

namespace lancer::viewer {

namespace {

/// The Ray panel's step list fills what it is given: it asks for as much as the column has.
constexpr float kFillsColumn = 1.0e6f;

/// The settings' flag that shows panel `id`.
template <class Settings>
auto openFlag(Settings& s, PanelId id) -> decltype((s.showRay)) {
    switch (id) {
        case PanelId::Parameters:
            return s.showParameters;
        case PanelId::View:
            return s.showView;
        case PanelId::Statistics:
            return s.showStatistics;
        case PanelId::Camera:
            return s.showCamera;
        case PanelId::Overlays:
            return s.showOverlays;
        case PanelId::Inspector:
            return s.showInspector;
        case PanelId::Selection:
            return s.showSelection;
        case PanelId::Tree:
            return s.showTree;
        case PanelId::Ray:
            break;
    }
    return s.showRay;
}

/// Place the next window at `r`, its size fixed (its content scrolls when taller).
void placeNext(const Rect& r) {
    ImGui::SetNextWindowPos(ImVec2(r.x0, r.y0), ImGuiCond_Always);
    const ImVec2 size(r.width(), r.height());
    ImGui::SetNextWindowSize(size, ImGuiCond_Always);
    ImGui::SetNextWindowSizeConstraints(size, size);
}

/// After a panel's End: the height its content asked for (title bar and padding included) and
/// whether it is folded, for the next frame's layout.
void measure(PanelId id, PanelRequest& req) {
    const ImGuiWindow* w = ImGui::FindWindowByName(panelTitle(id));
    if (!w) return;
    req.collapsed = w->Collapsed;
    if (w->Collapsed) return;  // a folded panel submits nothing: keep the last height
    const ImGuiStyle& style = ImGui::GetStyle();
    req.want = id == PanelId::Ray ? kFillsColumn
                                  : std::ceil(w->DC.CursorMaxPos.y - w->DC.CursorStartPos.y +
                                              2.0f * style.WindowPadding.y + w->TitleBarHeight());
}

/// A drag handle at `r` (a column's inner edge, the image and inspector's split): a window of
/// its own, so ImGui takes the mouse over it, drawn as a bar that brightens while hovered or
/// dragged. Returns the horizontal drag of this frame, in display units.
float dragHandle(const char* name, const Rect& r) {
    if (r.empty()) return 0.0f;
    placeNext(r);
    ImGui::PushStyleVar(ImGuiStyleVar_WindowPadding, ImVec2(0.0f, 0.0f));
    ImGui::PushStyleVar(ImGuiStyleVar_WindowBorderSize, 0.0f);
    ImGui::PushStyleVar(ImGuiStyleVar_WindowRounding, 0.0f);
    ImGui::PushStyleVar(ImGuiStyleVar_WindowMinSize, ImVec2(1.0f, 1.0f));
    float dx = 0.0f;
    if (ImGui::Begin(name, nullptr,
                     ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                         ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoFocusOnAppearing |
                         ImGuiWindowFlags_NoBringToFrontOnFocus | ImGuiWindowFlags_NoNav |
                         ImGuiWindowFlags_NoScrollWithMouse)) {
        ImGui::InvisibleButton("##drag",
                               ImVec2(std::max(r.width(), 1.0f), std::max(r.height(), 1.0f)));
        const bool active = ImGui::IsItemActive(), hovered = ImGui::IsItemHovered();
        if (active || hovered) ImGui::SetMouseCursor(ImGuiMouseCursor_ResizeEW);
        const float cx = std::floor(0.5f * (r.x0 + r.x1));
        ImGui::GetWindowDrawList()->AddRectFilled(
            ImVec2(cx - 1.0f, r.y0), ImVec2(cx + 1.0f, r.y1),
            ImGui::GetColorU32(active    ? ImGuiCol_SeparatorActive
                               : hovered ? ImGuiCol_SeparatorHovered
                                         : ImGuiCol_Separator));
        if (active) dx = ImGui::GetIO().MouseDelta.x;
    }
    ImGui::End();
    ImGui::PopStyleVar(4);
    return dx;
}

/// The handles of `layout`, and their drags into the settings (saved in the ini).
void dragHandles(ViewerSettings& s, const PanelLayout& layout) {
    bool changed = false;
    if (const float dx = dragHandle("##left column edge", layout.leftHandle); dx != 0.0f) {
        s.leftColumn = std::max(kColumnMinWidth, layout.leftWidth + dx);
        changed = true;
    }
    if (const float dx = dragHandle("##right column edge", layout.rightHandle); dx != 0.0f) {
        s.rightColumn = std::max(kColumnMinWidth, layout.rightWidth - dx);
        changed = true;
    }
    if (const float dx = dragHandle("##image inspector split", layout.splitHandle); dx != 0.0f) {
        const float both = layout.image.width() + layout.inspector.width();
        if (both > 0.0f) s.imageShare = std::clamp((layout.image.width() + dx) / both, 0.0f, 1.0f);
        changed = true;
    }
    if (changed) ImGui::MarkIniSettingsDirty();
}

/// One of panels.h's own panels, in a window of its own.
void ownPanel(PanelId id, bool& open, ViewerState& st, void (*content)(ViewerState&)) {
    if (ImGui::Begin(panelTitle(id), &open, ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize))
        content(st);
    ImGui::End();
}

}  // namespace

void menuBar(ViewerState& st) {
    ViewerSettings& s = st.settings();
    if (!ImGui::BeginMainMenuBar()) return;
    if (ImGui::BeginMenu("Panels")) {
        ImGui::MenuItem("Parameters", nullptr, &s.showParameters);
        ImGui::MenuItem("Camera", nullptr, &s.showCamera);
        ImGui::MenuItem("Statistics", nullptr, &s.showStatistics);
        ImGui::MenuItem("View", nullptr, &s.showView);
        ImGui::MenuItem("Overlays", nullptr, &s.showOverlays);
        ImGui::MenuItem("Selection", nullptr, &s.showSelection);
        ImGui::MenuItem("Structure tree", nullptr, &s.showTree);
        ImGui::MenuItem("Ray", nullptr, &s.showRay);
        ImGui::MenuItem("3D inspector", "I", &s.showInspector);
        ImGui::Separator();
        bool hidden = st.panelsHidden();
        if (ImGui::MenuItem("Hide all", "Tab", &hidden)) st.setPanelsHidden(hidden);
        ImGui::EndMenu();
    }
    ImGui::TextDisabled("%s", s.scene.c_str());
    // The image viewport's size is the traced image's: what `lancer render` needs to trace the
    // same rays.
    if (st.width() > 0) ImGui::TextDisabled("image %d x %d", st.width(), st.height());
    if (st.building()) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "building...");
    if (!st.error().empty())
        ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "error (see Parameters)");
    ImGui::EndMainMenuBar();
}

LayoutInput layoutInputOf(const ViewerSettings& s, bool panelsHidden, const PanelHeights& heights,
                          float width, float height) {
    LayoutInput in;
    in.width = width;
    in.height = height;
    in.panelsHidden = panelsHidden;
    in.inspector = s.showInspector;
    if (ImGui::GetCurrentContext() && ImGui::GetFontSize() > 0.0f)
        in.titleHeight = ImGui::GetFrameHeight();
    in.leftWidth = s.leftColumn;
    in.rightWidth = s.rightColumn;
    in.imageShare = s.imageShare;
    in.panels = heights;
    for (int i = 0; i < kPanelCount; ++i) in.panels[size_t(i)].open = openFlag(s, PanelId(i));
    return in;
}

PanelLayout planPanels(const ViewerState& st, const PanelHeights& heights, float width,
                       float height) {
    return layoutPanels(layoutInputOf(st.settings(), st.panelsHidden(), heights, width, height));
}

void drawPanels(ViewerState& st, const PanelLayout& layout, PanelHeights& heights,
                const PanelContents& more) {
    if (st.panelsHidden()) return;
    ViewerSettings& s = st.settings();
    menuBar(st);
    dragHandles(s, layout);
    for (int i = 0; i < kPanelCount; ++i) {
        const PanelId id = PanelId(i);
        bool& open = openFlag(s, id);
        // A panel opened during this frame (a menu, a pick) is placed from the next one.
        if (!open || layout[id].empty()) continue;
        placeNext(layout[id]);
        switch (id) {
            case PanelId::Parameters:
                ownPanel(id, open, st, parametersPanel);
                break;
            case PanelId::View:
                ownPanel(id, open, st, viewPanel);
                break;
            case PanelId::Statistics:
                ownPanel(id, open, st, statisticsPanel);
                break;
            case PanelId::Camera:
                ownPanel(id, open, st, cameraPanel);
                break;
            case PanelId::Overlays:
                // Folded at first (a click on its title opens it), so the panels of a first
                // run fit a 900 x 720 window whole.
                ImGui::SetNextWindowCollapsed(true, ImGuiCond_FirstUseEver);
                if (more.overlays) more.overlays(&open);
                break;
            case PanelId::Inspector:
                if (more.inspector) more.inspector(&open);
                break;
            case PanelId::Selection:
                if (more.selection) more.selection(&open);
                break;
            case PanelId::Tree:
                if (more.tree) more.tree(&open);
                break;
            case PanelId::Ray:
                if (more.ray) more.ray(&open);
                break;
        }
        measure(id, heights[size_t(i)]);
    }
}

}  // namespace lancer::viewer
