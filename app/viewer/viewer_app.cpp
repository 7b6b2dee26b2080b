#include "app/viewer/viewer_app.h"

#include <imgui.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty
#include <imgui_stdlib.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "app/viewer/camera_control.h"
#include "app/viewer/gl.h"
#include "engine/scene/builtin_scenes.h"

namespace lancer::viewer {

struct ViewerApp::Speedup {
    std::atomic<bool> cancel{false}, done{false};
    SpeedupResult result;
    int stride = 4;
};

namespace {

double msSince(ViewerApp::Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(ViewerApp::Clock::now() - t).count();
}

std::string humanBytes(size_t b) {
    char buf[64];
    if (b < 10 * 1024)
        std::snprintf(buf, sizeof buf, "%zu B", b);
    else if (b < 10 * 1024 * 1024)
        std::snprintf(buf, sizeof buf, "%.1f KiB", double(b) / 1024.0);
    else
        std::snprintf(buf, sizeof buf, "%.1f MiB", double(b) / (1024.0 * 1024.0));
    return buf;
}

/// "builtin:NAME[:SIZE]" split into its name and size (-1: none); false for a file path.
bool parseBuiltin(const std::string& spec, std::string& name, int& size) {
    if (spec.rfind("builtin:", 0) != 0) return false;
    std::string rest = spec.substr(8);
    size = -1;
    size_t colon = rest.find(':');
    if (colon != std::string::npos) {
        try {
            size = std::stoi(rest.substr(colon + 1));
        } catch (...) {
            size = -1;
        }
        rest = rest.substr(0, colon);
    }
    name = rest;
    return true;
}

const BuiltinInfo* findBuiltin(const std::string& name) {
    for (const BuiltinInfo& b : builtinScenes())
        if (name == b.name) return &b;
    return nullptr;
}

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

}  // namespace

ViewerApp::ViewerApp(ViewerSettings& settings, bool logTimings, std::function<void()> wake)
    : s_(settings),
      logTimings_(logTimings),
      view_(std::make_unique<ImageView>()),
      inspector_(std::make_unique<inspector::Inspector>(wake)) {
    if (wake) {
        renderer_.setOnPass(wake);
        builder_.setOnReady(wake);
    }
    pathInput_ = s_.scene.rfind("builtin:", 0) == 0 ? "" : s_.scene;
    // Opaque panels (ImGui's dark style has them 94% opaque): the image under them is not
    // drawn at all, and each is copied from a layer where it is redrawn only when it changes
    // (frame(), PanelCache).
    ImGuiStyle& style = ImGui::GetStyle();
    style.Colors[ImGuiCol_WindowBg].w = 1.0f;
    style.Colors[ImGuiCol_PopupBg].w = 1.0f;
    style.Colors[ImGuiCol_TitleBgCollapsed].w = 1.0f;
    requestBuild(true, "open scene");
}

ViewerApp::~ViewerApp() {
    if (speedup_) speedup_->cancel = true;
    if (speedupThread_.joinable()) speedupThread_.join();
    renderer_.cancel();
}

void ViewerApp::logTiming(const std::string& line) const {
    if (logTimings_) std::cerr << "timing: " << line << std::endl;
}

void ViewerApp::openScene(const std::string& spec) {
    s_.scene = spec;
    if (spec.rfind("builtin:", 0) != 0) pathInput_ = spec;  // a dropped file shows in the field
    ImGui::MarkIniSettingsDirty();
    requestBuild(true, "open scene");
}

void ViewerApp::setViewMode(ViewMode mode) {
    s_.mode = mode;
    view_->upload(shown_, s_.mode);
    updateAutoScale();
}

void ViewerApp::updateAutoScale() {
    if (s_.mode != ViewMode::Color) autoScale_ = autoScale(heatChannel(shown_, s_.mode));
}

void ViewerApp::updateScale() {
    if (s_.mode != ViewMode::Color) scale_ = s_.autoScale ? autoScale_ : s_.heatScale;
}

void ViewerApp::setHeatScale(float scale) {
    s_.autoScale = false;
    s_.heatScale = scale;
}

void ViewerApp::setCamera(const Camera& c) {
    camera_ = c;
    cameraSet_ = true;
    markRender("camera");
    if (s_.build.scheme == SchemeKind::Irregular) cameraMovedForBuild_ = true;
}

void ViewerApp::copyCameraJson() { ImGui::SetClipboardText(camera_.toJson().c_str()); }

bool ViewerApp::pasteCameraJson() {
    const char* clip = ImGui::GetClipboardText();
    cameraJson_ = clip ? clip : "";
    try {
        setCamera(cameraFromJson(cameraJson_, camera_));
        cameraError_.clear();
        return true;
    } catch (const std::exception& e) {
        cameraError_ = e.what();
        return false;
    }
}

void ViewerApp::requestBuild(bool reloadScene, const char* why) {
    BuildRequest r;
    r.params = s_.build;
    if (reloadScene || !structure_) {
        r.spec = s_.scene;
    } else {
        r.spec = structure_->spec;
        r.loaded = structure_->scene;
        r.camera = camera_;
    }
    buildChangeAt_ = Clock::now();
    buildWhy_ = why;
    builder_.request(std::move(r));
}

void ViewerApp::markRender(const char* why) {
    renderDirty_ = true;
    renderWhy_ = why;
    changeAt_ = Clock::now();
}

void ViewerApp::restartRender(const char* why) {
    if (!structure_ || jobWidth_ <= 0 || jobHeight_ <= 0) return;
    ProgressiveJob job;
    job.scene = structure_->scene;
    job.accel = structure_->accel;
    job.options.width = jobWidth_;
    job.options.height = jobHeight_;
    job.options.threads = s_.threads;
    job.options.shading = s_.shading;
    job.options.camera = camera_;
    if (speedup_ && !speedup_->done) speedup_->cancel = true;  // its view is gone
    renderer_.start(std::move(job), changeAt_);
    changeWhy_ = why;
    passesLogged_ = 0;
    renderDirty_ = false;
}

void ViewerApp::pollBackground() {
    if (std::optional<BuildResult> r = builder_.poll()) {
        if (r->structure) {
            const bool newScene = !structure_ || structure_->spec != r->structure->spec;
            logTiming(buildWhy_ + ": structure ready " + std::to_string(msSince(buildChangeAt_)) +
                      " ms after the change (load " + std::to_string(r->structure->loadMs) +
                      " ms, build " + std::to_string(r->structure->accel->info().buildMs) + " ms)");
            structure_ = r->structure;
            if (newScene) {
                home_ = structure_->scene->camera;
                camera_ = home_;
                cameraSet_ = true;
                s_.scene = structure_->spec;
                builtinSize_ = -1;
            }
            if (structure_->accel->params().scheme == s_.build.scheme) error_.clear();
            changeAt_ = buildChangeAt_;
            renderDirty_ = true;
            renderWhy_ = buildWhy_;
        } else {
            error_ = (r->sceneFailed ? "Scene not loaded: " : "Structure not built: ") + r->error;
            std::cerr << "lancer view: " << error_ << "\n";
            if (structure_) {
                // Keep what is on screen, and the settings that describe it.
                if (r->sceneFailed)
                    s_.scene = structure_->spec;
                else
                    s_.build = structure_->accel->params();
            } else if (!r->sceneFailed && s_.build.scheme != SchemeKind::Brute) {
                // Nothing on screen yet: show the scene with the reference scheme meanwhile.
                s_.build.scheme = SchemeKind::Brute;
                requestBuild(true, "fallback to brute force");
            }
        }
    }
}

void ViewerApp::handleInput(int fbWidth, int fbHeight) {
    ImGuiIO& io = ImGui::GetIO();
    // The inspector's half of the window moves the inspector's camera, and a click there picks.
    std::optional<int64_t> picked;
    if (inspector_->handleMouse(fbWidth, fbHeight, picked)) {
        if (picked) selectRegion(*picked);
        return;
    }
    if (io.WantCaptureMouse || !structure_) return;
    Camera c = camera_;
    bool moved = false;
    const float dx = io.MouseDelta.x * io.DisplayFramebufferScale.x;
    const float dy = io.MouseDelta.y * io.DisplayFramebufferScale.y;
    if (dx != 0.0f || dy != 0.0f) {
        if (ImGui::IsMouseDown(ImGuiMouseButton_Left)) {
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
    if (moved) setCamera(c);
}

void ViewerApp::handleKeys() {
    ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureKeyboard || io.WantTextInput || !structure_) return;
    for (ImWchar ch : io.InputQueueCharacters) {
        if (ch == 'r' || ch == 'R') {
            setCamera(home_);
        } else if (ch == 'i' || ch == 'I') {
            showInspector(!inspector_->shown());
        } else if (ch == 'o' || ch == 'O' || ch == 'p' || ch == 'P') {
            Camera c = camera_;
            toggleProjection(c);
            setCamera(c);
        }
    }
}

void ViewerApp::takeSnapshot() {
    ProgressiveRenderer::Shown what;
    if (!renderer_.snapshot(shownVersion_, shown_, &what)) return;
    view_->upload(shown_, s_.mode, what.changedBegin, what.changedEnd);
    shownJob_ = what.job;
    shownStride_ = what.stride;
    updateAutoScale();
    if (!logTimings_) return;
    // Passes this snapshot holds whole (one may have finished since it was taken), logged once
    // the frame showing them is on screen (presented()).
    std::vector<PassRecord> passes = renderer_.passes();
    for (; passesLogged_ < passes.size(); ++passesLogged_) {
        const PassRecord& p = passes[passesLogged_];
        if (p.stride < what.stride || (p.stride == what.stride && what.rows < shown_.height)) break;
        pendingLogs_.push_back(
            {changeWhy_ + ": pass stride " + std::to_string(p.stride) + " visible ",
             " ms after the change (pass render " + std::to_string(p.renderMs) + " ms, " +
                 std::to_string(shown_.width) + "x" + std::to_string(shown_.height) + ")",
             changeAt_});
        if (p.stride == 1)
            pendingLogs_.push_back(
                {changeWhy_ + ": full image ", " ms after the change", changeAt_});
    }
}

void ViewerApp::presented() {
    for (const PendingLog& l : pendingLogs_)
        logTiming(l.before + std::to_string(msSince(l.since)) + l.after);
    pendingLogs_.clear();
}

void ViewerApp::frame(int fbWidth, int fbHeight) {
    // Read before taking the snapshot: if the job was finished then, the snapshot below is final.
    bool finishedBefore = renderer_.finished();
    // Likewise: a builder idle before the poll has nothing left that this frame has not taken.
    const bool builtBefore = !builder_.busy();
    pollBackground();
    takeSnapshot();
    updateScale();

    ImGui_ImplOpenGL3_NewFrame();
    ImGui::NewFrame();
    inspector_->update(structure_, {camera_, std::max(jobWidth_, 1), std::max(jobHeight_, 1)},
                       fbWidth, fbHeight, selected_);
    handleInput(fbWidth, fbHeight);
    handleKeys();
    panels();
    if (fbWidth > 0 && fbHeight > 0 && (fbWidth != jobWidth_ || fbHeight != jobHeight_)) {
        jobWidth_ = fbWidth;
        jobHeight_ = fbHeight;
        if (!renderDirty_) markRender("window size");  // else keep the pending change's time
    }
    // The irregular scheme's regions live in the camera frame: rebuild once the drag ends.
    if (cameraMovedForBuild_ && !ImGui::IsAnyMouseDown()) {
        cameraMovedForBuild_ = false;
        if (s_.build.scheme == SchemeKind::Irregular)
            requestBuild(false, "camera (irregular frame)");
    }
    if (renderDirty_ && structure_) {
        restartRender(renderWhy_.c_str());
        finishedBefore = false;  // the snapshot above is of the job just cancelled
        // The frame does not wait for the first pass: the worker wakes the window when it is
        // ready, and the next frame shows it. (Waiting up to 40 ms here, to show it in this
        // frame, saved about 5 ms of latency on balls4 and cost a frame of up to 40 ms at
        // every change: below 60 frames a second.)
    }
    ImGui::Render();

    glViewport(0, 0, fbWidth, fbHeight);
    // The image is drawn over the whole framebuffer: clear only while there is none (one
    // full-screen fill less per frame, which software GL feels).
    if (view_->width() == 0) {
        glClearColor(0.12f, 0.12f, 0.14f, 1.0f);
        glClear(GL_COLOR_BUFFER_BIT);
    }
    // The image is copied only around the opaque panels drawn over it next.
    std::vector<PixelRect> covered = panels_.layout(ImGui::GetDrawData(), fbWidth, fbHeight);
    if (inspector_->shown()) covered.push_back(inspector::Inspector::viewport(fbWidth, fbHeight));
    view_->draw(fbWidth, fbHeight, s_.mode, scale_, covered);
    inspector_->draw(fbWidth, fbHeight);
    panels_.render();
    if (!pendingScreenshot_.empty()) {
        try {
            saveScreenshot(pendingScreenshot_, fbWidth, fbHeight);
            screenshotNote_ = "saved " + pendingScreenshot_;
        } catch (const std::exception& e) {
            screenshotNote_ = e.what();
        }
        pendingScreenshot_.clear();
    }

    settled_ = builtBefore && !builder_.busy() &&
               (!structure_ || (!renderDirty_ && finishedBefore && renderer_.finished())) &&
               inspector_->settled();
}

bool ViewerApp::eager() const {
    if (builder_.busy() || builder_.ready() || renderDirty_ || shownJob_ != renderer_.job())
        return true;
    const ProgressiveRenderer::Shown next = renderer_.latest();
    return next.stride != shownStride_ || (renderer_.finished() && !settled_);
}

void ViewerApp::saveScreenshot(const std::string& path, int fbWidth, int fbHeight) const {
    writePng(path, fbWidth, fbHeight, readFramebuffer(fbWidth, fbHeight));
}

void ViewerApp::panels() {
    if (ImGui::BeginMainMenuBar()) {
        if (ImGui::BeginMenu("Panels")) {
            ImGui::MenuItem("Parameters", nullptr, &s_.showParameters);
            ImGui::MenuItem("Camera", nullptr, &s_.showCamera);
            ImGui::MenuItem("Statistics", nullptr, &s_.showStatistics);
            ImGui::MenuItem("View", nullptr, &s_.showView);
            ImGui::EndMenu();
        }
        ImGui::TextDisabled("%s", s_.scene.c_str());
        if (builder_.busy()) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "building...");
        if (!error_.empty())
            ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "error (see Parameters)");
        ImGui::EndMainMenuBar();
    }
    if (s_.showParameters) parametersPanel();
    if (s_.showCamera) cameraPanel();
    if (s_.showStatistics) statisticsPanel();
    if (s_.showView) viewPanel();
}

