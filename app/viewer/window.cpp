#include "app/viewer/window.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <numbers>
#include <optional>
#include <thread>
#include <vector>

#include "app/viewer/camera_control.h"
#include "app/viewer/panels/panels.h"
#include "app/viewer/timing/frame_times.h"
#include "app/viewer/viewer_app.h"

namespace lancer::viewer {

namespace {

/// While a render only refines the image and nobody interacts: frames per second at most.
/// Measured on balls4 at 1280x720 under Xvfb: the UI drew 15 frames a second while rendering
/// (one per band and a 10 Hz progress tick), 6.7 at this pace.
constexpr double kRefineHz = 5.0;

std::string defaultIniPath() {
    namespace fs = std::filesystem;
    fs::path dir;
    if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x)
        dir = fs::path(x) / "lancer";
    else if (const char* h = std::getenv("HOME"); h && *h)
        dir = fs::path(h) / ".config" / "lancer";
    else
        return "lancer-imgui.ini";
    std::error_code ec;
    fs::create_directories(dir, ec);
    return (dir / "imgui.ini").string();
}

/// Settings explicitly given on the command line win over those saved in the ini: every entry
/// of the parameter table that reaches the viewer.
void applyCommandLine(const cli::CommonOptions& o,
                      const std::function<bool(const std::string&)>& given, ViewerSettings& s) {
    if (given("scene")) s.scene = o.scene;
    cli::Knobs k = knobsOf(s);
    for (const cli::ParamDesc& d : cli::paramTable())
        if (d.reach != cli::ViewerReach::BatchOnly && given(d.flag)) cli::copyValue(d, o.knobs, k);
    setKnobs(s, k);
}

}  // namespace

