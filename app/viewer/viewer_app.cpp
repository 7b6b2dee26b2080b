#include "app/viewer/viewer_app.h"

#include <imgui.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>

#include "app/viewer/gl.h"
#include "app/viewer/gl/batch.h"
#include "app/viewer/input.h"
#include "app/viewer/panels/panels.h"
#include "app/viewer/playback/ray_drawing.h"

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

void ViewerApp::pickPixel(int x, int y, int ray, int step) {
    player_.pickScripted({x, y, ray, step});
    state_.settings().showRay = true;
}

namespace {

/// A Shift+click on the image (outside the inspector and the panels) picks the pixel for the
/// ray playback; a Ctrl+click is the overlays' pick of a region.
std::optional<glm::ivec2> shiftClick(int fbWidth, int fbHeight, bool inspectorShown) {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse || !io.KeyShift || io.KeyCtrl ||
        !ImGui::IsMouseClicked(ImGuiMouseButton_Left) || !ImGui::IsMousePosValid())
        return std::nullopt;
    const int x = int(io.MousePos.x * io.DisplayFramebufferScale.x);
    const int y = int(io.MousePos.y * io.DisplayFramebufferScale.y);
    if (x < 0 || y < 0 || x >= fbWidth || y >= fbHeight) return std::nullopt;
    // The inspector takes the whole height of the window's right part.
    if (inspectorShown && x >= inspector::Inspector::viewport(fbWidth, fbHeight).x0)
        return std::nullopt;
    return glm::ivec2(x, y);
}

}  // namespace

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

    // 2b. Ray playback: a Shift+click picks a pixel; the pick is traced, traced again after a
    // rebuild, and played on the frame's clock. The current region is the selection, so the
    // inspector highlights it.
    if (std::optional<glm::ivec2> px = shiftClick(fbWidth, fbHeight, inspector_->shown())) {
        player_.pick(px->x, px->y);
        s.showRay = true;
    }
    const Clock::time_point now = Clock::now();
    const double dt = std::chrono::duration<double>(now - lastFrame_).count();
    lastFrame_ = now;
    player_.update(state_, std::min(dt, 0.5));
    const WalkEvent* region = player_.playback().region();
    const int64_t played = region ? int64_t(region->a) : -1;
    if (played != playedRegion_) {
        if (played >= 0 || selected_ == playedRegion_) selectRegion(played);
        playedRegion_ = played;
    }

    // 3. Panels: each reads and acts on the state (panels/). An inspector view, a panel showing
    // a texture of its own drawing, goes in drawPanels' list and calls
    // panels_.invalidate(its window's ID) whenever that texture's pixels change.
    drawPanels(state_);
    if (s.showInspector) inspector_->panel(&s.showInspector);
    if (s.showRay) rayPanel(state_, player_, &s.showRay);
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

    // 4b. The 3D inspector over the right half (the image is not copied under it), with the
    // ray played drawn into its picture.
    gl::Batch rayLines;
    if (!player_.playback().empty() && player_.view())
        rayLines = playback::rayBatch(player_.playback(), *player_.view());
    if (inspector_->shown()) {
        auto same = [](const gl::BatchVertex& a, const gl::BatchVertex& b) {
            return a.position == b.position && a.color == b.color;
        };
        if (!std::equal(rayLines.lines.begin(), rayLines.lines.end(), inspectorRay_.lines.begin(),
                        inspectorRay_.lines.end(), same)) {
            inspectorRay_ = rayLines;
            inspector_->setExtraLines(rayLines);
        }
    }
    inspector_->draw(fbWidth, fbHeight);

    // 5. Overlays: drawn over the image, under the panels (the panel layer replaces the pixels
    // of every panel's rectangle next): the ray played, with the viewer's camera, as the
    // tracer's rays go through the pixels (gl::worldToClip), left of the inspector.
    if (!rayLines.empty() && state_.width() > 0 && state_.height() > 0) {
        if (!rayRenderer_) rayRenderer_ = std::make_unique<gl::BatchRenderer>();
        const glm::mat4 toClip = playback::imageClipMatrix(
            state_.camera(), state_.width(), state_.height(), player_.playback(), *player_.view());
        glViewport(0, 0, fbWidth, fbHeight);
        if (inspector_->shown()) {
            const PixelRect r = inspector::Inspector::viewport(fbWidth, fbHeight);
            glEnable(GL_SCISSOR_TEST);
            glScissor(0, 0, r.x0, fbHeight);
        }
        rayRenderer_->drawNow(rayLines, toClip);
        glDisable(GL_SCISSOR_TEST);
    }

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
    settled_ = state_.settledSince() && inspector_->settled() && !player_.pending() &&
               !player_.playback().playing();
}

void ViewerApp::saveScreenshot(const std::string& path, int fbWidth, int fbHeight) const {
    writePng(path, fbWidth, fbHeight, readFramebuffer(fbWidth, fbHeight));
}

}  // namespace lancer::viewer
