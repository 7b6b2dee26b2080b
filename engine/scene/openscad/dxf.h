// DXF drawings as OpenSCAD's import() reads them: the closed outlines of one layer.
#pragma once

#include <string>
#include <vector>

#include "engine/scene/openscad/region2d.h"
#include "engine/scene/source_text.h"

namespace lancer::openscad {

/// How curves are cut into segments: OpenSCAD's $fn, $fa, $fs.
struct Fragments {
    double fn = 0.0, fa = 12.0, fs = 2.0;
    /// fragmentsFromR: the segments of a full circle of radius r, at most 1e9.
    int of(double r) const;
};

/// What a DXF drawing gave: its outlines, and how many were open (closed by their ends).
struct DxfOutlines {
    std::vector<std::vector<Vec2>> loops;  ///< closed, in drawing units, origin and scale applied
    int openChains = 0;                    ///< chains that did not close, closed by their ends
    int entities = 0;                      ///< entities read on the layer
};

/// The closed outlines of `layer` ("" for every layer) of the DXF file at `path`, as OpenSCAD's
/// DxfData: LINE, LWPOLYLINE, POLYLINE/VERTEX, CIRCLE and ARC entities, and INSERTs of blocks of
/// them (offset, scale, rotation), arcs and circles cut by `frag`; segments are chained by their
/// ends (within 1e-3, OpenSCAD's coarse grid) into paths, an open path closed by its ends as
/// OpenSCAD closes it. Each
/// point p becomes (p - origin) * scale. A file that cannot be read or parsed throws SceneError
/// naming its path and line.
DxfOutlines readDxf(const std::string& path, const std::string& layer, const Vec2& origin,
                    double scale, const Fragments& frag);

/// readDxf of a drawing already read (`src`'s path names it in messages).
DxfOutlines readDxfText(const SourceText& src, const std::string& layer, const Vec2& origin,
                        double scale, const Fragments& frag);

}  // namespace lancer::openscad
