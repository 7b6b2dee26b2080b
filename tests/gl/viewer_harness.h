// The whole viewer in an OSMesa context, driven as a user drives it: frames until the render is
// complete, keys pressed and characters typed through ImGui's io as a platform backend fills it.
#pragma once

#include <gtest/gtest.h>
#include <imgui.h>
#include <imgui_impl_opengl3.h>

#include <chrono>
#include <memory>
#include <thread>

#include "app/viewer/viewer_app.h"
#include "tests/gl/offscreen_gl.h"

namespace lancer::viewer::testing {

class ViewerHarness {
  public:
    /// A w x h window's viewer with `settings` (kept here: the ini handler's settings).
    ViewerHarness(int w, int h, const ViewerSettings& settings) : w_(w), h_(h), s_(settings) {
        gl_ = std::make_unique<OffscreenGl>(w, h);
        if (!gl_->ok()) return;
        ImGui::CreateContext();
        ImGuiIO& io = ImGui::GetIO();
        io.IniFilename = nullptr;
        io.DisplaySize = ImVec2(float(w), float(h));
        // Key indices as a platform backend maps them (any distinct indices below 512 do).
        for (int k = 0; k < ImGuiKey_COUNT; ++k) io.KeyMap[k] = 256 + k;
        ImGui_ImplOpenGL3_Init("#version 330 core");
        app_ = std::make_unique<ViewerApp>(s_, false);
    }
    ~ViewerHarness() {
        if (!app_) return;
        app_.reset();
        ImGui_ImplOpenGL3_Shutdown();
        ImGui::DestroyContext();
    }
    ViewerHarness(const ViewerHarness&) = delete;
    ViewerHarness& operator=(const ViewerHarness&) = delete;

    bool ok() const { return app_ != nullptr; }
    ViewerApp& app() { return *app_; }
    const OffscreenGl& gl() const { return *gl_; }
    int width() const { return w_; }
    int height() const { return h_; }

    /// One frame of 1/60 s.
    void frame() {
        ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
        app_->frame(w_, h_);
    }
    /// Frames until everything asked for is built and drawn (at least 5; at most 120 s, so a
    /// bug fails instead of hanging). False on time-out.
    bool runUntilSettled() {
        int frames = 0;
        const auto start = std::chrono::steady_clock::now();
        do {
            frame();
            ++frames;
            if (!app_->settled()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
        } while ((!app_->settled() || frames < 5) &&
                 std::chrono::steady_clock::now() - start < std::chrono::seconds(120));
        return app_->settled();
    }
    /// Key `k` pressed for one frame, then released for one.
    void press(ImGuiKey k) {
        ImGuiIO& io = ImGui::GetIO();
        io.KeysDown[io.KeyMap[k]] = true;
        frame();
        io.KeysDown[io.KeyMap[k]] = false;
        frame();
    }
    /// Character `c` typed (the F, R, O keys arrive as characters), the mouse at (x, y).
    void type(char c, float x, float y) {
        ImGuiIO& io = ImGui::GetIO();
        io.MousePos = ImVec2(x, y);
        io.AddInputCharacter(static_cast<unsigned>(c));
        frame();
    }

    /// A left click at (x, y): pressed for one frame, released for one.
    void click(float x, float y) {
        ImGuiIO& io = ImGui::GetIO();
        io.MousePos = ImVec2(x, y);
        frame();  // hovered first, as a real pointer is
        io.MouseDown[0] = true;
        frame();
        io.MouseDown[0] = false;
        frame();
    }

  private:
    int w_, h_;
    ViewerSettings s_;
    std::unique_ptr<OffscreenGl> gl_;
    std::unique_ptr<ViewerApp> app_;
};

}  // namespace lancer::viewer::testing
