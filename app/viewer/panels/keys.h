// The colour keys of what the image shows: a small box in the image viewport's bottom-left
// corner listing, for each overlay layer on and for the heat map, what its colours mean. The
// scales are fixed (levels by absolute level, counts on a log scale of whole decades, heat maps
// to a whole decade), so a key read before a rebuild still reads after it.
#pragma once

#include <glm/vec3.hpp>
#include <string>
#include <vector>

#include "app/viewer/colormap.h"
#include "app/viewer/overlay/overlay_geometry.h"
#include "app/viewer/panels/layout.h"

namespace lancer::viewer {

/// One colour of a key as drawn: its rectangle (display units), colour and label.
struct KeySwatch {
    Rect rect;          ///< where it is filled with `color` (its label may be drawn over it)
    glm::vec3 color{};  ///< the colour it stands for, as the overlay or heat map draws it
    std::string label;  ///< the value it stands for
};

/// One key: a title and its swatches.
struct Key {
    std::string title;  ///< what is coloured, and by what ("leaf level", "prim tests, log")
    std::vector<KeySwatch> swatches;
};

/// What drawKeys() drew: the box (empty when nothing needs a key) and its keys.
struct KeyReport {
    Rect box;
    std::vector<Key> keys;
};

/// What the keys describe this frame.
struct KeyInput {
    Rect image;  ///< the image viewport (display units): the box goes in its bottom-left corner
    /// The overlay layers on, and what the last build of their geometry drew (null: no
    /// structure yet, no overlay key).
    const overlay::OverlayOptions* overlays = nullptr;
    const overlay::OverlayGeometry* geometry = nullptr;
    ViewMode mode = ViewMode::Color;  ///< a heat map's counter (Color: no heat key)
    float heatScale = 1.0f;           ///< the heat map's top
    bool logScale = false;            ///< the heat map on log(1 + count)
    bool diverging = false;           ///< the heat map is an A/B difference
};

/// The keys `in` calls for, without drawing (what drawKeys() lays out; tests read the colours).
std::vector<Key> keysFor(const KeyInput& in);

/// Draw the keys (an ImGui window that takes no input, so clicks and drags reach the image)
/// and return where each swatch went.
KeyReport drawKeys(const KeyInput& in);

}  // namespace lancer::viewer
