#include "app/viewer/viewer_settings.h"

#include <imgui.h>
#include <imgui_internal.h>

#include <algorithm>
#include <iterator>
#include <sstream>

namespace lancer::viewer {

namespace {

/// The ini's words for the overlays' colourings, in the enums' order.
constexpr const char* kZoneFillWords[] = {"prims", "slabs", "visits", "tests"};
constexpr const char* kLeafColorWords[] = {"level", "prims", "visits", "tests"};
constexpr const char* kSlabColorWords[] = {"order", "visits", "tests"};

const char* viewModeKey(ViewMode m) {
    static const char* keys[] = {"color", "prim_tests", "region_visits", "time"};
    return keys[int(m)];
}

/// Flags written as 0/1 separated by spaces, read back in the same order (a short line leaves
/// the flags after it as they were).
/// The ini's word for a directory grid colouring.
const char* gridColorWord(overlay::GridColor c) {
    switch (c) {
        case overlay::GridColor::Level:
            return "level";
        case overlay::GridColor::TableDepth:
            return "depth";
        case overlay::GridColor::Kind:
            break;
    }
    return "kind";
}

std::string flagsText(std::initializer_list<bool> flags) {
    std::string out;
    for (bool f : flags) out += std::string(out.empty() ? "" : " ") + (f ? "1" : "0");
    return out;
}

void readFlags(std::istringstream& in, std::initializer_list<bool*> flags) {
    for (bool* f : flags) {
        int v;
        if (!(in >> v)) return;
        *f = v != 0;
    }
}

/// Whether `v` (a count, a level, an opacity) is a value the viewer can take.
template <class T>
bool readIn(std::istringstream& in, T& out, T lo, T hi) {
    T v;
    if (!(in >> v) || !(v >= lo && v <= hi)) return false;
    out = v;
    return true;
}

}  // namespace

cli::Knobs knobsOf(const ViewerSettings& s) {
    cli::Knobs k;
    k.build = s.build;
    k.shading = s.shading;
    k.threads = s.threads;
    k.width = s.windowWidth;
    k.height = s.windowHeight;
    k.cameraPath = s.cameraPath;
    k.read = s.read;
    return k;
}

void setKnobs(ViewerSettings& s, const cli::Knobs& k) {
    s.build = k.build;
    s.shading = k.shading;
    s.threads = k.threads;
    s.windowWidth = k.width;
    s.windowHeight = k.height;
    s.cameraPath = k.cameraPath;
    s.read = k.read;
}

std::string settingsLines(const ViewerSettings& s) {
    std::ostringstream o;
    o.precision(17);
    o << "scene=" << s.scene << "\n";
    o << "knob_format=2\n";
    const cli::Knobs k = knobsOf(s);
    for (const cli::ParamDesc& d : cli::paramTable())
        if (d.iniKey) o << d.iniKey << "=" << cli::formatValue(d, k) << "\n";
    o << "panels=" << s.showParameters << " " << s.showStatistics << " " << s.showCamera << " "
      << s.showView << "\n"
      << "inspector=" << s.showInspector << "\n"
      << "layout=" << s.leftColumn << " " << s.rightColumn << " " << s.imageShare << "\n"
      << "view=" << viewModeKey(s.mode) << "\n"
      << "auto_scale=" << s.autoScale << "\n"
      << "heat_scale=" << s.heatScale << "\n"
      << "log_scale=" << s.logScale << "\n";
    const overlay::OverlayOptions& ov = s.overlays;
    o << "overlay_layers=" << flagsText({ov.bsp, ov.zones, ov.slabs, ov.leaves, ov.grid}) << "\n"
      << "overlay_fill=" << kZoneFillWords[size_t(ov.zoneFill)] << "\n"
      << "overlay_color=" << kLeafColorWords[size_t(ov.leafColor)] << "\n"
      << "overlay_slab_color=" << kSlabColorWords[size_t(ov.slabColor)] << "\n"
      << "overlay_cost_rays=" << (ov.costRays == CostRays::Primary ? "primary" : "all") << "\n"
      << "overlay_grid_color=" << gridColorWord(ov.gridColor) << "\n"
      << "overlay_projective=" << ov.projective << "\n"
      << "overlay_levels=" << ov.levelMin << " " << ov.levelMax << "\n"
      << "overlay_cap=" << ov.cap << "\n"
      << "overlay_opacity=" << s.overlayLook.fillOpacity << " " << s.overlayLook.lineOpacity << "\n"
      << "overlay_tooltip=" << s.overlayLook.tooltip << "\n"
      << "overlay_moving_lines=" << s.overlayLook.movingLines << "\n";
    const inspector::InspectorOptions& in = s.inspector;
    o << "inspector_layers="
      << flagsText(
             {in.regions, in.zones, in.grid, in.boxes, in.frustum, in.surfaces, in.zoneSlabsOnly})
      << "\n"
      << "inspector_color=" << inspector::colorByName(in.colorBy) << "\n"
      << "inspector_levels=" << in.levelLo << " " << in.levelHi << "\n"
      << "inspector_slice=" << in.slab.on << " " << in.slab.axis << " " << in.slab.lo << " "
      << in.slab.hi << "\n"
      << "inspector_cap=" << in.cap << "\n";
    if (s.inspectorCamera) {
        const Camera& c = *s.inspectorCamera;
        o << "inspector_scene=" << s.inspectorScene << "\n"
          << "inspector_camera=" << c.from.x << " " << c.from.y << " " << c.from.z << " " << c.at.x
          << " " << c.at.y << " " << c.at.z << " " << c.up.x << " " << c.up.y << " " << c.up.z
          << " " << c.fov << " "
          << (c.projection == Projection::Orthographic ? "orthographic" : "perspective") << " "
          << c.orthoHeight << "\n";
    }
    return o.str();
}

void readSettingsLine(ViewerSettings& s, const std::string& line) {
    size_t eq = line.find('=');
    if (eq == std::string::npos) return;
    std::string key = line.substr(0, eq), value = line.substr(eq + 1);
    if (key == "knob_format") {
        s.knobFormat = value == "2" ? 2 : 1;
        return;
    }
    // An ini of format 1 wrote the default max-objects as 4, and any max-objects then built as
    // the default does (the cost stop deciding): auto keeps that build.
    if (key == "max_objects" && value == "4" && s.knobFormat < 2) value = "auto";
    for (const cli::ParamDesc& d : cli::paramTable())
        if (d.iniKey && key == d.iniKey) {
            cli::Knobs k = knobsOf(s);
            if (cli::parseValue(d, value, k)) setKnobs(s, k);
            return;
        }
    std::istringstream in(value);
    auto flag = [&](bool& out) {
        int v;
        if (in >> v) out = v != 0;
    };
    if (key == "scene" && !value.empty()) {
        s.scene = value;
    } else if (key == "panels") {
        int a, b, c, d;
        if (in >> a >> b >> c >> d) {
            s.showParameters = a;
            s.showStatistics = b;
            s.showCamera = c;
            s.showView = d;
        }
    } else if (key == "inspector") {
        int on;
        if (in >> on) s.showInspector = on;
    } else if (key == "layout") {
        float l = 0.0f, r = 0.0f, share = 0.5f;
        if (readIn(in, l, 0.0f, 1e5f) && readIn(in, r, 0.0f, 1e5f) &&
            readIn(in, share, 0.0f, 1.0f)) {
            s.leftColumn = l;
            s.rightColumn = r;
            s.imageShare = share;
        }
    } else if (key == "view") {
        for (int i = 0; i < kViewModeCount; ++i)
            if (value == viewModeKey(ViewMode(i))) s.mode = ViewMode(i);
    } else if (key == "auto_scale") {
        flag(s.autoScale);
    } else if (key == "log_scale") {
        flag(s.logScale);
    } else if (key == "heat_scale") {
        float v;
        if (in >> v && v > 0.0f && v < 1e12f) s.heatScale = v;
    } else if (key == "overlay_layers") {
        overlay::OverlayOptions& o = s.overlays;
        readFlags(in, {&o.bsp, &o.zones, &o.slabs, &o.leaves, &o.grid});
    } else if (key == "overlay_fill") {
        for (size_t i = 0; i < std::size(kZoneFillWords); ++i)
            if (value == kZoneFillWords[i]) s.overlays.zoneFill = overlay::ZoneFill(i);
    } else if (key == "overlay_color") {
        for (size_t i = 0; i < std::size(kLeafColorWords); ++i)
            if (value == kLeafColorWords[i]) s.overlays.leafColor = overlay::LeafColor(i);
    } else if (key == "overlay_slab_color") {
        for (size_t i = 0; i < std::size(kSlabColorWords); ++i)
            if (value == kSlabColorWords[i]) s.overlays.slabColor = overlay::SlabColor(i);
    } else if (key == "overlay_cost_rays") {
        if (value == "all" || value == "primary")
            s.overlays.costRays = value == "primary" ? CostRays::Primary : CostRays::All;
    } else if (key == "overlay_grid_color") {
        for (overlay::GridColor c :
             {overlay::GridColor::Kind, overlay::GridColor::Level, overlay::GridColor::TableDepth})
            if (value == gridColorWord(c)) s.overlays.gridColor = c;
    } else if (key == "overlay_projective") {
        flag(s.overlays.projective);
    } else if (key == "overlay_levels") {
        int lo = 0, hi = 0;
        if (readIn(in, lo, 0, 1 << 20) && readIn(in, hi, lo, 1 << 20)) {
            s.overlays.levelMin = lo;
            s.overlays.levelMax = hi;
        }
    } else if (key == "overlay_cap") {
        readIn(in, s.overlays.cap, size_t(0), size_t(1) << 40);
    } else if (key == "overlay_opacity") {
        float fill = 0.0f, line = 0.0f;
        if (readIn(in, fill, 0.0f, 1.0f) && readIn(in, line, 0.0f, 1.0f)) {
            s.overlayLook.fillOpacity = fill;
            s.overlayLook.lineOpacity = line;
        }
    } else if (key == "overlay_tooltip") {
        flag(s.overlayLook.tooltip);
    } else if (key == "overlay_moving_lines") {
        readIn(in, s.overlayLook.movingLines, size_t(0), size_t(1) << 40);
    } else if (key == "inspector_layers") {
        inspector::InspectorOptions& o = s.inspector;
        readFlags(in, {&o.regions, &o.zones, &o.grid, &o.boxes, &o.frustum, &o.surfaces,
                       &o.zoneSlabsOnly});
    } else if (key == "inspector_color") {
        for (inspector::ColorBy c : {inspector::ColorBy::Prims, inspector::ColorBy::Level})
            if (value == inspector::colorByName(c)) s.inspector.colorBy = c;
    } else if (key == "inspector_levels") {
        int lo = 0, hi = 0;
        if (readIn(in, lo, 0, 1 << 20) && readIn(in, hi, lo, 1 << 20)) {
            s.inspector.levelLo = lo;
            s.inspector.levelHi = hi;
        }
    } else if (key == "inspector_slice") {
        int on = 0, axis = 0;
        double lo = 0.0, hi = 0.0;
        if (readIn(in, on, 0, 1) && readIn(in, axis, 0, 2) && readIn(in, lo, -1e300, 1e300) &&
            readIn(in, hi, lo, 1e300))
            s.inspector.slab = {on != 0, axis, lo, hi};
    } else if (key == "inspector_cap") {
        readIn(in, s.inspector.cap, 0, 1 << 30);
    } else if (key == "inspector_scene") {
        s.inspectorScene = value;
    } else if (key == "inspector_camera") {
        Camera c;
        std::string projection;
        if (in >> c.from.x >> c.from.y >> c.from.z >> c.at.x >> c.at.y >> c.at.z >> c.up.x >>
                c.up.y >> c.up.z >> c.fov >> projection >> c.orthoHeight &&
            (projection == "perspective" || projection == "orthographic")) {
            c.projection =
                projection == "orthographic" ? Projection::Orthographic : Projection::Perspective;
            if (c.validate().empty()) s.inspectorCamera = c;
        }
    }
}

void registerSettingsHandler(ViewerSettings* s) {
    ImGuiSettingsHandler h;
    h.TypeName = "Lancer";
    h.TypeHash = ImHashStr("Lancer");
    h.UserData = s;
    h.ReadOpenFn = [](ImGuiContext*, ImGuiSettingsHandler* self, const char* name) -> void* {
        return std::string(name) == "Settings" ? self->UserData : nullptr;
    };
    h.ReadLineFn = [](ImGuiContext*, ImGuiSettingsHandler*, void* entry, const char* line) {
        readSettingsLine(*static_cast<ViewerSettings*>(entry), line);
    };
    h.WriteAllFn = [](ImGuiContext*, ImGuiSettingsHandler* self, ImGuiTextBuffer* out) {
        out->append("[Lancer][Settings]\n");
        std::string lines = settingsLines(*static_cast<ViewerSettings*>(self->UserData));
        out->append(lines.c_str());
        out->append("\n");
    };
    ImGui::GetCurrentContext()->SettingsHandlers.push_back(h);
}

}  // namespace lancer::viewer
