// ImGui's panels drawn from a layer: every top-level window (with its child windows) is
// rasterized into one framebuffer-sized texture only when its draw lists changed, and its
// rectangle is copied from there to the framebuffer every frame. Under software GL (llvmpipe)
// rasterizing the panels cost 8-11 ms a frame; copying a panel that did not change costs a
// third of drawing it. The panels are drawn into the layer exactly as ImGui would draw them on
// the framebuffer (same projection, same pixels), so they must be opaque (ViewerApp makes them
// so): a panel's rectangle replaces the pixels under it. At a framebuffer scale other than 1,
// or with rounded windows, the panels are drawn directly.
#pragma once

#include <imgui.h>

#include <cstdint>
#include <unordered_map>
#include <vector>

namespace lancer::viewer {

class PanelCache {
  public:
    PanelCache() = default;
    ~PanelCache();
    PanelCache(const PanelCache&) = delete;
    PanelCache& operator=(const PanelCache&) = delete;

    /// Draw `dd` (ImGui::GetDrawData(), after ImGui::Render()) into framebuffer 0 of
    /// fbWidth x fbHeight pixels, as ImGui_ImplOpenGL3_RenderDrawData does. Draw lists that
    /// belong to no window (the foreground and background lists) are drawn directly.
    void render(ImDrawData* dd, int fbWidth, int fbHeight);
    /// Panels rasterized again by the last render() (for tests and timings).
    int redrawn() const { return redrawn_; }

  private:
    struct Panel {
        unsigned id = 0;
        uint64_t hash = 0;
        int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  ///< framebuffer pixels, row 0 at the top
    };
    std::vector<Panel> last_;  ///< last frame's panels, bottom to top
    unsigned tex_ = 0, fbo_ = 0;
    int w_ = 0, h_ = 0;
    int redrawn_ = 0;
};

}  // namespace lancer::viewer
