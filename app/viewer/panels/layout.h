// Where the panels, the image and the inspector's view go in the window: a pure function of the
// window's size, the panels open and the heights their contents asked for last frame, so a test
// checks the layout without a window (layout_test.cpp) and the frame applies it (panels.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <string>

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
    Ray,
};
inline constexpr int kPanelCount = 8;
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
    std::array<PanelRequest, kPanelCount> panels;
    PanelRequest& operator[](PanelId id) { return panels[size_t(id)]; }
};

struct PanelLayout {
    /// Each open panel's rectangle (empty for a closed one).
    std::array<Rect, kPanelCount> panels;
    /// The part of the window the image is seen in, which no panel covers (the traced image
    /// spans the whole window, as `lancer render` traces it, and shows here).
    Rect image;
    /// The inspector's view (empty when it is not shown), beside the image.
    Rect inspector;
    bool twoColumns = false;  ///< a column of panels on each side, else one on the left
    const Rect& operator[](PanelId id) const { return panels[size_t(id)]; }
};

/// The height the Ray panel, then the Selection panel, get before the others when a column's
/// panels do not fit (the Ray panel's pixel, counts, rays and transport), room permitting.
inline constexpr float kUsablePanelHeight = 260.0f;

/// The menu bar's height the panels stay under.
inline constexpr float kMenuBarHeight = 28.0f;

/// Polyscope's arrangement: the panels stack in a column on the left and, when the window is
/// wide enough, a second on the right (the parameters on the left, the view and statistics on
/// the right, the others in the column with more room), so the image keeps the middle. With the
/// inspector shown, the inspector takes the right half of what the panels leave, and a second
/// column (the Inspector, Selection and Ray panels) stands right of it only when one column
/// cannot hold the open panels and the image and the inspector keep 400 units each. A column's
/// panels share its height: each gets what its content asks for while they all fit; else each
/// keeps a title bar and two lines, the Ray panel then the Selection panel grow to
/// kUsablePanelHeight, the others are cut down to a common height and scroll, and what they
/// leave goes to the Selection panel, then the Ray panel (whose step list fills what it is
/// given). A folded panel takes its title bar. Nothing overlaps, and everything stays inside the
/// window at any size.
PanelLayout layoutPanels(const LayoutInput& in);

}  // namespace lancer::viewer
