#include "app/viewer/input.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>

#include "app/viewer/camera_control.h"

namespace lancer::viewer {

void handleMouse(ViewerState& st, int fbHeight) {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse || !st.sceneBuild()) return;
    Camera c = st.camera();
    bool moved = false;
    const float dx = io.MouseDelta.x * io.DisplayFramebufferScale.x;
    const float dy = io.MouseDelta.y * io.DisplayFramebufferScale.y;
    if (dx != 0.0f || dy != 0.0f) {
        if (ImGui::IsMouseDown(ImGuiMouseButton_Left) && !io.KeyCtrl) {  // Ctrl+click picks
            orbit(c, -0.008 * dx, 0.008 * dy);
            moved = true;
        } else if (ImGui::IsMouseDown(ImGuiMouseButton_Middle)) {
            pan(c, dx, dy, std::max(1, fbHeight));
            moved = true;
        } else if (ImGui::IsMouseDown(ImGuiMouseButton_Right)) {
            zoom(c, std::exp(0.01 * dy));
            moved = true;
        }
    }
    if (io.MouseWheel != 0.0f) {
        zoom(c, std::pow(0.9, double(io.MouseWheel)));
        moved = true;
    }
    if (moved) st.setCamera(c);
}

void handleKeys(ViewerState& st) {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureKeyboard || io.WantTextInput) return;
    const int tab = ImGui::GetKeyIndex(ImGuiKey_Tab);
    if (tab >= 0 && ImGui::IsKeyPressed(tab, false)) st.setPanelsHidden(!st.panelsHidden());
    if (!st.sceneBuild()) return;
    for (ImWchar ch : io.InputQueueCharacters) {
        if (ch == 'r' || ch == 'R') {
            st.setCamera(st.home());
        } else if (ch == 'b' || ch == 'B') {  // the rebuild's A/B: old and new in turn
            st.flipAb();
        } else if (ch == 'i' || ch == 'I') {
            st.settings().showInspector = !st.settings().showInspector;
        } else if (ch == 'o' || ch == 'O' || ch == 'p' || ch == 'P') {
            Camera c = st.camera();
            toggleProjection(c);
            st.setCamera(c);
        }
    }
}

namespace {

/// ImGui key `k` went down this frame (with the repeat while held when `repeat`); false when
/// the platform backend maps no key to it.
bool pressed(ImGuiKey k, bool repeat) {
    const int index = ImGui::GetKeyIndex(k);
    return index >= 0 && ImGui::IsKeyPressed(index, repeat);
}

bool keyboardFree() {
    const ImGuiIO& io = ImGui::GetIO();
    return !io.WantCaptureKeyboard && !io.WantTextInput;
}

}  // namespace

bool handlePlaybackKeys(playback::RayPlayback& play) {
    if (!keyboardFree() || play.empty()) return false;
    bool acted = true;
    if (pressed(ImGuiKey_RightArrow, true)) {
        play.pause();
        play.forward();
    } else if (pressed(ImGuiKey_LeftArrow, true)) {
        play.pause();
        play.back();
    } else if (pressed(ImGuiKey_Home, false)) {
        play.pause();
        play.first();
    } else if (pressed(ImGuiKey_End, false)) {
        play.pause();
        play.last();
    } else if (pressed(ImGuiKey_Space, false)) {
        if (play.playing())
            play.pause();
        else
            play.play();
    } else if (pressed(ImGuiKey_DownArrow, true)) {
        if (size_t(play.state().ray) + 1 < play.tree().rays.size())
            play.selectRay(play.state().ray + 1);
    } else if (pressed(ImGuiKey_UpArrow, true)) {
        if (play.state().ray > 0) play.selectRay(play.state().ray - 1);
    } else {
        acted = false;
    }
    return acted;
}

bool frameKeyPressed() {
    if (!keyboardFree()) return false;
    for (ImWchar ch : ImGui::GetIO().InputQueueCharacters)
        if (ch == 'f' || ch == 'F') return true;
    return false;
}

}  // namespace lancer::viewer
