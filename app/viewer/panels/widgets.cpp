#include "app/viewer/panels/widgets.h"

namespace lancer::viewer {

void errorText(const std::string& text) {
    if (text.empty()) return;
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.45f, 1.0f));
    ImGui::TextWrapped("%s", text.c_str());
    ImGui::PopStyleColor();
}

void errorLines(const std::string& text, int lines) {
    const float h = float(lines) * ImGui::GetTextLineHeightWithSpacing();
    ImGui::BeginChild("##error", ImVec2(0.0f, h), false);
    errorText(text);
    ImGui::EndChild();
    if (!text.empty() && ImGui::IsItemHovered()) ImGui::SetTooltip("%s", text.c_str());
}

void hintText(const char* text) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("%s", text);
    ImGui::PopStyleColor();
}

}  // namespace lancer::viewer
