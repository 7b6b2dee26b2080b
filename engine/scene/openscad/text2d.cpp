#include "engine/scene/openscad/text2d.h"

#include <fontconfig/fontconfig.h>
#include <ft2build.h>
#include FT_FREETYPE_H
#include FT_GLYPH_H
#include FT_OUTLINE_H
#include <hb-ft.h>
#include <hb.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

namespace lancer::openscad {

namespace {

// OpenSCAD's FreetypeRenderer divides outline coordinates (26.6 pixels) by 1000, but HarfBuzz
// advances, offsets and the grid-fitted boxes by 64 * 16 = 1024. The mismatch is OpenSCAD's and
// is kept: it decides where each glyph lands, and Lancer draws what OpenSCAD draws.
constexpr double kOutlineScale = 1000.0;
constexpr double kMetricScale = 64.0 * 16.0;

/// One glyph's contours being drawn: DrawingCallback's pen, offset and flattening.
struct Pen {
    std::vector<std::vector<Vec2>> contours;
    Vec2 pen{0.0}, origin{0.0};
    int segments = 2;
    void add(Vec2 v) { contours.back().push_back(v + origin); }
};

Vec2 scaled(const FT_Vector* v) {
    return {double(v->x) / kOutlineScale, double(v->y) / kOutlineScale};
}

int moveTo(const FT_Vector* to, void* user) {
    Pen& p = *static_cast<Pen*>(user);
    p.contours.emplace_back();
    p.pen = scaled(to);
    p.add(p.pen);
    return 0;
}
int lineTo(const FT_Vector* to, void* user) {
    Pen& p = *static_cast<Pen*>(user);
    p.pen = scaled(to);
    p.add(p.pen);
    return 0;
}
// Bézier curves at `segments` equal parameter steps, as OpenSCAD's DrawingCallback::curve_to.
int conicTo(const FT_Vector* c, const FT_Vector* to, void* user) {
    Pen& p = *static_cast<Pen*>(user);
    const Vec2 a = p.pen, b = scaled(c), e = scaled(to);
    for (int i = 1; i <= p.segments; ++i) {
        const double t = i * (1.0 / p.segments), s = 1.0 - t;
        p.add(a * (s * s) + b * (2.0 * s * t) + e * (t * t));
    }
    p.pen = e;
    return 0;
}
int cubicTo(const FT_Vector* c1, const FT_Vector* c2, const FT_Vector* to, void* user) {
    Pen& p = *static_cast<Pen*>(user);
    const Vec2 a = p.pen, b = scaled(c1), c = scaled(c2), e = scaled(to);
    for (int i = 1; i <= p.segments; ++i) {
        const double t = i * (1.0 / p.segments), s = 1.0 - t;
        p.add(a * (s * s * s) + b * (3.0 * s * s * t) + c * (3.0 * s * t * t) + e * (t * t * t));
    }
    p.pen = e;
    return 0;
}

/// The font file and face index fontconfig picks for `pattern` (its best match, so an unknown
/// family falls back to a default font as in OpenSCAD).
std::pair<std::string, int> findFont(const std::string& pattern) {
    // fontconfig's default configuration is global; FcInit is cheap after the first call.
    static std::mutex m;
    std::lock_guard<std::mutex> lock(m);
    if (!FcInit()) throw TextError("fontconfig could not be initialised");
    std::unique_ptr<FcPattern, decltype(&FcPatternDestroy)> pat(
        FcNameParse(reinterpret_cast<const FcChar8*>(pattern.c_str())), FcPatternDestroy);
    if (!pat) throw TextError("the font name '" + pattern + "' is not a fontconfig pattern");
    FcConfigSubstitute(nullptr, pat.get(), FcMatchPattern);
    FcDefaultSubstitute(pat.get());
    FcResult res = FcResultNoMatch;
    std::unique_ptr<FcPattern, decltype(&FcPatternDestroy)> match(
        FcFontMatch(nullptr, pat.get(), &res), FcPatternDestroy);
    FcChar8* file = nullptr;
    int index = 0;
    if (!match || FcPatternGetString(match.get(), FC_FILE, 0, &file) != FcResultMatch || !file)
        throw TextError("fontconfig finds no font for '" + pattern +
                        "' (is fonts-liberation "
                        "installed?)");
    FcPatternGetInteger(match.get(), FC_INDEX, 0, &index);
    return {reinterpret_cast<const char*>(file), index};
}

}  // namespace

int textCurveSegments(double size, double fn, double fa, double fs) {
    // OpenSCAD's get_fragments_from_r(size, fn, fs, fa), then text.cc's fraction of it.
    const double fragments = fragmentsFromR(size, fn, fa, fs);
    return int(std::min(std::max(std::floor(fragments / 8.0) + 1.0, 2.0), 1000.0));
}

TextLayout layoutText(const TextParams& p) {
    TextLayout out;
    const std::string pattern = p.font.empty() ? "Liberation Sans" : p.font;
    auto [file, index] = findFont(pattern);
    out.fontFile = file;

    FT_Library lib = nullptr;
    if (FT_Init_FreeType(&lib)) throw TextError("FreeType could not be initialised");
    std::unique_ptr<FT_LibraryRec_, decltype(&FT_Done_FreeType)> libGuard(lib, FT_Done_FreeType);
    FT_Face face = nullptr;
    if (FT_New_Face(lib, file.c_str(), index, &face))
        throw TextError("FreeType cannot read the font file " + file);
    std::unique_ptr<FT_FaceRec_, decltype(&FT_Done_Face)> faceGuard(face, FT_Done_Face);
    // OpenSCAD's size: a character height of size * 1000 (26.6 points) at 100 dpi, whose outline
    // coordinates are then divided by 1000, so one em is size / 0.72 and a capital about `size`.
    if (FT_Set_Char_Size(face, 0, FT_F26Dot6(p.size * kOutlineScale), 100, 100))
        throw TextError("FreeType cannot set the size " + std::to_string(p.size) + " for " + file);

    std::unique_ptr<hb_font_t, decltype(&hb_font_destroy)> font(hb_ft_font_create(face, nullptr),
                                                                hb_font_destroy);
    std::unique_ptr<hb_buffer_t, decltype(&hb_buffer_destroy)> buf(hb_buffer_create(),
                                                                   hb_buffer_destroy);
    hb_buffer_add_utf8(buf.get(), p.text.c_str(), int(p.text.size()), 0, int(p.text.size()));
    if (!p.direction.empty())
        hb_buffer_set_direction(buf.get(), hb_direction_from_string(p.direction.c_str(), -1));
    if (!p.script.empty())
        hb_buffer_set_script(buf.get(), hb_script_from_string(p.script.c_str(), -1));
    hb_buffer_set_language(buf.get(), hb_language_from_string(p.language.c_str(), -1));
    // What is not given comes from the text, as OpenSCAD's detect_properties.
    hb_buffer_guess_segment_properties(buf.get());
    hb_shape(font.get(), buf.get(), nullptr, 0);
    const bool horizontal = HB_DIRECTION_IS_HORIZONTAL(hb_buffer_get_direction(buf.get()));

    unsigned count = 0;
    hb_glyph_info_t* info = hb_buffer_get_glyph_infos(buf.get(), &count);
    hb_glyph_position_t* pos = hb_buffer_get_glyph_positions(buf.get(), &count);

    struct Glyph {
        FT_Glyph glyph;
        const hb_glyph_position_t* pos;
    };
    std::vector<Glyph> glyphs;
    auto freeGlyphs = [&] {
        for (Glyph& g : glyphs) FT_Done_Glyph(g.glyph);
    };
    for (unsigned i = 0; i < count; ++i) {
        // A glyph FreeType cannot load is skipped, as OpenSCAD does (it warns). Unhinted: Debian's
        // OpenSCAD 2021.01 meshes unhinted outlines (its L is 1409 font units tall, not the
        // hinted 9.536 at size 10), and hinting would move stems by up to 0.03 at size 10.
        if (FT_Load_Glyph(face, info[i].codepoint, FT_LOAD_NO_HINTING)) continue;
        FT_Glyph g = nullptr;
        if (FT_Get_Glyph(face->glyph, &g)) continue;
        if (g->format != FT_GLYPH_FORMAT_OUTLINE) {
            FT_Done_Glyph(g);
            freeGlyphs();
            throw TextError("the font " + file + " has bitmap glyphs, which have no outline");
        }
        glyphs.push_back({g, &pos[i]});
    }

    double width = 0.0, ascend = 0.0, descend = 0.0;
    for (const Glyph& g : glyphs) {
        FT_BBox box;
        // Not grid-fitted: Debian's OpenSCAD 2021.01 aligns on the outline's own box (its
        // valign = "top" puts an L's top at 9.5548 - 9.3312, the unrounded yMax / 1024).
        FT_Glyph_Get_CBox(g.glyph, FT_GLYPH_BBOX_UNSCALED, &box);
        if (horizontal) {
            width += g.pos->x_advance / kMetricScale * p.spacing;
            ascend = std::max(ascend, std::max(0.0, box.yMax / kMetricScale));
            descend = std::max(descend, std::max(0.0, -box.yMin / kMetricScale));
        } else {
            width = std::max(width, (box.xMax - box.xMin) / kMetricScale);
            ascend += g.pos->y_advance / kMetricScale * p.spacing;
        }
    }
    const double dx = p.halign == "right" ? -width : p.halign == "center" ? -width / 2.0 : 0.0;
    const double dy = p.valign == "top"      ? -ascend
                      : p.valign == "center" ? descend / 2.0 - ascend / 2.0
                      : p.valign == "bottom" ? descend
                                             : 0.0;

    FT_Outline_Funcs funcs{};
    funcs.move_to = moveTo;
    funcs.line_to = lineTo;
    funcs.conic_to = conicTo;
    funcs.cubic_to = cubicTo;
    Vec2 advance(0.0);
    for (const Glyph& g : glyphs) {
        Pen pen;
        pen.segments = p.segments;
        pen.origin =
            Vec2(dx + g.pos->x_offset / kMetricScale, dy + g.pos->y_offset / kMetricScale) +
            advance;
        FT_Outline outline = reinterpret_cast<FT_OutlineGlyph>(g.glyph)->outline;
        FT_Outline_Decompose(&outline, &funcs, &pen);
        advance += Vec2(g.pos->x_advance, g.pos->y_advance) * (p.spacing / kMetricScale);
        if (!pen.contours.empty()) out.glyphs.push_back(std::move(pen.contours));
    }
    freeGlyphs();
    return out;
}

}  // namespace lancer::openscad
