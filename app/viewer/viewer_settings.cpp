#include "app/viewer/viewer_settings.h"

#include <imgui.h>
#include <imgui_internal.h>

#include <algorithm>
#include <sstream>

namespace lancer::viewer {

namespace {

template <class E>
bool parseEnum(const std::string& v, E count, const char* (*name)(E), E& out) {
    for (int i = 0; i < int(count); ++i)
        if (v == name(E(i))) {
            out = E(i);
            return true;
        }
    return false;
}

const char* viewModeKey(ViewMode m) {
    static const char* keys[] = {"color", "prim_tests", "region_visits", "time"};
    return keys[int(m)];
}

}  // namespace

std::string settingsLines(const ViewerSettings& s) {
    std::ostringstream o;
    o.precision(17);
    o << "scene=" << s.scene << "\n"
      << "scheme=" << schemeName(s.build.scheme) << "\n"
      << "max_level=" << s.build.maxLevel << "\n"
      << "max_objects=" << s.build.maxObjects << "\n"
      << "split_axes=" << splitAxesName(s.build.splitAxes) << "\n"
      << "step=" << stepName(s.build.step) << "\n"
      << "delta=" << s.build.delta << "\n"
      << "bsp_heuristic=" << heuristicName(s.build.heuristic) << "\n"
      << "mailboxes=" << s.build.mailboxes << "\n"
      << "light_buffer=" << s.build.lightBuffer << "\n"
      << "threads=" << s.threads << "\n"
      << "bounces=" << s.shading.bounces << "\n"
      << "shadows=" << s.shading.shadows << "\n"
      << "reflections=" << s.shading.reflections << "\n"
      << "refractions=" << s.shading.refractions << "\n"
      << "window=" << s.windowWidth << " " << s.windowHeight << "\n"
      << "panels=" << s.showParameters << " " << s.showStatistics << " " << s.showCamera << " "
      << s.showView << "\n"
      << "inspector=" << s.showInspector << "\n"
      << "view=" << viewModeKey(s.mode) << "\n"
      << "auto_scale=" << s.autoScale << "\n"
      << "heat_scale=" << s.heatScale << "\n";
    return o.str();
}

void readSettingsLine(ViewerSettings& s, const std::string& line) {
    size_t eq = line.find('=');
    if (eq == std::string::npos) return;
    std::string key = line.substr(0, eq), value = line.substr(eq + 1);
    std::istringstream in(value);
    auto integer = [&](int& out, int lo, int hi) {
        int v;
        if (in >> v && v >= lo && v <= hi) out = v;
    };
    auto flag = [&](bool& out) {
        int v;
        if (in >> v) out = v != 0;
    };
    if (key == "scene" && !value.empty())
        s.scene = value;
    else if (key == "scheme")
        parseEnum(value, SchemeKind(3), schemeName, s.build.scheme);
    else if (key == "max_level")
        integer(s.build.maxLevel, 0, 48);
    else if (key == "max_objects")
        integer(s.build.maxObjects, 1, 1000000);
    else if (key == "split_axes")
        parseEnum(value, SplitAxes(2), splitAxesName, s.build.splitAxes);
    else if (key == "step")
        parseEnum(value, StepMethod(2), stepName, s.build.step);
    else if (key == "delta") {
        double d;
        if (in >> d && d >= 1e-15 && d <= 0.5) s.build.delta = d;
    } else if (key == "bsp_heuristic")
        parseEnum(value, BspHeuristic(3), heuristicName, s.build.heuristic);
    else if (key == "mailboxes")
        flag(s.build.mailboxes);
    else if (key == "light_buffer")
        flag(s.build.lightBuffer);
    else if (key == "threads")
        integer(s.threads, 0, 1024);
    else if (key == "bounces")
        integer(s.shading.bounces, 0, 64);
    else if (key == "shadows")
        flag(s.shading.shadows);
    else if (key == "reflections")
        flag(s.shading.reflections);
    else if (key == "refractions")
        flag(s.shading.refractions);
    else if (key == "window") {
        int w, h;
        if (in >> w >> h && w >= 64 && h >= 64 && w <= 16384 && h <= 16384) {
            s.windowWidth = w;
            s.windowHeight = h;
        }
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
    } else if (key == "view") {
        for (int i = 0; i < kViewModeCount; ++i)
            if (value == viewModeKey(ViewMode(i))) s.mode = ViewMode(i);
    } else if (key == "auto_scale")
        flag(s.autoScale);
    else if (key == "heat_scale") {
        float v;
        if (in >> v && v > 0.0f && v < 1e12f) s.heatScale = v;
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
