// Small ImGui pieces the panels share.
#pragma once

#include <imgui.h>

#include <string>

namespace lancer::viewer {

/// A combo box over the values 0..count-1 of an enum, named by `name`. True when changed.
template <class E>
bool enumCombo(const char* label, E& value, int count, const char* (*name)(E)) {
    bool changed = false;
    if (ImGui::BeginCombo(label, name(value))) {
        for (int i = 0; i < count; ++i) {
            bool selected = int(value) == i;
            if (ImGui::Selectable(name(E(i)), selected) && !selected) {
                value = E(i);
                changed = true;
            }
        }
        ImGui::EndCombo();
    }
    return changed;
}

/// `text` wrapped, in the colour of errors (nothing for an empty one).
void errorText(const std::string& text);
/// `text` wrapped, greyed out (hints).
void hintText(const char* text);

}  // namespace lancer::viewer
