// The colours OpenSCAD's color() takes: SVG names, "#rrggbb" forms, and its default face colour.
#pragma once

#include <cstdint>

#include "engine/geometry/geometry.h"
#include "engine/scene/openscad/parser.h"
#include "engine/scene/source_text.h"

namespace lancer::openscad {

/// OpenSCAD's default face colour (the "Cornfield" scheme), for nodes without a color().
constexpr uint32_t kDefaultColor = 0xf9d72c;

/// 0xrrggbb as RGB in [0, 1].
Vec3 hexColor(uint32_t hex);

/// The colour a string names: an SVG colour name (case-insensitive), "transparent", or #rgb,
/// #rgba, #rrggbb, #rrggbbaa (alpha ignored). Throws SceneError at the string otherwise.
Vec3 namedColor(const SourceText& src, const Value& c);

}  // namespace lancer::openscad
