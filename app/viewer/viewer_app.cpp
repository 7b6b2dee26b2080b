#include "app/viewer/viewer_app.h"

#include <imgui.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>

#include "app/viewer/gl.h"
#include "app/viewer/gl/batch.h"
#include "app/viewer/input.h"
#include "app/viewer/panels/panels.h"
#include "app/viewer/playback/ray_drawing.h"

namespace lancer::viewer {

namespace {

/// What the overlays' optional work keeps back of the frame's budget beside the learned costs
/// of the steps after it (the image's rows to composite, the composite of the layer's changes,
/// the inspector's copy to the window, the panel layer and the swap, added each frame): the
/// flush of the frame's drawing before the inspector (about 6 ms) and room for the inspector's
/// pieces, or more (layerReserveMs()). See the constructor.
constexpr double kLayerReserveMs = 9.0;
/// Of kLayerReserveMs, the room for the inspector's pieces beside the flush.
constexpr double kInspectorRoomMs = 3.0;
/// What the inspector's and the panels' optional work keeps back for the swap and what follows
/// the frame's steps (0.1-0.5 ms, 2026-12-07).
constexpr double kSwapReserveMs = 1.0;

bool sameCamera(const Camera& a, const Camera& b) {
    return a.from == b.from && a.at == b.at && a.up == b.up && a.fov == b.fov &&
           a.projection == b.projection && a.orthoHeight == b.orthoHeight;
}

}  // namespace

ViewerApp::ViewerApp(ViewerSettings& settings, bool logTimings, std::function<void()> wake)
    : state_(settings, logTimings, wake),
      view_(std::make_unique<ImageView>()),
      overlays_(std::make_unique<overlay::Overlays>()),
      logTimings_(logTimings),
      inspector_(std::make_unique<inspector::Inspector>(wake)) {
    overlays_->buildInBackground(wake);
    inspector_->buildInBackground(std::move(wake));
    inspector_->drawInParts(1000, 4.0);
    // One budget for the frame (FrameBudget): each step that may leave work for the next
    // frame starts a part only when the part's learned cost fits in what is left, less what
    // the steps after it take in a frame that runs them all (balls4's slabs with the
    // inspector, the slow-frame lines of --log-timings, 2026-12-06/07): after the layer, the
    // image's changed texels (3-5 ms), the flush of the frame's drawing before the
    // inspector's picture (the image's copy and the layer, about 6 ms), the inspector's copy
    // to the window (4-5 ms) and the panel layer; after the inspector, the panel layer (its
    // copies about 3 ms, the panels it must draw again 1-2 ms each) and the swap; after a
    // panel, the copies of the panels and the swap. What the panel layer and the inspector's
    // copy take is learned (PanelCache::estimateMs(), the inspector's own) and set each
    // frame (frame()).
    overlays_->setFrameBudget(&budget_, kLayerReserveMs);
    inspector_->setFrameBudget(&budget_, kSwapReserveMs);
    panels_.setFrameBudget(&budget_, kSwapReserveMs);
    // Opaque panels (ImGui's dark style has them 94% opaque): the image under them is not
    // drawn at all, and each is copied from a layer where it is redrawn only when it changes
    // (frame(), PanelCache).
    ImGuiStyle& style = ImGui::GetStyle();
    style.Colors[ImGuiCol_WindowBg].w = 1.0f;
    style.Colors[ImGuiCol_PopupBg].w = 1.0f;
    style.Colors[ImGuiCol_TitleBgCollapsed].w = 1.0f;
    // The overlays' and the inspector's options as the ini left them (a --show list, applied
    // after, overrides the layers).
    overlays_->options = settings.overlays;
    overlays_->look = settings.overlayLook;
    settings.overlayLook.replayCuts = overlays_->look.replayCuts = -1;
    inspector::InspectorOptions& o = inspector_->options();
    o = settings.inspector;
    o.show = settings.showInspector;
    inspector_->changed();
    if (settings.inspectorCamera)
        inspector_->restoreCamera(*settings.inspectorCamera, settings.inspectorScene);
}

void ViewerApp::keepSettings() {
    // The ini handler writes from the settings: they follow the overlays and the inspector,
    // and a change marks the ini to be saved.
    ViewerSettings& s = state_.settings();
    bool changed = false;
    auto keep = [&changed](auto& kept, const auto& now) {
        if (kept == now) return;
        kept = now;
        changed = true;
    };
    overlay::OverlayOptions oo = overlays_->options;
    oo.only = {};  // the played ray's, not a setting
    keep(s.overlays, oo);
    overlay::OverlayLook look = overlays_->look;
    look.replayCuts = -1;  // the replay belongs to the structure on screen
    keep(s.overlayLook, look);
    inspector::InspectorOptions io = inspector_->options();
    io.show = false;
    io.only = {};
    keep(s.inspector, io);
    if (!inspector_->cameraScene().empty()) {
        const Camera& c = inspector_->camera();
        if (!s.inspectorCamera || !sameCamera(*s.inspectorCamera, c) ||
            s.inspectorScene != inspector_->cameraScene()) {
            s.inspectorCamera = c;
            s.inspectorScene = inspector_->cameraScene();
            changed = true;
        }
    }
    if (changed && ImGui::GetCurrentContext()) ImGui::MarkIniSettingsDirty();
}

ViewerApp::~ViewerApp() = default;

double ViewerApp::layerReserveMs(double flushMs) {
    return std::max(kLayerReserveMs, kInspectorRoomMs + flushMs);
}

void ViewerApp::pickPixel(int x, int y, int ray, int step) {
    player_.pickScripted({x, y, ray, step});
    state_.settings().showRay = true;
}

namespace {

/// A Shift+click on the image viewport picks the pixel for the ray playback; a Ctrl+click is
/// the overlays' pick of a region.
std::optional<glm::ivec2> shiftClick(const ViewerState& st) {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse || !io.KeyShift || io.KeyCtrl ||
        !ImGui::IsMouseClicked(ImGuiMouseButton_Left))
        return std::nullopt;
    const auto px = st.pixelUnderMouse();
    if (!px) return std::nullopt;
    return glm::ivec2(px->first, px->second);
}

/// `r` (display units) in framebuffer pixels.
PixelRect toPixels(const Rect& r, glm::vec2 scale) {
    return {int(std::lround(r.x0 * scale.x)), int(std::lround(r.y0 * scale.y)),
            int(std::lround(r.x1 * scale.x)), int(std::lround(r.y1 * scale.y))};
}

}  // namespace