void ViewerApp::parametersPanel() {
    ImGui::SetNextWindowPos(ImVec2(8, 28), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(330, 430), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Parameters", &s_.showParameters)) {
        ImGui::End();
        return;
    }
    bool rebuild = false, rerender = false;

    // Scene: a built-in (with its size) or a file.
    std::string bname;
    int bsize = -1;
    const bool isBuiltin = parseBuiltin(s_.scene, bname, bsize);
    const BuiltinInfo* info = isBuiltin ? findBuiltin(bname) : nullptr;
    if (ImGui::BeginCombo("built-in", info ? info->name : "(file)")) {
        for (const BuiltinInfo& b : builtinScenes()) {
            if (ImGui::Selectable(b.name, info == &b)) openScene(std::string("builtin:") + b.name);
            if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", b.description);
        }
        ImGui::EndCombo();
    }
    if (info && info->maxSize > info->minSize) {
        if (builtinSize_ < 0) builtinSize_ = bsize >= 0 ? bsize : info->defaultSize;
        ImGui::SliderInt("size", &builtinSize_, info->minSize,
                         std::min(info->maxSize, info->minSize + 64));
        if (ImGui::IsItemDeactivatedAfterEdit())
            openScene("builtin:" + std::string(info->name) + ":" + std::to_string(builtinSize_));
    }
    ImGui::InputText("file", &pathInput_);
    ImGui::SameLine();
    if (ImGui::Button("Open") && !pathInput_.empty()) openScene(pathInput_);
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("or drop a .json / .nff / .csg file on the window");
    ImGui::PopStyleColor();
    if (!error_.empty()) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.45f, 1.0f));
        ImGui::TextWrapped("%s", error_.c_str());
        ImGui::PopStyleColor();
    }

    ImGui::Separator();
    ImGui::TextUnformatted("Subdivision");
    rebuild |= enumCombo("scheme", s_.build.scheme, 3, schemeName);
    if (ImGui::InputInt("max-level", &s_.build.maxLevel)) {
        s_.build.maxLevel = std::clamp(s_.build.maxLevel, 0, 48);
        rebuild = true;
    }
    if (ImGui::InputInt("max-objects", &s_.build.maxObjects)) {
        s_.build.maxObjects = std::clamp(s_.build.maxObjects, 1, 1000000);
        rebuild = true;
    }
    rebuild |= enumCombo("split axes", s_.build.splitAxes, 2, splitAxesName);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "Regular: cycle cuts x, y, z in turn (the report's); cost picks each\n"
            "level's axis by an area estimate (cells stay about cubic)");
    rebuild |= enumCombo("step", s_.build.step, 2, stepName);
    if (s_.build.step == StepMethod::Push) {
        double d = s_.build.delta;
        if (ImGui::InputDouble("delta", &d, 0.0, 0.0, "%.3e",
                               ImGuiInputTextFlags_EnterReturnsTrue) &&
            d >= 1e-15 && d <= 0.5) {
            s_.build.delta = d;
            rebuild = true;
        }
    }
    rebuild |= enumCombo("BSP heuristic", s_.build.heuristic, 3, heuristicName);
    rebuild |= ImGui::Checkbox("mailboxes", &s_.build.mailboxes);
    ImGui::SameLine();
    rebuild |= ImGui::Checkbox("light buffer", &s_.build.lightBuffer);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Shadow rays stop where the light's depth map says nothing is left");
    if (structure_) {
        const AccelInfo& ai = structure_->accel->info();
        ImGui::Text("on screen: %s, built in %.1f ms",
                    schemeName(structure_->accel->params().scheme), ai.buildMs);
        ImGui::Text("regions %zu, memory %s", ai.regions, humanBytes(ai.memoryBytes).c_str());
        ImGui::Text("%zu primitives (%d dropped by minimization)", structure_->scene->prims.size(),
                    structure_->scene->droppedPrims);
    }
    if (builder_.busy())
        ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "building in the background...");

    ImGui::Separator();
    ImGui::TextUnformatted("Rendering");
    int maxThreads = effectiveThreads(0);
    rerender |= ImGui::SliderInt("threads", &s_.threads, 0, std::max(maxThreads, 1),
                                 s_.threads ? "%d" : "all");
    rerender |= ImGui::Checkbox("shadows", &s_.shading.shadows);
    ImGui::SameLine();
    rerender |= ImGui::Checkbox("reflection", &s_.shading.reflections);
    ImGui::SameLine();
    rerender |= ImGui::Checkbox("refraction", &s_.shading.refractions);
    rerender |= ImGui::SliderInt("bounces", &s_.shading.bounces, 0, 10);
    ImGui::End();

    if (rebuild) {
        ImGui::MarkIniSettingsDirty();
        requestBuild(false, "subdivision parameter");
    }
    if (rerender) {
        ImGui::MarkIniSettingsDirty();
        markRender("shading parameter");
    }
}

