#include "app/viewer/viewer_app.h"

#include <imgui.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>

#include "app/viewer/gl.h"
#include "app/viewer/input.h"
#include "app/viewer/panels/panels.h"

namespace lancer::viewer {

ViewerApp::ViewerApp(ViewerSettings& settings, bool logTimings, std::function<void()> wake)
    : state_(settings, logTimings, wake),
      view_(std::make_unique<ImageView>()),
      inspector_(std::make_unique<inspector::Inspector>(std::move(wake))) {
    // Opaque panels (ImGui's dark style has them 94% opaque): the image under them is not
    // drawn at all, and each is copied from a layer where it is redrawn only when it changes
    // (frame(), PanelCache).
    ImGuiStyle& style = ImGui::GetStyle();
    style.Colors[ImGuiCol_WindowBg].w = 1.0f;
    style.Colors[ImGuiCol_PopupBg].w = 1.0f;
    style.Colors[ImGuiCol_TitleBgCollapsed].w = 1.0f;
}

ViewerApp::~ViewerApp() = default;

void ViewerApp::frame(int fbWidth, int fbHeight) {
    // 1. Poll: the structure and the image the workers finished since the last frame.
    state_.poll();

    // 2. Input: the camera's mouse and keys (unless ImGui wants them).
    ImGui_ImplOpenGL3_NewFrame();
    ImGui::NewFrame();
    ViewerSettings& s = state_.settings();
    inspector_->setShown(s.showInspector);
    inspector_->update(state_.sceneBuild(),
                       {state_.camera(), std::max(state_.width(), 1), std::max(state_.height(), 1)},
                       fbWidth, fbHeight, selected_);
    // The inspector's half of the window moves the inspector's camera, and a click there picks.
    std::optional<int64_t> picked;
    if (inspector_->handleMouse(fbWidth, fbHeight, picked)) {
        if (picked) selectRegion(*picked);
    } else {
        handleMouse(state_, fbHeight);
    }
    handleKeys(state_);

    // 3. Panels: each reads and acts on the state (panels/). An inspector view, a panel showing
    // a texture of its own drawing, goes in drawPanels' list and calls
    // panels_.invalidate(its window's ID) whenever that texture's pixels change.
    drawPanels(state_);
    if (s.showInspector) inspector_->panel(&s.showInspector);
    state_.startWork(fbWidth, fbHeight);
    ImGui::Render();

    // 4. Image: the traced image or a heat map, copied only around the opaque panels drawn over
    // it in step 6. The image covers the whole framebuffer: clear only while there is none (one
    // full-screen fill less per frame, which software GL feels).
    if (RowRange rows; state_.takeUpload(rows))
        view_->upload(state_.shown(), s.mode, rows.begin, rows.end);
    glViewport(0, 0, fbWidth, fbHeight);
    if (view_->width() == 0) {
        glClearColor(0.12f, 0.12f, 0.14f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
    }
    std::vector<PixelRect> covered = panels_.layout(ImGui::GetDrawData(), fbWidth, fbHeight);
    if (inspector_->shown()) covered.push_back(inspector::Inspector::viewport(fbWidth, fbHeight));
    view_->draw(fbWidth, fbHeight, s.mode, state_.heatScale(), covered);

    // 4b. The 3D inspector over the right half (the image is not copied under it).
    inspector_->draw(fbWidth, fbHeight);

    // 5. Overlays: drawn over the image, under the panels (the panel layer replaces the pixels
    // of every panel's rectangle next). Nothing is drawn here yet; app/viewer/overlay/ draws
    // the structure's regions and the rays here.

    // 6. Panel layer: ImGui's panels, each rasterized again only when it changed.
    panels_.render();

    PanelNotes& notes = state_.notes();
    if (!notes.pendingScreenshot.empty()) {
        try {
            saveScreenshot(notes.pendingScreenshot, fbWidth, fbHeight);
            notes.screenshotNote = "saved " + notes.pendingScreenshot;
        } catch (const std::exception& e) {
            notes.screenshotNote = e.what();
        }
        notes.pendingScreenshot.clear();
    }
    settled_ = state_.settledSince() && inspector_->settled();
}

void ViewerApp::saveScreenshot(const std::string& path, int fbWidth, int fbHeight) const {
    writePng(path, fbWidth, fbHeight, readFramebuffer(fbWidth, fbHeight));
}

}  // namespace lancer::viewer