void ViewerApp::frame(int fbWidth, int fbHeight) {
    // 1. Poll: the structure and the image the workers finished since the last frame.
    phases_.begin();
    budget_.begin();
    state_.poll();
    phases_.mark("poll");

    // 2. Input: the camera's mouse and keys (unless ImGui wants them).
    ImGui_ImplOpenGL3_NewFrame();
    ImGui::NewFrame();
    ViewerSettings& s = state_.settings();
    // The layout of this frame (panels/layout.h): the inspector's view goes where it says.
    const ImGuiIO& io = ImGui::GetIO();
    layout_ = planPanels(state_, panelHeights_, io.DisplaySize.x, io.DisplaySize.y);
    const glm::vec2 scale(io.DisplayFramebufferScale.x, io.DisplayFramebufferScale.y);
    inspector_->setArea(toPixels(layout_.inspector, scale));
    // The image viewport: the render's size, and where mouse and pixels meet.
    PixelRect area = toPixels(layout_.image, scale);
    area.x0 = std::clamp(area.x0, 0, fbWidth);
    area.x1 = std::clamp(area.x1, area.x0, fbWidth);
    area.y0 = std::clamp(area.y0, 0, fbHeight);
    area.y1 = std::clamp(area.y1, area.y0, fbHeight);
    state_.setImageArea(area);
    const int imageW = area.x1 - area.x0, imageH = area.y1 - area.y0;
    // Counts that arrived in the poll: the overlays take them before the keys read them.
    overlays_->setCosts(state_.costs());
    // The batches' copy to GL waits for prepareOverlays(), once the steps after the layer have
    // said what they take in this frame: copied here, with the last frame's reserve, a part
    // took 6-7 ms before any budgeted step (a new structure's batches, balls4's slabs,
    // 2026-12-07).
    overlays_->update(state_.sceneBuild(), state_.camera(), imageW, imageH, cameraMoving(), false);
    inspector_->setShown(s.showInspector);
    phases_.mark("overlay update");
    inspector_->update(state_.sceneBuild(),
                       {state_.camera(), std::max(state_.width(), 1), std::max(state_.height(), 1)},
                       fbWidth, fbHeight, selectedRegion());
    phases_.mark("inspector update");
    // The inspector's half of the window moves the inspector's camera, and a click there picks.
    std::optional<int64_t> picked;
    if (inspector_->handleMouse(fbWidth, fbHeight, picked)) {
        if (picked) selectRegion(*picked);
    } else {
        handleMouse(state_, imageH);
        overlayInput();
    }
    handleKeys(state_);
    handlePlaybackKeys(player_.playback());
    if (frameKeyPressed()) {
        const ImVec2 m = ImGui::GetIO().MousePos;
        const Rect& in = layout_.inspector;
        frameSelection(s.showInspector && m.x >= in.x0 && m.x < in.x1 && m.y >= in.y0 &&
                       m.y < in.y1);
    }

    // 2b. Ray playback: a Shift+click picks a pixel; the pick is traced, traced again after a
    // rebuild, and played on the frame's clock. The current region is the selection, so the
    // inspector highlights it.
    if (std::optional<glm::ivec2> px = shiftClick(state_)) {
        player_.pick(px->x, px->y);
        s.showRay = true;
    }
    const Clock::time_point now = Clock::now();
    const double dt = std::chrono::duration<double>(now - lastFrame_).count();
    lastFrame_ = now;
    player_.update(state_, std::min(dt, 0.5));
    const walk::Region* region = player_.playback().region();
    const int64_t played = region ? int64_t(region->region) : -1;
    if (played != playedRegion_) {
        if (played >= 0 || selectedRegion() == playedRegion_) selectRegion(played);
        playedRegion_ = played;
    }
    syncRegionFilter();
    if (const StepCsg* step = player_.currentStep())
        overlays_->setEvaluatedNodes(step->region, step->pool, step->nodes);
    else
        overlays_->setEvaluatedNodes(-1, nullptr, {});

    phases_.mark("input and playback");
    // 3. Panels: each reads and acts on the state (panels/), where the layout puts it. A panel
    // showing a texture of its own drawing calls panels_.invalidate(its window's ID) whenever
    // that texture's pixels change.
    PanelContents more;
    more.overlays = [this](bool* open) { overlays_->panel(open); };
    more.selection = [this](bool* open) { overlays_->selectionPanel(open); };
    more.inspector = [this](bool* open) { inspector_->panel(open); };
    more.ray = [this](bool* open) { rayPanel(state_, player_, open); };
    more.tree = [this](bool* open) { treePanel(open); };
    drawPanels(state_, layout_, panelHeights_, more);
    // The keys of the overlays and the heat map, in the image viewport's corner.
    KeyInput keys;
    keys.image = layout_.image;
    if (overlays_->view()) {
        keys.overlays = &overlays_->options;
        keys.geometry = &overlays_->geometry();
    }
    keys.mode = s.mode;
    keys.heatScale = state_.heatScale();
    keys.logScale = s.logScale;
    keys.diverging = state_.heatDiverging();
    keys_ = drawKeys(keys);
    // The counts per region of the complete image, for what shows them (a cost colouring, the
    // tree), counted once the image is complete; the overlays take them at their update.
    const overlay::OverlayOptions& oo = overlays_->options;
    if ((oo.any() && oo.usesCosts()) || (s.showTree && !state_.panelsHidden()))
        state_.requestCosts(oo.costRays);
    state_.startWork(imageW, imageH);
    overlays_->setCosts(state_.costs());
    ImGui::Render();
    phases_.mark("panels");

    // 4. Image: the traced image or a heat map, the size of its viewport, copied there only
    // around the opaque popups or menus drawn over it in step 6. What no view fills (the gaps
    // between panels, under the menu bar) is cleared, the image viewport only while there is
    // no image: one full-window fill less per frame, which software GL feels.
    if (RowRange rows; state_.takeUpload(rows)) uploadImage(rows.begin, rows.end);
    phases_.mark("upload");
    // The image's rows to composite in this frame come before the layer's optional work: a
    // new view released whole took 8-16 ms of the image step (balls4, 2026-12-06), so the
    // layer keeps that back too.
    view_->setHold(state_.holdImage());
    // The composite of the texels a new drawing of the layer changes comes after the layer
    // too: its learned cost (a moving camera's layer changes most of its texels, 8-11 ms of
    // the image step on balls4's slabs, a part at rest few) is kept back as well.
    const bool moving = cameraMoving();
    const bool layerDraws = overlays_->options.any() && (moving || overlays_->layerPending());
    StepCost& composite = layerCompositeCost_[moving ? 1 : 0];
    // The panel layer's learned cost in this frame: the panels it must draw again (a new
    // structure's first frame redraws five) are kept back by the steps before it.
    std::vector<PixelRect> covered;  // a menu or a tooltip over the image
    for (const PixelRect& r : panels_.layout(ImGui::GetDrawData(), fbWidth, fbHeight))
        if (r.x0 < area.x1 && area.x0 < r.x1 && r.y0 < area.y1 && area.y0 < r.y1)
            covered.push_back(r);
    const double panelsMs = panels_.estimateMs() + kSwapReserveMs;
    inspector_->setFrameBudget(&budget_, panelsMs);
    const double layerReserve = layerReserveMs(imageFlushCost_.estimateMs(1));
    const double overlaysReserve = layerReserve + panelsMs + inspector_->showEstimateMs() +
                                   view_->shadeEstimateMs(s.mode) +
                                   (layerDraws ? composite.estimateMs(1) : 0.0);
    overlays_->setFrameBudget(&budget_, overlaysReserve);
    const uint64_t layerVersion = overlays_->layerVersion();
    prepareOverlays(imageW, imageH, overlaysReserve);
    const bool layerChanged = overlays_->layerVersion() != layerVersion;
    phases_.mark("overlays");
    // A new view held off the screen is composited in parts as its rows come, so that its
    // release only copies it, and a finer pass's rows in parts with the image step: both
    // within what the steps after the image keep (as the layer keeps for them, less the
    // image's own estimate); the rest waits for the next frames.
    view_->setFrameBudget(&budget_, layerReserve + panelsMs + inspector_->showEstimateMs());
    if (state_.holdImage()) view_->composeHeld();
    glViewport(0, 0, fbWidth, fbHeight);
    glClearColor(0.12f, 0.12f, 0.14f, 1.0f);
    std::vector<PixelRect> views;
    if (view_->showsPicture()) views.push_back(area);
    if (inspector_->shown()) views.push_back(inspector_->area(fbWidth, fbHeight));
    glEnable(GL_SCISSOR_TEST);
    for (const PixelRect& r : uncovered(fbWidth, fbHeight, views)) {
        glScissor(r.x0, fbHeight - r.y1, r.x1 - r.x0, r.y1 - r.y0);
        glClear(GL_COLOR_BUFFER_BIT);
    }
    glDisable(GL_SCISSOR_TEST);
    view_->setViewport(area);
    const double imageStart = budget_.spentMs();
    view_->draw(fbWidth, fbHeight, s.mode, state_.heatScale(), covered, s.logScale,
                state_.heatDiverging());
    // What compositing the layer's changes took (the rows of a pass aside), learned.
    if (layerChanged && view_->lastShade().texels > 0 && view_->lastShade().rows == 0)
        composite.record(1, budget_.spentMs() - imageStart);
    // The frame's GL work so far (the image's copy to the window, the clears around it)
    // finished and learned here, so that the steps before it keep it back (layerReserveMs()):
    // with the inspector shown it was its step's flush (3-7 ms), which no learned cost
    // covered.
    const double flushStart = budget_.spentMs();
    glFinish();
    imageFlushCost_.record(1, budget_.spentMs() - flushStart);
    phases_.mark("image");

    // 4b. The 3D inspector beside the image (the image is not copied under it), with the
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
    phases_.mark("inspector");

    // 5. Overlays: their layers were composited into the image when it was shaded
    // (prepareOverlays); the selection's highlight is drawn over the image, under the panels
    // (the panel layer replaces the pixels of every panel's rectangle next).
    const Clock::time_point selectionStart = Clock::now();
    // In the image viewport, and nowhere else (GL's rows go up).
    const int glY0 = fbHeight - area.y1;
    glEnable(GL_SCISSOR_TEST);
    glScissor(area.x0, glY0, imageW, imageH);
    overlays_->drawSelection(state_.camera(), imageW, imageH, area.x0, glY0);
    glDisable(GL_SCISSOR_TEST);
    overlayStat_.ms +=
        std::chrono::duration<double, std::milli>(Clock::now() - selectionStart).count();

    // 5b. The ray played, with the viewer's camera, as the tracer's rays go through the
    // pixels (gl::worldToClip), in the image viewport.
    if (!rayLines.empty() && state_.width() > 0 && state_.height() > 0) {
        if (!rayRenderer_) rayRenderer_ = std::make_unique<gl::BatchRenderer>();
        const glm::mat4 toClip = playback::imageClipMatrix(
            state_.camera(), state_.width(), state_.height(), player_.playback(), *player_.view());
        glViewport(area.x0, glY0, imageW, imageH);
        glEnable(GL_SCISSOR_TEST);
        glScissor(area.x0, glY0, imageW, imageH);
        rayRenderer_->drawNow(rayLines, toClip);
        glDisable(GL_SCISSOR_TEST);
        glViewport(0, 0, fbWidth, fbHeight);
    }

    phases_.mark("overlays");
    // 6. Panel layer: ImGui's panels, each rasterized again only when it changed.
    panels_.render();
    phases_.mark("panel layer");

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
    settled_ = state_.settledSince() && inspector_->settled() && !overlays_->building() &&
               !overlays_->layerPending() && !player_.pending() && !player_.playback().playing() &&
               panels_.deferred() == 0 && view_->pendingRows() == 0 && layerRead_;
    keepSettings();
}