void ViewerApp::cameraPanel() {
    ImGui::SetNextWindowPos(ImVec2(8, 468), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(330, 215), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Camera", &s_.showCamera)) {
        ImGui::End();
        return;
    }
    Camera c = camera_;
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
    if (changed && c.validate().empty()) setCamera(c);
    if (ImGui::Button("Reset (R)")) setCamera(home_);
    ImGui::SameLine();
    if (ImGui::Button("Copy JSON")) copyCameraJson();
    ImGui::SameLine();
    if (ImGui::Button("Paste JSON")) pasteCameraJson();
    if (!cameraError_.empty()) {
        ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1.0f, 0.45f, 0.45f, 1.0f));
        ImGui::TextWrapped("%s", cameraError_.c_str());
        ImGui::PopStyleColor();
    }
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped(
        "Left drag: orbit. Middle drag: pan. Right drag or wheel: zoom. R: reset. O: "
        "perspective/orthographic.");
    ImGui::PopStyleColor();
    ImGui::End();
}

void ViewerApp::statisticsPanel() {
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - 348, 28), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 265), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Statistics", &s_.showStatistics)) {
        ImGui::End();
        return;
    }
    ImGui::Text("%d x %d, %d threads, %.0f fps", jobWidth_, jobHeight_,
                effectiveThreads(s_.threads), io.Framerate);
    std::vector<PassRecord> passes = renderer_.passes();
    RayCounters total;
    double renderMs = 0.0;
    if (ImGui::BeginTable("passes", 4,
                          ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
        ImGui::TableSetupColumn("pass");
        ImGui::TableSetupColumn("render ms");
        ImGui::TableSetupColumn("since change");
        ImGui::TableSetupColumn("rays");
        ImGui::TableHeadersRow();
        for (const PassRecord& p : passes) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::Text("1/%d", p.stride * p.stride);
            ImGui::TableNextColumn();
            ImGui::Text("%.1f", p.renderMs);
            ImGui::TableNextColumn();
            ImGui::Text("%.1f", p.sinceStartMs);
            ImGui::TableNextColumn();
            ImGui::Text("%llu", (unsigned long long)p.counters.rays);
            total += p.counters;
            renderMs += p.renderMs;
        }
        ImGui::EndTable();
    }
    if (!renderer_.finished()) {
        size_t done = 0, count = 0;
        renderer_.progress(done, count);
        ImGui::ProgressBar(count ? float(done) / float(count) : 0.0f, ImVec2(-1, 0),
                           "rendering next pass");
    }
    if (total.rays) {
        const double rays = double(total.rays);
        ImGui::Text("rays %llu (%llu primary, %llu shadow)", (unsigned long long)total.rays,
                    (unsigned long long)total.primaryRays, (unsigned long long)total.shadowRays);
        ImGui::Text("%.3f Mrays/s", renderMs > 0 ? rays / renderMs / 1000.0 : 0.0);
        ImGui::Text("prim tests / ray    %.2f", double(total.primTests) / rays);
        ImGui::Text("region visits / ray %.2f", double(total.regionVisits) / rays);
        const double asked = double(total.primTests + total.mailboxHits);
        ImGui::Text("mailbox hit rate    %.1f %%",
                    asked > 0 ? 100.0 * double(total.mailboxHits) / asked : 0.0);
        if (total.shadowRays)
            ImGui::Text("shadow rays with no walk %.1f %% (light buffer)",
                        100.0 * double(total.lightBufferSkips) / double(total.shadowRays));
        if (total.walkErrors)
            ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "walk errors %llu",
                               (unsigned long long)total.walkErrors);
    }

    ImGui::Separator();
    static const char* strides[] = {"every pixel", "1 in 4", "1 in 16", "1 in 64"};
    int si = speedupStride_ == 1 ? 0 : speedupStride_ == 2 ? 1 : speedupStride_ == 4 ? 2 : 3;
    ImGui::SetNextItemWidth(110);
    if (ImGui::Combo("##sample", &si, strides, 4)) speedupStride_ = 1 << si;
    ImGui::SameLine();
    const bool running = speedup_ && !speedup_->done;
    if (running) {
        ImGui::TextUnformatted("measuring...");
    } else if (ImGui::Button("Speedup over brute force") && structure_) {
        startSpeedup();
    }
    if (speedup_ && speedup_->done) {
        const SpeedupResult& r = speedup_->result;
        if (!r.error.empty())
            ImGui::TextWrapped("%s", r.error.c_str());
        else
            ImGui::TextWrapped(
                "%s %.1f ms, brute %.1f ms on %zu pixels: speedup x%.2f; primitive tests per "
                "ray %.1f against %.1f",
                r.scheme.c_str(), r.schemeMs, r.bruteMs, r.pixels,
                r.schemeMs > 0 ? r.bruteMs / r.schemeMs : 0.0,
                r.schemeRays ? double(r.schemeTests) / double(r.schemeRays) : 0.0,
                r.bruteRays ? double(r.bruteTests) / double(r.bruteRays) : 0.0);
    }
    ImGui::End();
}

