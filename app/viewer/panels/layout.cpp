#include "app/viewer/panels/layout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace lancer::viewer {

namespace {

constexpr float kMargin = 8.0f, kGap = 8.0f;
/// A column's width: a quarter of the window or so, within what the panels' controls need.
constexpr float kColumnMin = 290.0f, kColumnMax = 340.0f;
/// The image keeps at least this width between two columns, else the second column's panels
/// join the first.
constexpr float kMinImageWidth = 260.0f;

/// Which column a panel goes to when there are two: the parameters on the left, the view and
/// statistics on the right, the others where there is more room. The room is counted with
/// these typical heights, not with what the contents ask for frame by frame, so a panel moves
/// only when a panel opens, closes or folds, never as a table grows.
enum class Side : uint8_t { Left, Right, Roomier };
constexpr Side kSide[kPanelCount] = {Side::Left,    Side::Right,   Side::Right,   Side::Roomier,
                                     Side::Roomier, Side::Roomier, Side::Roomier, Side::Roomier};
constexpr float kTypical[kPanelCount] = {640, 110, 300, 180, 240, 320, 420, 400};

/// Stack `ids` (open panels, top to bottom) in column `col`; each gets its wanted height while
/// all fit, else the tallest share what is left at a common height (water filling).
void stack(const std::vector<PanelId>& ids, const Rect& col, const LayoutInput& in,
           PanelLayout& out) {
    if (ids.empty()) return;
    const float title = in.titleHeight;
    std::vector<float> h(ids.size());
    float room = col.height() - kGap * float(ids.size() - 1);
    std::vector<size_t> growing;
    for (size_t i = 0; i < ids.size(); ++i) {
        const PanelRequest& p = in.panels[size_t(ids[i])];
        if (p.collapsed) {
            h[i] = title;
            room -= title;
        } else {
            growing.push_back(i);
        }
    }
    // The common height L: every expanded panel gets min(want, L), all of them filling `room`.
    std::sort(growing.begin(), growing.end(), [&](size_t a, size_t b) {
        return in.panels[size_t(ids[a])].want < in.panels[size_t(ids[b])].want;
    });
    float left = std::max(room, 0.0f);
    for (size_t k = 0; k < growing.size(); ++k) {
        const float want = std::max(in.panels[size_t(ids[growing[k]])].want, title);
        const float share = std::floor(left / float(growing.size() - k));
        h[growing[k]] = std::max(title, std::min(want, share));
        left -= h[growing[k]];
    }
    float y = col.y0;
    for (size_t i = 0; i < ids.size(); ++i) {
        // A window too small for every title bar: the last ones stay inside it, overlapping.
        const float y0 = std::min(y, std::max(col.y0, col.y1 - h[i]));
        out.panels[size_t(ids[i])] = {col.x0, y0, col.x1, std::min(col.y1, y0 + h[i])};
        y = y0 + h[i] + kGap;
    }
}

}  // namespace

const char* panelTitle(PanelId id) {
    static const char* titles[kPanelCount] = {"Parameters", "View",      "Statistics", "Camera",
                                              "Overlays",   "Inspector", "Selection",  "Ray"};
    return titles[size_t(id)];
}

std::string Rect::toString() const {
    char buf[96];
    std::snprintf(buf, sizeof buf, "[%g, %g) x [%g, %g)", x0, x1, y0, y1);
    return buf;
}

PanelLayout layoutPanels(const LayoutInput& in) {
    PanelLayout out;
    const float w = std::max(in.width, 1.0f), h = std::max(in.height, 1.0f);
    float imageTop = 0.0f, imageLeft = 0.0f, imageRight = w;
    if (!in.panelsHidden) {
        imageTop = std::min(kMenuBarHeight, h);
        const float colW = std::max(
            0.0f, std::min(std::clamp(0.27f * w, kColumnMin, kColumnMax), w - 2 * kMargin));
        out.twoColumns = !in.inspector && w - 2.0f * (colW + 2.0f * kMargin) >= kMinImageWidth;
        const float top = imageTop, bottom = std::max(top, h - kMargin);
        std::vector<PanelId> left, right;
        float leftUsed = 0.0f, rightUsed = 0.0f;
        for (int i = 0; i < kPanelCount; ++i) {
            const PanelRequest& p = in.panels[size_t(i)];
            if (!p.open) continue;
            const Side side = kSide[i] == Side::Roomier
                                  ? (rightUsed < leftUsed ? Side::Right : Side::Left)
                                  : kSide[i];
            const bool toRight = out.twoColumns && side == Side::Right;
            (toRight ? right : left).push_back(PanelId(i));
            (toRight ? rightUsed : leftUsed) += (p.collapsed ? in.titleHeight : kTypical[i]) + kGap;
        }
        stack(left, {kMargin, top, kMargin + colW, bottom}, in, out);
        stack(right, {w - kMargin - colW, top, w - kMargin, bottom}, in, out);
        if (!left.empty()) imageLeft = std::min(w, 2.0f * kMargin + colW);
        if (!right.empty()) imageRight = std::max(imageLeft, w - 2.0f * kMargin - colW);
    }
    out.image = {imageLeft, imageTop, imageRight, h};
    if (in.inspector) {
        // The inspector's view takes the right half of what the panels leave, to the edge.
        const float mid = std::floor(imageLeft + 0.5f * (w - imageLeft));
        out.image.x1 = mid;
        out.inspector = {mid, imageTop, w, h};
    }
    return out;
}

}  // namespace lancer::viewer