void ViewerApp::treePanel(bool* open) {
    if (ImGui::Begin(panelTitle(PanelId::Tree), open,
                     ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize)) {
        overlay::OverlayOptions& o = overlays_->options;
        int rays = int(o.costRays);
        const char* which[] = {"all rays", "primary rays"};
        if (ImGui::Combo("cost of", &rays, which, 2)) o.costRays = CostRays(rays);
        const ImageCosts* c = state_.costs().get();
        const RegionCosts* counts =
            costsFit(c, overlays_->structure(), o.costRays) ? &c->costs : nullptr;
        if (const std::optional<uint32_t> r =
                tree_.draw(overlays_->view(), counts, selectedRegion()))
            selectRegion(int64_t(*r));
    }
    ImGui::End();
}

void ViewerApp::uploadImage(int rowBegin, int rowEnd) {
    // A new size comes in parts too, held off the screen until whole (ViewerState).
    const Image& shown = state_.shown();
    const std::vector<float> heat = state_.heatRows(rowBegin, rowEnd);
    view_->upload(shown, state_.settings().mode, rowBegin, rowEnd, heat.empty() ? nullptr : &heat);
}

std::vector<std::string> ViewerApp::applyInspectorShow(const std::vector<std::string>& items) {
    std::vector<std::string> left;
    inspector::InspectorOptions& o = inspector_->options();
    o.boxes = o.frustum = false;
    for (const std::string& item : items) {
        if (item == "inspector")
            showInspector(true);
        else if (item == "boxes")
            o.boxes = true;
        else if (item == "frustum")
            o.frustum = true;
        else
            left.push_back(item);
    }
    inspector_->changed();
    return left;
}