void ViewerApp::measureSpeedup(int stride) {
    if (!structure_) return;
    speedupStride_ = stride;
    startSpeedup();
}

std::optional<ViewerApp::SpeedupResult> ViewerApp::speedupResult() const {
    if (!speedup_ || !speedup_->done) return std::nullopt;
    return speedup_->result;
}

void ViewerApp::startSpeedup() {
    if (speedupThread_.joinable()) speedupThread_.join();
    auto sp = std::make_shared<Speedup>();
    sp->stride = speedupStride_;
    sp->result.scheme = schemeName(structure_->accel->params().scheme);
    speedup_ = sp;
    RenderOptions opt;
    opt.width = jobWidth_;
    opt.height = jobHeight_;
    opt.threads = s_.threads;
    opt.shading = s_.shading;
    opt.camera = camera_;
    std::shared_ptr<const Structure> st = structure_;
    // Both timed on the same pixels, one after the other, on the current view.
    speedupThread_ = std::thread([sp, st, opt] {
        lowerThreadPriority();
        try {
            PassLattice lattice{sp->stride, 0};
            Image img(opt.width, opt.height);
            for (int y = 0; y < opt.height; y += sp->stride)
                for (int x = 0; x < opt.width; x += sp->stride) ++sp->result.pixels;
            RenderStats a = render(*st->scene, *st->accel, opt, img, lattice, &sp->cancel);
            BuildParams bp = st->accel->params();
            bp.scheme = SchemeKind::Brute;
            auto brute = buildAccelerator(*st->scene, bp);
            RenderStats b = render(*st->scene, *brute, opt, img, lattice, &sp->cancel);
            SpeedupResult& r = sp->result;
            if (a.cancelled || b.cancelled) r.error = "cancelled: the view changed";
            r.schemeMs = a.renderMs;
            r.bruteMs = b.renderMs;
            r.schemeRays = a.counters.rays;
            r.bruteRays = b.counters.rays;
            r.schemeTests = a.counters.primTests;
            r.bruteTests = b.counters.primTests;
        } catch (const std::exception& e) {
            sp->result.error = e.what();
        }
        sp->done = true;
    });
}

