// OpenSCAD's text(): glyph outlines from FreeType, shaped by HarfBuzz, fonts found through
// fontconfig, laid out and flattened as OpenSCAD 2021.01's FreetypeRenderer does, so that the
// outline Lancer extrudes is the polygon OpenSCAD itself would extrude.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "engine/scene/openscad/region2d.h"

namespace lancer::openscad {

/// text()'s arguments, already checked (halign, valign and direction among OpenSCAD's words).
struct TextParams {
    std::string text;                 ///< UTF-8
    double size = 10.0;               ///< > 0
    std::string font;                 ///< a fontconfig pattern; "" means "Liberation Sans"
    std::string halign = "left";      ///< left, center, right
    std::string valign = "baseline";  ///< top, center, baseline, bottom
    double spacing = 1.0;
    std::string direction;  ///< ltr, rtl, ttb, btt, or "" (from the script)
    std::string language = "en";
    std::string script;  ///< ISO 15924 ("Latn"), or "" (from the text)
    int segments = 2;    ///< straight pieces per Bézier curve
};

/// A laid-out text: each glyph's closed contours (even-odd), in OpenSCAD's units.
struct TextLayout {
    std::vector<std::vector<std::vector<Vec2>>> glyphs;
    std::string fontFile;  ///< the font fontconfig chose (it falls back when none matches)
};

/// Thrown when no font can be loaded or FreeType fails; the reader names the node with it.
struct TextError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// OpenSCAD's straight pieces per glyph curve: floor(get_fragments_from_r(size) / 8) + 1, at
/// least 2 (text.cc), with get_fragments_from_r from OpenSCAD's calc.cc.
int textCurveSegments(double size, double fn, double fa, double fs);

/// The glyph outlines of `p`. Throws TextError.
TextLayout layoutText(const TextParams& p);

}  // namespace lancer::openscad