bool ViewerApp::cameraMoving() const {
    return cameraTurning_ || (ImGui::IsAnyMouseDown() && !ImGui::GetIO().WantCaptureMouse);
}

void ViewerApp::prepareOverlays(int fbWidth, int fbHeight, double reserveMs) {
    const Clock::time_point start = Clock::now();
    const uint64_t version = overlays_->layerVersion();
    const Camera& camera = state_.camera();
    overlays_->update(state_.sceneBuild(), camera, fbWidth, fbHeight, cameraMoving());
    // While a drag moves the camera the layers are drawn capped (the longest lines; none if
    // the cap is 0) rather than whole each frame: all of balls4's regular leaves take llvmpipe
    // a quarter of a second. They are drawn whole when the drag ends.
    const bool dragging = cameraMoving() && overlays_->layerStale(camera, fbWidth, fbHeight);
    const unsigned layer = overlays_->layerTexture(camera, fbWidth, fbHeight, dragging);
    // Read back within what the layer's own parts leave (the steps after it keep the same).
    layerRead_ = view_->setOverlay(layer, overlays_->layerVersion(), budget_, reserveMs);
    if (logTimings_)
        logOverlayTiming(std::chrono::duration<double, std::milli>(Clock::now() - start).count(),
                         overlays_->layerVersion() != version);
}

