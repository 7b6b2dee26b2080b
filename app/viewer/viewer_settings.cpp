#include "app/viewer/viewer_settings.h"

#include <imgui.h>
#include <imgui_internal.h>

#include <algorithm>
#include <sstream>

namespace lancer::viewer {

namespace {

const char* viewModeKey(ViewMode m) {
    static const char* keys[] = {"color", "prim_tests", "region_visits", "time"};
    return keys[int(m)];
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
    return k;
}

void setKnobs(ViewerSettings& s, const cli::Knobs& k) {
    s.build = k.build;
    s.shading = k.shading;
    s.threads = k.threads;
    s.windowWidth = k.width;
    s.windowHeight = k.height;
    s.cameraPath = k.cameraPath;
}

std::string settingsLines(const ViewerSettings& s) {
    std::ostringstream o;
    o.precision(17);
    o << "scene=" << s.scene << "\n";
    const cli::Knobs k = knobsOf(s);
    for (const cli::ParamDesc& d : cli::paramTable())
        if (d.iniKey) o << d.iniKey << "=" << cli::formatValue(d, k) << "\n";
    o << "panels=" << s.showParameters << " " << s.showStatistics << " " << s.showCamera << " "
      << s.showView << "\n"
      << "inspector=" << s.showInspector << "\n"
      << "view=" << viewModeKey(s.mode) << "\n"
      << "auto_scale=" << s.autoScale << "\n"
      << "heat_scale=" << s.heatScale << "\n"
      << "log_scale=" << s.logScale << "\n";
    return o.str();
}

void readSettingsLine(ViewerSettings& s, const std::string& line) {
    size_t eq = line.find('=');
    if (eq == std::string::npos) return;
    std::string key = line.substr(0, eq), value = line.substr(eq + 1);
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
