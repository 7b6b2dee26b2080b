// ImGui's panels drawn from textures: each top-level window (with its child windows) is
// rasterized into a texture of its own only when its draw lists changed, and copied to the
// framebuffer every frame. Under software GL (llvmpipe) rasterizing the panels cost 8-11 ms a
// frame; copying a panel that did not change costs a third of drawing it. Needs the panels
// opaque (ViewerApp makes them so): a panel's texture replaces the pixels under it.
#pragma once

#include <imgui.h>

#include <cstdint>
#include <unordered_map>

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
    struct Entry {
        uint64_t hash = 0;
        unsigned tex = 0, fbo = 0;
        int x0 = 0, y0 = 0, w = 0, h = 0;  ///< the panel's rectangle, row 0 at the top
        bool used = false;
    };
    std::unordered_map<unsigned, Entry> entries_;  ///< by the root window's ImGuiID
    int redrawn_ = 0;
};

}  // namespace lancer::viewer
