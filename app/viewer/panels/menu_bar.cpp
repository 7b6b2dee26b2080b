#include <imgui.h>

#include "app/viewer/panels/panels.h"

namespace lancer::viewer {

void menuBar(ViewerState& st) {
    ViewerSettings& s = st.settings();
    if (!ImGui::BeginMainMenuBar()) return;
    if (ImGui::BeginMenu("Panels")) {
        ImGui::MenuItem("Parameters", nullptr, &s.showParameters);
        ImGui::MenuItem("Camera", nullptr, &s.showCamera);
        ImGui::MenuItem("Statistics", nullptr, &s.showStatistics);
        ImGui::MenuItem("View", nullptr, &s.showView);
        ImGui::EndMenu();
    }
    ImGui::TextDisabled("%s", s.scene.c_str());
    if (st.building()) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "building...");
    if (!st.error().empty())
        ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "error (see Parameters)");
    ImGui::EndMainMenuBar();
}

void drawPanels(ViewerState& st) {
    const ViewerSettings& s = st.settings();
    menuBar(st);
    if (s.showParameters) parametersPanel(st);
    if (s.showCamera) cameraPanel(st);
    if (s.showStatistics) statisticsPanel(st);
    if (s.showView) viewPanel(st);
}

}  // namespace lancer::viewer
