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

struct ImGuiWindow;  // imgui_internal.h

#include <cstdint>
#include <utility>
#include <vector>

#include "app/viewer/image_view.h"  // PixelRect
#include "app/viewer/timing/frame_budget.h"

namespace lancer::viewer {

class PanelCache {
  public:
    PanelCache() = default;
    ~PanelCache();
    PanelCache(const PanelCache&) = delete;
    PanelCache& operator=(const PanelCache&) = delete;

    /// Take the frame's draw data (ImGui::GetDrawData(), after ImGui::Render()) for framebuffer
    /// 0 of fbWidth x fbHeight pixels. Returns the rectangles render() will fill with opaque
    /// panels (none when it draws them directly): what lies under them need not be drawn.
    const std::vector<PixelRect>& layout(ImDrawData* dd, int fbWidth, int fbHeight);
    /// Draw the draw data given to layout(), as ImGui_ImplOpenGL3_RenderDrawData does. Draw
    /// lists that belong to no window (the foreground and background lists) are drawn directly.
    void render();
    /// Rasterize the panel of ImGui window `windowId` (ImGuiWindow::ID of a top-level window)
    /// again at the next render(), though its draw lists are the same: the layer knows a
    /// texture a panel shows by its id, not its pixels, so a panel showing a texture whose
    /// pixels changed must say so.
    void invalidate(unsigned windowId) { invalid_.push_back(windowId); }
    /// Panels rasterized again by the last render() (for tests and timings).
    int redrawn() const { return redrawn_; }
    /// Panels whose new content the last render() left for a later frame (the budget).
    int deferred() const { return deferred_; }
    /// Share a frame's budget from now on (null: none): a panel whose content changed (and
    /// nothing else: not moved, not uncovered, nothing redrawn under it) is rasterized again
    /// only when the learned cost of a redraw fits in the frame's budget less `reserveMs` and
    /// the learned cost of the copies; else the layer shows its last content until a later
    /// frame (kPatienceFrames frames at most: the next redraws it whatever the budget). The
    /// budget must outlive the cache or be unset.
    void setFrameBudget(FrameBudget* budget, double reserveMs) {
        budget_ = budget;
        budgetReserveMs_ = reserveMs;
    }
    /// What the next render() will take of the frame in any case, in ms, once layout() has
    /// the frame's panels: the learned cost of the panels it must draw again (new, moved,
    /// uncovered) and of the copies. The steps before it keep that much back: a new
    /// structure's first frame redraws five panels, 9-11 ms (balls4, 2026-12-06).
    double estimateMs() const;
    /// The learned cost of drawing a panel of `pixels` again, in ms.
    double redrawEstimateMs(double pixels) const { return redrawCost_.estimateMs(pixels); }
    /// The learned cost of a render() that draws no panel again (the copies), in ms.
    double copyEstimateMs() const { return copyCost_.estimateMs(1); }

  private:
    struct Panel {
        unsigned id = 0;
        uint64_t hash = 0;
        PixelRect rect;  ///< inside the framebuffer; empty when the window is off it
    };
    /// A run of the draw data: a panel's lists (a window and its children), or lists drawn
    /// directly (panel < 0: no window, or a window without a background).
    struct Run {
        const ImGuiWindow* window = nullptr;
        std::vector<ImDrawList*> lists;
        int panel = -1;
    };

    /// Why a panel is drawn again: its content changed (optional, under the budget), or the
    /// layer's pixels under it are stale (drawn in any case).
    enum Need : char { kNone, kContent, kMust };
    /// What render() draws again, by panel (bottom to top), before the budget.
    struct Plan {
        std::vector<char> need;      ///< a Need a panel
        std::vector<size_t> lastOf;  ///< the panel's index in last_ (SIZE_MAX: new)
    };
    Plan plan() const;

    // This frame, from layout().
    ImDrawData* dd_ = nullptr;
    int fbWidth_ = 0, fbHeight_ = 0;
    bool direct_ = true;
    std::vector<Run> runs_;
    std::vector<Panel> panels_;  ///< bottom to top
    std::vector<PixelRect> covered_;

    std::vector<Panel> last_;        ///< the last frame drawn through the layer
    std::vector<unsigned> invalid_;  ///< windows to rasterize again (invalidate())
    unsigned tex_ = 0, fbo_ = 0;
    int w_ = 0, h_ = 0;  ///< the layer's size
    int redrawn_ = 0;
    int deferred_ = 0;
    /// By window ID, the frames in a row a panel's new content waited for the budget (never
    /// starved: redrawn whatever the budget after kPatienceFrames); the frame's panels only.
    std::vector<std::pair<unsigned, Patience>> patience_;
    FrameBudget* budget_ = nullptr;  ///< setFrameBudget()
    double budgetReserveMs_ = 0.0;
    /// Learned (FrameBudget's clock): a panel drawn again, by its pixels (at first 1.5 ms for a
    /// panel of 100,000, as llvmpipe takes for the viewer's at 1280x720: a new structure's five
    /// took 9-11 ms, 2026-12-06), and a render()'s copies and direct lists (about 3 ms).
    StepCost redrawCost_{1.5e-5};
    StepCost copyCost_{3.0};
};

}  // namespace lancer::viewer
