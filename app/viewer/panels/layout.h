// Where the panels, the image and the inspector's view go in the window: a pure function of the
// window's size, the panels open and the heights their contents asked for last frame, so a test
// checks the layout without a window (layout_test.cpp) and the frame applies it (panels.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>

namespace lancer::viewer {

/// The viewer's panels, in the order a single column stacks them.
enum class PanelId : uint8_t {
    Parameters,
    View,
    Statistics,
    Camera,
    Overlays,
    Inspector,
    Selection,
    Tree,
    Ray,
};
inline constexpr int kPanelCount = 9;
/// Its window's title (ImGui's name for it).
const char* panelTitle(PanelId id);

/// A rectangle in display units (ImGui's coordinates: y down from the window's top).
struct Rect {
    float x0 = 0.0f, y0 = 0.0f, x1 = 0.0f, y1 = 0.0f;
    float width() const { return x1 - x0; }
    float height() const { return y1 - y0; }
    bool empty() const { return x1 <= x0 || y1 <= y0; }
    /// Both have some area in common (touching edges do not overlap).
    bool overlaps(const Rect& o) const {
        return !empty() && !o.empty() && x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1;
    }
    /// `o` lies wholly inside.
    bool contains(const Rect& o) const {
        return o.x0 >= x0 && o.x1 <= x1 && o.y0 >= y0 && o.y1 <= y1;
    }
    std::string toString() const;
};

/// What the layout knows of one panel.
struct PanelRequest {
    bool open = false;       ///< shown (its menu item is checked)
    bool collapsed = false;  ///< folded to its title bar
    float want = 240.0f;     ///< the height its content asked for, title bar included
};

struct LayoutInput {
    float width = 1280.0f, height = 720.0f;  ///< the window, in display units
    bool panelsHidden = false;               ///< Tab: the image (and inspector) alone
    bool inspector = false;                  ///< the 3D inspector's view is shown
    float titleHeight = 19.0f;               ///< a collapsed panel's height
    /// The columns' widths the user dragged them to (0: the automatic width, about a quarter
    /// of the window); clamped to what the window leaves the image.
    float leftWidth = 0.0f, rightWidth = 0.0f;
    /// With the inspector shown: the image's share of the width the columns leave.
    float imageShare = 0.5f;
    std::array<PanelRequest, kPanelCount> panels;
    PanelRequest& operator[](PanelId id) { return panels[size_t(id)]; }
};

struct PanelLayout {
    /// Each open panel's rectangle (empty for a closed one).
    std::array<Rect, kPanelCount> panels;
    /// The image viewport: the traced image is exactly this size (`lancer render` at this
    /// size traces the same rays) and no panel covers it.
    Rect image;
    /// The inspector's view (empty when it is not shown), beside the image.
    Rect inspector;
    /// The drag handles: a column's inner edge (between it and the image) and the split
    /// between the image and the inspector; empty where there is none.
    Rect leftHandle, rightHandle, splitHandle;
    float leftWidth = 0.0f, rightWidth = 0.0f;  ///< the columns' widths in use (0: none)
    bool twoColumns = false;  ///< a column of panels on each side, else one on the left
    const Rect& operator[](PanelId id) const { return panels[size_t(id)]; }
};

/// The height the Ray panel, then the Selection panel, get before the others when a column's
/// panels do not fit: the Ray panel's pixel, counts, transport and 8 lines of its step list at
/// 1280x720, room permitting.
inline constexpr float kUsablePanelHeight = 380.0f;

/// The menu bar's height the panels stay under.
inline constexpr float kMenuBarHeight = 28.0f;
/// The narrowest column a drag leaves (the panels' labels need about this much).
inline constexpr float kColumnMinWidth = 250.0f;
/// The width of a drag handle: the gap between a column and the image, or between the image
/// and the inspector.
inline constexpr float kHandleWidth = 8.0f;
/// The least width or height the image (and the inspector) keep when a handle is dragged.
inline constexpr float kMinViewportSide = 160.0f;

/// Polyscope's arrangement, docked: the panels stack in a column on the left and, when the
/// window is wide enough, a second on the right (the parameters on the left, the view and
/// statistics on the right, the others in the column with more room); the image viewport is
/// what they leave, each column's inner edge a drag handle. With the inspector shown, the
/// inspector takes the viewport's right part (imageShare, with a handle between), and a second
/// column (the Inspector, Selection and Ray panels) stands right of it only when one column
/// cannot hold the open panels and the image and the inspector keep 400 units each. A column's
/// panels share its height: each gets what its content asks for while they all fit; else each
/// keeps a title bar and two lines (only its title bar when that would leave the Ray panel less
/// than kUsablePanelHeight), the Ray panel then the Selection panel grow to
/// kUsablePanelHeight, the others are cut down to a common height and scroll, and what they
/// leave goes to the Selection panel, then the Ray panel. A folded panel takes its title bar.
/// Nothing overlaps, and everything stays inside the window at any size.
PanelLayout layoutPanels(const LayoutInput& in);

/// The window size whose layout (`in`, its width and height ignored) gives an image viewport
/// of imageWidth x imageHeight display units: what `--width`/`--height` open the window at.
/// The layout's rules depend on the window's width, so this converges by a few fixed-point
/// steps; the result is exact unless the image would be below its minimum.
std::pair<float, float> windowForImage(LayoutInput in, float imageWidth, float imageHeight);

}  // namespace lancer::viewer