int runViewer(const cli::CommonOptions& o, const ViewOptions& v,
              const std::function<bool(const std::string&)>& given, std::string& why) {
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if (!(display && *display) && !(wayland && *wayland)) {
        why = "no display (DISPLAY is not set)";
        return kNoDisplay;
    }
    // Under Mesa's software rasterizer (llvmpipe: no GPU, a VM, Xvfb), draw on the UI thread:
    // with llvmpipe's worker threads, ThreadSanitizer finds a frame destroying a fence's mutex
    // while a worker still signals it (tests/gl/CMakeLists.txt). The render's own threads are
    // the ones that matter for speed; other drivers ignore the variable. A value the user set
    // stays.
    setenv("LP_NUM_THREADS", "0", 0);
    glfwSetErrorCallback(
        [](int code, const char* text) { std::cerr << "glfw: " << text << " (" << code << ")\n"; });
    if (!glfwInit()) {
        why = "no display (GLFW could not initialise)";
        return kNoDisplay;
    }

    // Settings: defaults, then the ini, then the command line.
    ViewerSettings settings;
    ImGui::CreateContext();
    ImGuiIO& io = ImGui::GetIO();
    registerSettingsHandler(&settings);
    // A scripted run (--frames) neither reads nor writes the user's settings unless told to.
    std::string ini = v.ini.empty() ? (v.frames > 0 ? "none" : defaultIniPath()) : v.ini;
    if (ini == "none") {
        io.IniFilename = nullptr;
    } else {
        io.IniFilename = ini.c_str();
        ImGui::LoadIniSettingsFromDisk(ini.c_str());
    }
    applyCommandLine(o, given, settings);
    // A layer the scheme (from the command line or the ini) does not have: refused by name.
    if (std::string bad = overlay::showListMismatch(v.show, settings.build.scheme); !bad.empty()) {
        std::cerr << "error: " << bad << "\n";
        io.IniFilename = nullptr;  // nothing changed: the settings file stays as it is
        ImGui::DestroyContext();
        glfwTerminate();
        return 2;
    }
    if (std::optional<ViewMode> m = viewModeOf(v.view)) settings.mode = *m;
    if (v.select >= 0) settings.showSelection = true;
    if (given("--width") || given("--height")) {
        // --width and --height are the image's size: the window opens at that size plus the
        // panels that open with it (the inspector and the Ray panel as --show and --pick
        // open them), so the image viewport is exactly W x H.
        ViewerSettings opening = settings;
        for (size_t b = 0; b <= v.show.size();) {
            const size_t e = std::min(v.show.find(',', b), v.show.size());
            if (v.show.compare(b, e - b, "inspector") == 0) opening.showInspector = true;
            b = e + 1;
        }
        if (v.pick.size() == 2) opening.showRay = true;
        const auto [w, h] =
            windowForImage(layoutInputOf(opening, v.hidePanels, PanelHeights{}, 0.0f, 0.0f),
                           float(settings.windowWidth), float(settings.windowHeight));
        settings.windowWidth = int(w);
        settings.windowHeight = int(h);
    }

    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    GLFWwindow* window =
        glfwCreateWindow(settings.windowWidth, settings.windowHeight, "lancer", nullptr, nullptr);
    if (!window) {
        ImGui::DestroyContext();
        glfwTerminate();
        why = "no OpenGL 3.3 core window could be opened";
        return kNoDisplay;
    }
    glfwMakeContextCurrent(window);
    glfwSwapInterval(1);

    // Dropped files open as scenes; chained before ImGui installs its own callbacks.
    static std::vector<std::string> dropped;
    glfwSetDropCallback(window, [](GLFWwindow*, int count, const char** paths) {
        for (int i = 0; i < count; ++i) dropped.emplace_back(paths[i]);
    });
    // Any input since the last frame: then the next frame is drawn at once (ImGui's backend
    // chains to these; it installs no cursor callback of its own in 1.86).
    static bool input = false;
    glfwSetCursorPosCallback(window, [](GLFWwindow*, double, double) { input = true; });
    glfwSetMouseButtonCallback(window, [](GLFWwindow*, int, int, int) { input = true; });
    glfwSetScrollCallback(window, [](GLFWwindow*, double, double) { input = true; });
    glfwSetKeyCallback(window, [](GLFWwindow*, int, int, int, int) { input = true; });
    glfwSetCharCallback(window, [](GLFWwindow*, unsigned) { input = true; });
    glfwSetWindowSizeCallback(window, [](GLFWwindow*, int, int) { input = true; });
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");

    int status = 0;
    try {
        // Worker threads wake the loop when a band, pass or structure is ready: through the
        // condition variable if it is pacing frames, else through GLFW's event queue.
        std::mutex wakeMutex;
        std::condition_variable wakeCv;
        bool woken = false;
        ViewerApp app(settings, v.logTimings, [&] {
            {
                std::lock_guard lock(wakeMutex);
                woken = true;
            }
            wakeCv.notify_one();
            glfwPostEmptyEvent();  // thread-safe in GLFW
        });
        app.state().setPanelsHidden(v.hidePanels);
        if (!v.show.empty()) {
            // Every item names something drawn: an item no view draws is refused, not ignored.
            std::vector<std::string> notDrawn = app.applyShow(v.show);
            if (!notDrawn.empty()) {
                std::string names;
                for (const std::string& n : notDrawn) names += (names.empty() ? "" : ", ") + n;
                throw std::invalid_argument("--show: not drawn by this viewer yet: " + names);
            }
        }
        if (v.select >= 0) app.overlays().select(uint32_t(v.select));
        if (std::optional<compare::AbView> ab = compare::abViewOf(v.ab)) app.setAbView(*ab);
        if (v.pick.size() == 2) app.pickPixel(v.pick[0], v.pick[1], v.pickRay, v.pickStep);
        using Clock = std::chrono::steady_clock;
        int frames = 0, statFrames = 0;
        bool replayed = false, droppedScripted = false, changedScripted = false;
        double statWorkMs = 0.0, statSwapMs = 0.0;
        Clock::time_point frameStart = Clock::now(), statStart = frameStart, lastDrawn = frameStart;
        // When the next frame may start: frames are paced on a fixed 60 Hz timeline, so a wait
        // that oversleeps is made up by the next one (paced from each frame's own start, 15 ms
        // frames came at 55-57 a second).
        const auto period =
            std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / 60.0));
        Clock::time_point due = frameStart;
        // --log-timings: each frame's work once the structure is ready, and --orbit's turns.
        FrameTimes turningFrames, stillFrames;
        int turned = 0;
        while (!glfwWindowShouldClose(window)) {
            const bool turnDue = v.orbit != 0.0 && app.sceneBuild() && turned < v.frames;
            // At most 60 frames per second for input (no swap interval is guaranteed, e.g.
            // under Xvfb); a worker's result ends the wait at once, so a new pass or structure
            // is shown (or a render started on it) without waiting out the frame.
            if (due > Clock::now()) {
                std::unique_lock lock(wakeMutex);
                wakeCv.wait_until(lock, due, [&] { return woken; });
            }
            {
                std::lock_guard lock(wakeMutex);
                woken = false;
            }
            // Interactive: draw on input at once; on a new structure, the first pass of a
            // change or each finer pass at once too (the workers post an empty event); idle once
            // settled. While a render only refines a pass band by band and nobody interacts, its
            // bands (and the progress bar) are shown at most kRefineHz times a second: each
            // frame drawn takes CPU from the render threads. A scripted run (--frames) counts
            // its frames quickly once the image is complete.
            if (v.continuous || turnDue || (v.frames > 0 && app.settled())) {
                glfwPollEvents();
            } else if (app.settled()) {
                glfwWaitEventsTimeout(1.0);
            } else {
                const auto due = lastDrawn + std::chrono::duration<double>(1.0 / kRefineHz);
                glfwWaitEventsTimeout(1.0 / kRefineHz);
                for (auto now = Clock::now(); now < due && !input && !app.eager();
                     now = Clock::now())
                    glfwWaitEventsTimeout(std::chrono::duration<double>(due - now).count());
            }
            input = false;
            frameStart = Clock::now();
            const double frameCpuStart = threadCpuMs();
            due += period;
            if (due < frameStart) due = frameStart + period;  // behind (or idle): start afresh
            if (!dropped.empty()) {
                app.openScene(dropped.back());
                dropped.clear();
            }
            int fbw = 0, fbh = 0, ww = 0, wh = 0;
            glfwGetFramebufferSize(window, &fbw, &fbh);
            glfwGetWindowSize(window, &ww, &wh);
            if (ww > 0 && wh > 0 && (ww != settings.windowWidth || wh != settings.windowHeight)) {
                settings.windowWidth = ww;
                settings.windowHeight = wh;
                ImGui::MarkIniSettingsDirty();
            }
            if (turnDue) {  // about the target, as a drag to the side does (input.cpp)
                Camera c = app.state().camera();
                orbit(c, v.orbit * std::numbers::pi / 180.0, 0.0);
                app.state().setCamera(c);
                ++turned;
            }
            app.setCameraTurning(turnDue);
            ImGui_ImplGlfw_NewFrame();
            app.frame(fbw, fbh);
            ++frames;
            if (const std::string& refused = app.state().startRefusal(); !refused.empty()) {
                // No fallback image: the options the run was started with are wrong.
                std::cerr << "error: lancer view: the structure was refused: " << refused << "\n";
                status = 2;
                break;
            }
            if (v.replayChange && !replayed && app.settled() && app.sceneBuild()) {
                app.rebuild("replayed parameter change");
                replayed = true;
            } else if (!v.change.empty() && !changedScripted && app.settled() && app.sceneBuild()) {
                // As the Parameters panel applies a change (parameters_panel.cpp).
                const cli::Knobs before = knobsOf(settings);
                cli::Knobs after = before;
                cli::applyAssignments(v.change, after);  // checked when parsed
                setKnobs(settings, after);
                const cli::ChangeEffect effect = cli::changeEffect(before, after);
                if (effect == cli::ChangeEffect::Rebuild)
                    app.state().requestBuild(false, "--change");
                else if (effect == cli::ChangeEffect::Rerender)
                    app.state().markRender("--change");
                changedScripted = true;
            } else if (!v.drop.empty() && !droppedScripted && app.settled() && app.sceneBuild()) {
                // Through the callback the window has installed, as a drop from the desktop.
                GLFWdropfun onDrop = glfwSetDropCallback(window, nullptr);
                glfwSetDropCallback(window, onDrop);
                const char* paths[] = {v.drop.c_str()};
                if (onDrop) onDrop(window, 1, paths);
                droppedScripted = true;
            } else if (v.frames > 0 && frames >= v.frames && app.settled() &&
                       (v.orbit == 0.0 || turned >= v.frames)) {
                if (!app.sceneBuild()) {  // a scripted run on a scene that cannot be shown fails
                    std::cerr << "error: lancer view: the scene could not be shown (see above)\n";
                    status = 2;
                } else if (v.select >= 0 && !app.overlays().selection()) {
                    const StructureView* sv = app.overlays().view();
                    std::cerr << "error: --select: no region " << v.select << " in the structure ("
                              << (sv ? sv->regionCount() : 0) << " regions)\n";
                    status = 2;
                }
                std::string played;  // "ray 0 at step 3 of 5": where the playback stopped
                if (v.pick.size() == 2 && app.rayPlayer().playback().empty()) {
                    std::cerr << "error: --pick: " << app.rayPlayer().note() << "\n";
                    status = 2;
                } else if (v.pick.size() == 2) {
                    const playback::RayPlayback& pb = app.rayPlayer().playback();
                    played = ", ray " + std::to_string(v.pickRay) + " at step " +
                             std::to_string(pb.state().step) + " of " +
                             std::to_string(pb.stepCount());
                }
                // A failed run writes no screenshot: a file there would pass for its result.
                if (!v.screenshot.empty() && status == 0) {
                    try {
                        app.saveScreenshot(v.screenshot, fbw, fbh);
                        // Where the image viewport is, so a script finds the render in it.
                        const PixelRect& ia = app.state().imageArea();
                        std::cout << "lancer view: " << frames << " frames, screenshot "
                                  << v.screenshot << played << ", image " << ia.x1 - ia.x0 << "x"
                                  << ia.y1 - ia.y0 << " at " << ia.x0 << "," << ia.y0 << "\n";
                    } catch (const std::exception& e) {
                        std::cerr << "error: --screenshot: " << e.what() << "\n";
                        status = 2;
                    }
                }
                glfwSwapBuffers(window);  // after the screenshot, which reads the back buffer
                app.presented();
                break;
            }
            auto beforeSwap = Clock::now();
            // The swap's own CPU apart: llvmpipe rasterizes there what was drawn since the
            // last finish (the inspector's and the panel layer's draws).
            const double swapCpuStart = threadCpuMs();
            glfwSwapBuffers(window);
            const double swapCpuMs = threadCpuMs() - swapCpuStart;
            app.presented();
            lastDrawn = Clock::now();
            statSwapMs +=
                std::chrono::duration<double, std::milli>(Clock::now() - beforeSwap).count();
            // The UI thread's own cost per frame (the render runs on other threads).
            const double workMs =
                std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count();
            statWorkMs += workMs;
            if (app.sceneBuild()) {
                const double cpuMs = threadCpuMs() - frameCpuStart;
                (turnDue ? turningFrames : stillFrames).add(workMs, cpuMs);
                // A frame over budget says where its time went.
                if (v.logTimings && cpuMs > kFrameBudgetMs)
                    std::fprintf(stderr,
                                 "timing: slow frame %d (%s): %.1f ms, %.1f ms of UI CPU: %s, "
                                 "swap %.1f, rest %.1f; %d panels redrawn, %d steps deferred; "
                                 "image: %d rows composited, %zu texels of layer changes, %d "
                                 "rows shown\n",
                                 frames, turnDue ? "turning" : "still", workMs, cpuMs,
                                 app.phases().summary().c_str(), swapCpuMs,
                                 cpuMs - app.phases().totalMs() - swapCpuMs, app.panelsRedrawn(),
                                 app.frameBudget().deferred(), app.imageShade().rows,
                                 app.imageShade().texels, app.imageShade().shownRows);
            }
            // A step let in over the budget (it had waited its patience) says why it waited.
            if (v.logTimings)
                for (const FrameBudget::Forced& f : app.frameBudget().forcedSteps())
                    std::fprintf(stderr,
                                 "timing: frame %d: %s let in over the budget after %u frames "
                                 "of waiting: %.1f ms estimated, %.1f ms left beyond its "
                                 "reserve of %.1f ms\n",
                                 frames, f.step, kPatienceFrames, f.estimateMs, f.leftMs,
                                 f.reserveMs);
            ++statFrames;
            if (v.logTimings && Clock::now() - statStart > std::chrono::seconds(2)) {
                double secs = std::chrono::duration<double>(Clock::now() - statStart).count();
                std::cerr << "timing: ui " << statFrames / secs << " fps, "
                          << statWorkMs / statFrames << " ms of work per frame ("
                          << statSwapMs / statFrames << " ms in the swap)\n";
                statFrames = 0;
                statWorkMs = statSwapMs = 0.0;
                statStart = Clock::now();
            }
        }
        if (v.logTimings)
            std::cerr << "timing: frames since the structure was ready: "
                      << turningFrames.summary("turning") << "; " << stillFrames.summary("still")
                      << "\n";
    } catch (const std::exception& e) {  // e.g. a shader the driver refuses
        std::cerr << "error: the viewer failed: " << e.what() << "\n";
        status = 2;
    }
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();  // writes the ini
    glfwDestroyWindow(window);
    glfwTerminate();
    return status;
}

}  // namespace lancer::viewer
