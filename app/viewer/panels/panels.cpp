#include "app/viewer/panels/panels.h"

#include <imgui.h>

#include <algorithm>

namespace lancer::viewer {

namespace {

/// Panels stack in two columns, Polyscope's way: each is as tall as its content (no scrollbar
/// while the window has room), placed under the one above it, and the columns follow the
/// window's size, so a smaller window never leaves a panel off-screen.
constexpr float kMargin = 8.0f, kGap = 8.0f, kMenuBar = 28.0f;
/// A panel keeps this height at least when its column is full (it scrolls then).
constexpr float kMinHeight = 90.0f;

struct Column {
    float x, width, y;
};

/// Begin a panel at the top of what is left of `col`; false when it is collapsed.
bool beginPanel(const char* name, bool* open, const Column& col) {
    const ImVec2 display = ImGui::GetIO().DisplaySize;
    const float bottom = display.y - kMargin;
    const float y = std::max(kMenuBar, std::min(col.y, bottom - kMinHeight));
    ImGui::SetNextWindowPos(ImVec2(std::max(0.0f, col.x), y), ImGuiCond_Always);
    ImGui::SetNextWindowSizeConstraints(ImVec2(col.width, 0.0f),
                                        ImVec2(col.width, std::max(kMinHeight, bottom - y)));
    return ImGui::Begin(name, open, ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoMove);
}

/// End the panel Begun last; the next one in `col` goes under it.
void endPanel(Column& col) {
    col.y = ImGui::GetWindowPos().y + ImGui::GetWindowHeight() + kGap;
    ImGui::End();
}

void panel(const char* name, bool& open, Column& col, void (*content)(ViewerState&),
           ViewerState& st) {
    if (!open) return;
    if (beginPanel(name, &open, col)) content(st);
    endPanel(col);
}

/// The column with more room left.
Column& roomier(Column& a, Column& b) { return a.y <= b.y ? a : b; }

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
        ImGui::MenuItem("Ray", nullptr, &s.showRay);
        ImGui::Separator();
        bool hidden = st.panelsHidden();
        if (ImGui::MenuItem("Hide all", "Tab", &hidden)) st.setPanelsHidden(hidden);
        ImGui::EndMenu();
    }
    ImGui::TextDisabled("%s", s.scene.c_str());
    if (st.building()) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "building...");
    if (!st.error().empty())
        ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "error (see Parameters)");
    ImGui::EndMainMenuBar();
}

void drawPanels(ViewerState& st) {
    if (st.panelsHidden()) return;
    ViewerSettings& s = st.settings();
    const float width = ImGui::GetIO().DisplaySize.x;
    menuBar(st);
    Column left{kMargin, 330.0f, kMenuBar};
    Column right{width - 348.0f, 340.0f, kMenuBar};
    panel("Parameters", s.showParameters, left, parametersPanel, st);
    panel("Statistics", s.showStatistics, right, statisticsPanel, st);
    panel("View", s.showView, right, viewPanel, st);
    panel("Camera", s.showCamera, roomier(left, right), cameraPanel, st);
    // An inspector view goes here, in the column with more room (roomier()).
}

}  // namespace lancer::viewer
