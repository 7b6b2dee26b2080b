#include "app/viewer/panels/layout.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

namespace lancer::viewer {

namespace {

constexpr float kMargin = 8.0f, kGap = 8.0f;
/// A column's width: a quarter of the window or so, within what the panels' controls need.
constexpr float kColumnMin = 290.0f, kColumnMax = 340.0f;
/// The image keeps at least this width between two columns, else the second column's panels
/// join the first.
constexpr float kMinImageWidth = 260.0f;
/// With the inspector shown, a second column only when the image and the inspector's view
/// each keep this width.
constexpr float kMinViewWidth = 400.0f;

/// Which column a panel goes to when there are two: the parameters on the left, the view and
/// statistics on the right, the others where there is more room. The room is counted with
/// these typical heights, not with what the contents ask for frame by frame, so a panel moves
/// only when a panel opens, closes or folds, never as a table grows.
enum class Side : uint8_t { Left, Right, Roomier };
constexpr Side kSide[kPanelCount] = {Side::Left,    Side::Right,   Side::Right,
                                     Side::Roomier, Side::Roomier, Side::Roomier,
                                     Side::Roomier, Side::Roomier, Side::Roomier};
/// With the inspector shown, the second column stands right of the inspector's view and holds
/// the panels about what the inspector shows: its own, the selection's, the ray's.
constexpr Side kSideBesideInspector[kPanelCount] = {Side::Left,  Side::Left,  Side::Left,
                                                    Side::Left,  Side::Left,  Side::Right,
                                                    Side::Right, Side::Right, Side::Right};
constexpr float kTypical[kPanelCount] = {640, 110, 300, 180, 240, 320, 420, 420, 400};

/// The panels a column cuts last: the Ray panel's step list and the Selection panel's lists
/// are what a user reads while the others are set once.
bool cutLast(PanelId id) { return id == PanelId::Ray || id == PanelId::Selection; }

/// Water filling: heights min(want, L) for a common L, filling `room` when the wants do not
/// fit; `floor` is the least height given.
void waterFill(const std::vector<float>& want, float room, float floor, std::vector<float>& h) {
    std::vector<size_t> order(want.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return want[a] < want[b]; });
    float left = std::max(room, 0.0f);
    h.assign(want.size(), 0.0f);
    for (size_t k = 0; k < order.size(); ++k) {
        const float share = std::floor(left / float(order.size() - k));
        // Whole units: the panels' edges add up exactly.
        h[order[k]] = std::max(floor, std::min(std::ceil(std::max(want[order[k]], floor)), share));
        left -= h[order[k]];
    }
}

/// Stack `ids` (open panels, top to bottom) in column `col`. A folded panel takes its title
/// bar. The expanded ones get what they ask for while all fit; else each keeps a title bar and
/// two lines, the Ray panel then the Selection panel grow to kUsablePanelHeight, the others
/// share what is left at a common height (water filling), and what they do not take goes to
/// the Selection panel then the Ray panel, which fills the column.
void stack(const std::vector<PanelId>& ids, const Rect& col, const LayoutInput& in,
           PanelLayout& out) {
    if (ids.empty()) return;
    const float title = in.titleHeight, keep = std::ceil(3.0f * title);
    std::vector<float> h(ids.size(), title);
    float room = col.height() - kGap * float(ids.size() - 1);
    std::vector<size_t> expanded, others;
    for (size_t i = 0; i < ids.size(); ++i) {
        if (in.panels[size_t(ids[i])].collapsed) {
            room -= title;
            continue;
        }
        expanded.push_back(i);
        if (!cutLast(ids[i])) others.push_back(i);
    }
    auto want = [&](size_t i) {
        return std::ceil(std::max(in.panels[size_t(ids[i])].want, title));
    };
    auto wantsOf = [&](const std::vector<size_t>& which) {
        std::vector<float> w;
        for (size_t i : which) w.push_back(want(i));
        return w;
    };
    // Each keeps a title bar and two lines; a column too short for that and a usable Ray
    // panel keeps the others to their title bar (a line cut in half reads worse than none), so
    // the step list stays readable; folding the Ray panel gives them their room back.
    float extra = room;
    for (size_t i : expanded) {
        h[i] = std::min(want(i), keep);
        extra -= h[i];
    }
    const bool ray = std::any_of(expanded.begin(), expanded.end(),
                                 [&](size_t i) { return ids[i] == PanelId::Ray; });
    if (ray && extra < kUsablePanelHeight - keep) {
        const float tight = title;
        for (size_t i : others) {
            const float t = std::min(want(i), tight);
            extra += h[i] - t;
            h[i] = t;
        }
        for (size_t i : expanded)  // the Selection panel too, if still short
            if (ids[i] == PanelId::Selection && extra < kUsablePanelHeight - keep) {
                const float t = std::min(want(i), tight);
                extra += h[i] - t;
                h[i] = t;
            }
    }
    std::vector<float> shared;
    if (extra < 0.0f) {
        // Not even a few lines each: all share the column alike.
        waterFill(wantsOf(expanded), room, title, shared);
        for (size_t k = 0; k < expanded.size(); ++k) h[expanded[k]] = shared[k];
    } else {
        // The Ray panel, then the Selection panel, up to a usable height.
        auto find = [&](PanelId id) -> std::optional<size_t> {
            for (size_t i : expanded)
                if (ids[i] == id) return i;
            return std::nullopt;
        };
        for (PanelId id : {PanelId::Ray, PanelId::Selection})
            if (const auto i = find(id)) {
                const float add =
                    std::clamp(std::min(want(*i), kUsablePanelHeight) - h[*i], 0.0f, extra);
                h[*i] += add;
                extra -= add;
            }
        // The others share theirs and the rest (each keeps at least what it had).
        float othersRoom = extra;
        for (size_t i : others) othersRoom += h[i];
        waterFill(wantsOf(others), othersRoom, title, shared);
        for (size_t k = 0; k < others.size(); ++k) {
            extra -= shared[k] - h[others[k]];
            h[others[k]] = shared[k];
        }
        // What they leave: the Selection panel to what it asks, the Ray panel the rest.
        for (PanelId id : {PanelId::Selection, PanelId::Ray})
            if (const auto i = find(id)) {
                const float add = std::clamp(want(*i) - h[*i], 0.0f, std::max(extra, 0.0f));
                h[*i] += add;
                extra -= add;
            }
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
    static const char* titles[kPanelCount] = {"Parameters", "View",           "Statistics",
                                              "Camera",     "Overlays",       "Inspector",
                                              "Selection",  "Structure tree", "Ray"};
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
        // A column is as wide as the user dragged it, else about a quarter of the window; never
        // so wide that two columns leave the image less than kMinViewportSide. Whole units, so
        // the image's pixels are whole too.
        const float autoWidth = std::clamp(0.27f * w, kColumnMin, kColumnMax);
        const float widest =
            std::max(kColumnMinWidth, 0.5f * (w - kMinViewportSide) - kMargin - kHandleWidth);
        auto columnWidth = [&](float asked) {
            const float c = std::clamp(asked > 0.0f ? asked : autoWidth, kColumnMinWidth, widest);
            return std::floor(std::max(0.0f, std::min(c, w - kMargin - kHandleWidth)));
        };
        const float leftW = columnWidth(in.leftWidth), rightW = columnWidth(in.rightWidth);
        const float top = imageTop, bottom = std::max(top, h - kMargin);
        const float between = w - (leftW + rightW + 2.0f * (kMargin + kHandleWidth));
        if (!in.inspector) {
            out.twoColumns = between >= kMinImageWidth;
        } else if (between >= 2.0f * kMinViewWidth) {
            // Beside the inspector only when one column cannot hold the open panels at their
            // typical heights: the image and the inspector keep the width otherwise.
            float need = 0.0f;
            for (int i = 0; i < kPanelCount; ++i) {
                const PanelRequest& p = in.panels[size_t(i)];
                if (p.open) need += (p.collapsed ? in.titleHeight : kTypical[i]) + kGap;
            }
            out.twoColumns = need - kGap > bottom - top;
        }
        std::vector<PanelId> left, right;
        float leftUsed = 0.0f, rightUsed = 0.0f;
        for (int i = 0; i < kPanelCount; ++i) {
            const PanelRequest& p = in.panels[size_t(i)];
            if (!p.open) continue;
            const Side fixed = in.inspector ? kSideBesideInspector[i] : kSide[i];
            const Side side =
                fixed == Side::Roomier ? (rightUsed < leftUsed ? Side::Right : Side::Left) : fixed;
            const bool toRight = out.twoColumns && side == Side::Right;
            (toRight ? right : left).push_back(PanelId(i));
            (toRight ? rightUsed : leftUsed) += (p.collapsed ? in.titleHeight : kTypical[i]) + kGap;
        }
        stack(left, {kMargin, top, kMargin + leftW, bottom}, in, out);
        stack(right, {w - kMargin - rightW, top, w - kMargin, bottom}, in, out);
        // Each column's inner edge is its drag handle, the gap between it and the image.
        if (!left.empty()) {
            imageLeft = std::min(w, kMargin + leftW + kHandleWidth);
            out.leftHandle = {kMargin + leftW, top, imageLeft, h};
            out.leftWidth = leftW;
        }
        if (!right.empty()) {
            imageRight = std::max(imageLeft, w - kMargin - rightW - kHandleWidth);
            out.rightHandle = {imageRight, top, w - kMargin - rightW, h};
            out.rightWidth = rightW;
        }
    }
    out.image = {imageLeft, imageTop, imageRight, h};
    if (in.inspector) {
        // The inspector's view takes the image's right part, as the split says, with the
        // split's handle between them.
        const float total = std::max(0.0f, imageRight - imageLeft - kHandleWidth);
        float imageW = std::round(std::clamp(in.imageShare, 0.0f, 1.0f) * total);
        if (total >= 2.0f * kMinViewportSide)
            imageW = std::clamp(imageW, kMinViewportSide, total - kMinViewportSide);
        out.image.x1 = imageLeft + imageW;
        out.splitHandle = {out.image.x1, imageTop, out.image.x1 + kHandleWidth, h};
        out.inspector = {out.splitHandle.x1, imageTop, imageRight, h};
    }
    return out;
}

std::pair<float, float> windowForImage(LayoutInput in, float imageWidth, float imageHeight) {
    float w = imageWidth + 2.0f * (kColumnMax + kMargin + kHandleWidth);
    float h = imageHeight + kMenuBarHeight;
    for (int step = 0; step < 16; ++step) {
        in.width = w;
        in.height = h;
        const PanelLayout l = layoutPanels(in);
        const float dw = imageWidth - l.image.width(), dh = imageHeight - l.image.height();
        if (dw == 0.0f && dh == 0.0f) break;
        // With the inspector, the image gets its share of each unit the window grows by.
        const float share = in.inspector ? std::clamp(in.imageShare, 0.1f, 1.0f) : 1.0f;
        w = std::max(1.0f, w + std::round(dw / share));
        h = std::max(1.0f, h + dh);
    }
    return {w, h};
}

}  // namespace lancer::viewer