void ViewerApp::viewPanel() {
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x - 348, 301), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(340, 175), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("View", &s_.showView)) {
        ImGui::End();
        return;
    }
    int mode = int(s_.mode);
    for (int i = 0; i < kViewModeCount; ++i) {
        if (i) ImGui::SameLine();
        ImGui::RadioButton(i == 0   ? "colour"
                           : i == 1 ? "prim tests"
                           : i == 2 ? "regions"
                                    : "time",
                           &mode, i);
    }
    if (mode != int(s_.mode)) {
        setViewMode(ViewMode(mode));
        ImGui::MarkIniSettingsDirty();
        if (s_.mode != ViewMode::Color && s_.autoScale) scale_ = autoScale_;
    }
    if (s_.mode != ViewMode::Color) {
        if (ImGui::Checkbox("auto scale", &s_.autoScale)) ImGui::MarkIniSettingsDirty();
        ImGui::SameLine();
        if (s_.autoScale) s_.heatScale = scale_;
        if (ImGui::SliderFloat("##scale", &s_.heatScale, 1.0f, 1e6f, "%.0f",
                               ImGuiSliderFlags_Logarithmic)) {
            s_.autoScale = false;
            ImGui::MarkIniSettingsDirty();
        }
        // The colour bar: the stops of the shader's map, value 0 on the left, the scale on the
        // right.
        ImVec2 p = ImGui::GetCursorScreenPos();
        const float w = ImGui::GetContentRegionAvail().x, h = 16.0f;
        const auto& stops = colormapStops();
        ImDrawList* dl = ImGui::GetWindowDrawList();
        const int segs = int(stops.size()) - 1;
        for (int i = 0; i < segs; ++i) {
            auto col = [](const glm::vec3& c) {
                return ImGui::ColorConvertFloat4ToU32(ImVec4(c.x, c.y, c.z, 1.0f));
            };
            float x0 = p.x + w * float(i) / float(segs), x1 = p.x + w * float(i + 1) / float(segs);
            dl->AddRectFilledMultiColor(ImVec2(x0, p.y), ImVec2(x1, p.y + h), col(stops[size_t(i)]),
                                        col(stops[size_t(i) + 1]), col(stops[size_t(i) + 1]),
                                        col(stops[size_t(i)]));
        }
        ImGui::Dummy(ImVec2(w, h));
        ImGui::Text("0");
        char right[32];
        std::snprintf(right, sizeof right, "%.6g %s", double(scale_),
                      s_.mode == ViewMode::TimeUs ? "us" : "");
        ImGui::SameLine(std::max(0.0f, w - ImGui::CalcTextSize(right).x));
        ImGui::TextUnformatted(right);
    }
    // The pixel under the cursor, from the same per-pixel counters as --stats.
    if (!io.WantCaptureMouse && shown_.width > 0) {
        int x = int(io.MousePos.x * io.DisplayFramebufferScale.x),
            y = int(io.MousePos.y * io.DisplayFramebufferScale.y);
        if (x >= 0 && y >= 0 && x < shown_.width && y < shown_.height) {
            size_t i = shown_.index(x, y);
            ImGui::Text("pixel %d %d: %u prim tests, %u regions, %.1f us", x, y,
                        shown_.primTests[i], shown_.regionVisits[i], double(shown_.timeUs[i]));
        }
    }
    ImGui::Separator();
    inspector_->controls();
    if (inspector_->shown() && selected_ >= 0)
        ImGui::Text("selected region %lld", (long long)selected_);
    ImGui::Separator();
    if (ImGui::Button("Screenshot")) {
        std::string path = "lancer-screenshot-" + std::to_string(++screenshotCount_) + ".png";
        pendingScreenshot_ = path;  // taken once this frame is drawn
    }
    if (!screenshotNote_.empty()) ImGui::TextWrapped("%s", screenshotNote_.c_str());
    ImGui::End();
}

}  // namespace lancer::viewer
