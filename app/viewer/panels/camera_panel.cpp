#include <imgui.h>

#include "app/viewer/camera_control.h"
#include "app/viewer/panels/panels.h"
#include "app/viewer/panels/widgets.h"

namespace lancer::viewer {

void cameraPanel(ViewerState& st) {
    ImGui::SetNextWindowPos(ImVec2(8, 468), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(330, 215), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Camera", &st.settings().showCamera)) {
        ImGui::End();
        return;
    }
    Camera c = st.camera();
    bool changed = false;
    int proj = int(c.projection);
    ImGui::RadioButton("perspective", &proj, 0);
    ImGui::SameLine();
    ImGui::RadioButton("orthographic", &proj, 1);
    if (proj != int(c.projection)) {
        toggleProjection(c);
        changed = true;
    }
    if (c.projection == Projection::Perspective) {
        double lo = 1.0, hi = 170.0;
        changed |= ImGui::SliderScalar("fov", ImGuiDataType_Double, &c.fov, &lo, &hi, "%.1f deg");
    } else {
        changed |=
            ImGui::InputDouble("height", &c.orthoHeight, 0.0, 0.0, "%.4g") && c.orthoHeight > 0.0;
    }
    changed |= ImGui::InputScalarN("from", ImGuiDataType_Double, &c.from.x, 3, nullptr, nullptr,
                                   "%.4g", ImGuiInputTextFlags_EnterReturnsTrue);
    changed |= ImGui::InputScalarN("at", ImGuiDataType_Double, &c.at.x, 3, nullptr, nullptr, "%.4g",
                                   ImGuiInputTextFlags_EnterReturnsTrue);
    if (changed && c.validate().empty()) st.setCamera(c);
    if (ImGui::Button("Reset (R)")) st.setCamera(st.home());
    ImGui::SameLine();
    if (ImGui::Button("Copy JSON")) st.copyCameraJson();
    ImGui::SameLine();
    if (ImGui::Button("Paste JSON")) st.pasteCameraJson();
    errorText(st.notes().cameraError);
    hintText(
        "Left drag: orbit. Middle drag: pan. Right drag or wheel: zoom. R: reset. O: "
        "perspective/orthographic.");
    ImGui::End();
}

}  // namespace lancer::viewer
