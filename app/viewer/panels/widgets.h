// Small ImGui pieces the panels share.
#pragma once

#include <imgui.h>

#include <string>

namespace lancer::viewer {

/// `text` wrapped, in the colour of errors (nothing for an empty one).
void errorText(const std::string& text);
/// `text` as errorText() in a region `lines` lines high, there with or without an error, so the
/// controls under it stay where they are; a longer error scrolls and shows whole when hovered.
void errorLines(const std::string& text, int lines);
/// `text` wrapped, greyed out (hints).
void hintText(const char* text);

}  // namespace lancer::viewer