void ViewerApp::logOverlayTiming(double ms, bool layerDrawn) {
    // The overlays' UI work, per frame, apart from frames that drew the layers again (a
    // change): those are logged one by one.
    if (layerDrawn) {
        const overlay::OverlayGeometry& g = overlays_->geometry();
        const bool moving = overlays_->layerPartial() && !overlays_->layerPending();
        std::fprintf(stderr,
                     "timing: overlays: layers drawn again%s in %.2f ms (%zu of %zu lines, %zu "
                     "triangles; batches built in %.2f ms)\n",
                     moving                      ? " while the camera moves"
                     : overlays_->layerPending() ? ", a part"
                                                 : "",
                     overlays_->lastLayerMs(), overlays_->layerDrawn(), overlays_->layerLines(),
                     g.fills.triangleCount(), overlays_->lastBuildMs());
        return;
    }
    overlayStat_.ms += ms;
    ++overlayStat_.frames;
    if (Clock::now() - overlayStat_.since < std::chrono::seconds(2)) return;
    std::fprintf(stderr, "timing: overlays: %.3f ms of UI work a frame (%d frames)\n",
                 overlayStat_.ms / overlayStat_.frames, overlayStat_.frames);
    overlayStat_ = {};
}

void ViewerApp::overlayInput() {
    ImGuiIO& io = ImGui::GetIO();
    // Clicks ImGui wants never pick; a plain left drag orbits, so picking takes Ctrl+click.
    if (io.WantCaptureMouse || !state_.sceneBuild() || !ImGui::IsMousePosValid()) return;
    // Continuous image coordinates: the viewport's corner is the image's (0, 0).
    const PixelRect& area = state_.imageArea();
    const int fbWidth = area.x1 - area.x0, fbHeight = area.y1 - area.y0;
    const double x = double(io.MousePos.x * io.DisplayFramebufferScale.x) - area.x0;
    const double y = double(io.MousePos.y * io.DisplayFramebufferScale.y) - area.y0;
    if (x < 0.0 || y < 0.0 || x >= fbWidth || y >= fbHeight) return;
    // The primary hit's depth under the mouse, from the image on screen when it is this size.
    const Image& shown = state_.shown();
    float depth = std::numeric_limits<float>::infinity();
    if (shown.width == fbWidth && shown.height == fbHeight && !shown.depth.empty())
        depth = shown.depth[shown.index(int(x), int(y))];
    if (io.KeyCtrl && ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {
        overlays_->pickAt(state_.camera(), fbWidth, fbHeight, x, y, depth);
        state_.settings().showSelection = true;
    } else if (!ImGui::IsAnyMouseDown() && !state_.panelsHidden() && overlays_->options.any()) {
        overlays_->tooltip(state_.camera(), fbWidth, fbHeight, x, y, depth);
    }
}

std::vector<std::string> ViewerApp::applyShow(const std::string& list) {
    // The overlays take their layers; the inspector and the ray playback take what they leave.
    std::vector<std::string> left;
    for (std::string& item : applyInspectorShow(overlay::applyShowList(list, overlays_->options))) {
        if (item == "ray") {
            state_.settings().showRay = true;
        } else if (item == "visited") {
            state_.settings().showRay = true;
            state_.settings().rayRegionsOnly = true;
        } else if (item == "tree") {
            state_.settings().showTree = true;
        } else if (item == "worst") {
            state_.settings().showRay = true;
            state_.notes().worstOpen = true;
        } else {
            left.push_back(std::move(item));
        }
    }
    return left;
}

void ViewerApp::selectRegion(int64_t id) {
    if (id < 0) {
        overlays_->clearSelection();
    } else if (overlays_->select(uint32_t(id))) {
        state_.settings().showSelection = true;
    }
}

bool ViewerApp::frameSelection(bool inInspector) {
    const int64_t id = selectedRegion();
    const StructureView* view = overlays_->view();
    if (id < 0 || !view || uint64_t(id) >= view->regionCount()) return false;
    Box3 box;
    for (const Vec3& p : view->regionCorners(uint32_t(id))) box.expand(p);
    // The irregular scheme's regions are cut for the main camera: moving it rebuilds them.
    if (inInspector || view->scheme() == SchemeKind::Irregular) {
        state_.settings().showInspector = true;
        inspector_->setShown(true);
        inspector_->frame(box);
    } else {
        const double aspect = double(std::max(state_.width(), 1)) / std::max(state_.height(), 1);
        state_.setCamera(inspector::framedOn(state_.camera(), box, aspect));
    }
    return true;
}

void ViewerApp::syncRegionFilter() {
    RegionFilter f;
    f.on = state_.settings().rayRegionsOnly && !player_.playback().empty();
    if (f.on) f.ids = playback::visitedRegions(player_.playback());
    if (!(overlays_->options.only == f)) overlays_->options.only = f;
    if (!(inspector_->options().only == f)) {
        inspector_->options().only = f;
        inspector_->changed();
    }
}

void ViewerApp::saveScreenshot(const std::string& path, int fbWidth, int fbHeight) const {
    writeImage(path, fbWidth, fbHeight, readFramebuffer(fbWidth, fbHeight));
}

}  // namespace lancer::viewer
