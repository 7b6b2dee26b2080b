#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/viewer/panels/panels.h"
#include "app/viewer/panels/widgets.h"

namespace lancer::viewer {

namespace {

/// "tests 9 -> 4, mailbox hits 0 -> 1, regions 3 -> 2": the walk before the rebuild and now.
std::string compareCounts(const playback::WalkCounts& a, const playback::WalkCounts& b) {
    auto pair = [](const char* what, uint64_t x, uint64_t y) {
        return std::string(what) + " " + std::to_string(x) + " -> " + std::to_string(y);
    };
    return pair("tests", a.primTests, b.primTests) + ", " +
           pair("mailbox hits", a.mailboxHits, b.mailboxHits) + ", " +
           pair("regions", a.regions, b.regions);
}

/// The CSG along the ray in the current step: one row per primitive tested (mailbox hits
/// greyed, with the spans of their earlier test) and the region tree's combined spans, on a t
/// axis covering the region's stretch [t0, t1] (shaded) and every finite span end; the hit, when
/// it lies on the axis, as a vertical line.
void csgStrip(const playback::RayPlayback& play) {
    const std::vector<playback::SpanRow> rows = playback::stepSpans(play);
    const WalkEvent* region = play.region();
    if (!region) return;
    if (rows.empty()) {
        hintText("No primitive tested in this region.");
        return;
    }
    double lo = region->t0, hi = std::isfinite(region->t1) ? region->t1 : region->t0;
    for (const playback::SpanRow& r : rows)
        for (const Span& sp : r.spans) {
            if (std::isfinite(sp.in.t)) lo = std::min(lo, sp.in.t), hi = std::max(hi, sp.in.t);
            if (std::isfinite(sp.out.t)) lo = std::min(lo, sp.out.t), hi = std::max(hi, sp.out.t);
        }
    const TracedRay& ray = play.ray();
    if (ray.hit.valid()) hi = std::max(hi, ray.hit.t);
    lo = std::max(lo, ray.tmin);
    if (!(hi > lo)) hi = lo + 1.0;
    const double pad = 0.03 * (hi - lo);
    lo -= pad;
    hi += pad;

    const float labelW = 70.0f, rowH = 14.0f;
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    const float w = std::max(ImGui::GetContentRegionAvail().x - labelW, 50.0f);
    const float h = rowH * float(rows.size() + 1);
    ImDrawList* dl = ImGui::GetWindowDrawList();
    auto X = [&](double t) {
        return origin.x + labelW + float((std::clamp(t, lo, hi) - lo) / (hi - lo)) * w;
    };
    // The region's stretch of the ray, shaded behind the rows.
    const double t1 = std::isfinite(region->t1) ? region->t1 : hi;
    dl->AddRectFilled(ImVec2(X(region->t0), origin.y), ImVec2(X(t1), origin.y + h),
                      IM_COL32(255, 216, 26, 40));
    for (size_t i = 0; i < rows.size(); ++i) {
        const playback::SpanRow& r = rows[i];
        const float y = origin.y + rowH * float(i);
        const std::string label = r.prim == kNoPrim ? "region" : "p" + std::to_string(r.prim);
        const ImU32 text = r.mailbox ? IM_COL32(150, 150, 150, 255) : IM_COL32(230, 230, 230, 255);
        dl->AddText(ImVec2(origin.x, y), text, (label + (r.mailbox ? " (mb)" : "")).c_str());
        const ImU32 fill = r.prim == kNoPrim ? IM_COL32(255, 60, 220, 255)
                           : r.mailbox       ? IM_COL32(110, 110, 140, 255)
                                             : IM_COL32(90, 160, 255, 255);
        dl->AddLine(ImVec2(origin.x + labelW, y + rowH * 0.5f),
                    ImVec2(origin.x + labelW + w, y + rowH * 0.5f), IM_COL32(80, 80, 80, 255));
        for (const Span& sp : r.spans) {
            const float x0 = X(sp.in.t), x1 = std::max(X(sp.out.t), x0 + 2.0f);
            dl->AddRectFilled(ImVec2(x0, y + 2.0f), ImVec2(x1, y + rowH - 2.0f), fill);
        }
    }
    if (ray.hit.valid() && ray.hit.t >= lo && ray.hit.t <= hi)
        dl->AddLine(ImVec2(X(ray.hit.t), origin.y), ImVec2(X(ray.hit.t), origin.y + h),
                    IM_COL32(40, 255, 80, 255), 2.0f);
    // The axis: its two ends' t.
    char buf[64];
    const float ya = origin.y + rowH * float(rows.size());
    std::snprintf(buf, sizeof buf, "t %.4g", lo);
    dl->AddText(ImVec2(origin.x + labelW, ya), IM_COL32(200, 200, 200, 255), buf);
    std::snprintf(buf, sizeof buf, "%.4g", hi);
    dl->AddText(ImVec2(origin.x + labelW + w - ImGui::CalcTextSize(buf).x, ya),
                IM_COL32(200, 200, 200, 255), buf);
    ImGui::Dummy(ImVec2(labelW + w, h + 2.0f));
}

}  // namespace

void rayPanel(ViewerState& st, playback::RayPlayer& player, bool* open) {
    ImGuiIO& io = ImGui::GetIO();
    ImGui::SetNextWindowPos(ImVec2(8, io.DisplaySize.y - 368), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(560, 360), ImGuiCond_FirstUseEver);
    if (!ImGui::Begin("Ray", open)) {
        ImGui::End();
        return;
    }
    playback::RayPlayback& play = player.playback();
    static int typed[2] = {0, 0};
    if (!play.empty() && !ImGui::IsAnyItemActive()) {
        typed[0] = play.pixel().x;
        typed[1] = play.pixel().y;
    }
    ImGui::SetNextItemWidth(160);
    ImGui::InputInt2("pixel", typed);
    ImGui::SameLine();
    if (ImGui::Button("Pick")) player.pick(typed[0], typed[1]);
    ImGui::SameLine();
    hintText("or Shift+click the image");
    errorText(player.note().rfind("pixel", 0) == 0 ? player.note() : "");
    if (play.empty()) {
        ImGui::End();
        return;
    }
    const Scene* scene = st.sceneBuild() ? st.sceneBuild()->scene.get() : nullptr;
    const RayTree& tree = play.tree();
    ImGui::TextWrapped("%s", tree.counters.toString().c_str());

    // The tree: one line per ray, as `lancer trace` prints it; a click plays that ray.
    if (ImGui::BeginChild("rays", ImVec2(0, 90), true)) {
        for (size_t k = 0; k < tree.rays.size(); ++k) {
            const TracedRay& r = tree.rays[k];
            std::string line(size_t(2 * r.depth + (r.kind == RayKind::Shadow ? 2 : 0)), ' ');
            line += r.toString();
            if (std::optional<playback::WalkCounts> was = play.previousCounts(int(k)))
                line += "   [rebuilt: " + compareCounts(*was, playback::countsOf(r)) + "]";
            ImGui::PushID(int(k));
            if (ImGui::Selectable(line.c_str(), int(k) == play.state().ray)) play.selectRay(int(k));
            ImGui::PopID();
        }
    }
    ImGui::EndChild();

    // Transport: first, back, play / pause, forward, last, speed.
    if (ImGui::Button("|<")) play.first();
    ImGui::SameLine();
    if (ImGui::Button("<")) play.back();
    ImGui::SameLine();
    if (play.playing() ? ImGui::Button("pause") : ImGui::Button("play")) {
        if (play.playing())
            play.pause();
        else
            play.play();
    }
    ImGui::SameLine();
    if (ImGui::Button(">")) play.forward();
    ImGui::SameLine();
    if (ImGui::Button(">|")) play.last();
    ImGui::SameLine();
    float speed = float(play.speed());
    ImGui::SetNextItemWidth(120);
    if (ImGui::SliderFloat("steps/s", &speed, 0.1f, 20.0f, "%.1f", ImGuiSliderFlags_Logarithmic))
        play.setSpeed(speed);
    ImGui::SameLine();
    if (play.stepCount() > 0)
        ImGui::Text("step %d / %d", play.state().step + 1, play.stepCount());
    else
        ImGui::TextUnformatted("walks no region");
    const TracedRay& ray = play.ray();
    if (std::optional<playback::WalkCounts> was = play.previousCounts(play.state().ray))
        ImGui::TextWrapped("after the rebuild: %s",
                           compareCounts(*was, playback::countsOf(ray)).c_str());

    if (ImGui::Button("Copy as trace command")) {
        const std::string file =
            (std::filesystem::temp_directory_path() / "lancer-pick-camera.json").string();
        const std::string cmd = player.copyTraceCommand(st, file);
        if (!cmd.empty()) ImGui::SetClipboardText(cmd.c_str());
    }
    if (player.note().rfind("pixel", 0) != 0 && !player.note().empty()) {
        ImGui::SameLine();
        hintText(player.note().c_str());
    }

    if (ImGui::CollapsingHeader("CSG along the ray (this region)", ImGuiTreeNodeFlags_DefaultOpen))
        csgStrip(play);

    // The ray's events as `lancer trace` prints them, the current step's lit; each region
    // step's reason (explainSteps: how the walk goes on from it) as its line's tooltip, and the
    // current step's under the list.
    const playback::PlaybackState& s = play.state();
    const std::vector<StepReason> why =
        player.view() ? explainSteps(ray, *player.view(), &player.view()->scene())
                      : std::vector<StepReason>();
    const float whyLines = 3.0f;
    if (ImGui::BeginChild("steps", ImVec2(0, -ImGui::GetTextLineHeightWithSpacing() * whyLines),
                          true)) {
        size_t step = 0;
        for (size_t i = 0; i < ray.events.size(); ++i) {
            const bool current = i >= s.eventBegin && i < s.eventEnd;
            const std::string line = ray.events[i].toString(scene);
            if (current) {
                ImGui::TextColored(ImVec4(1.0f, 0.85f, 0.1f, 1.0f), "%s", line.c_str());
                if (i == s.eventBegin && play.playing()) ImGui::SetScrollHereY(0.3f);
            } else {
                ImGui::TextDisabled("%s", line.c_str());
            }
            if (ray.events[i].isRegion() && step < why.size()) {
                if (ImGui::IsItemHovered()) {
                    ImGui::BeginTooltip();
                    ImGui::PushTextWrapPos(ImGui::GetFontSize() * 40.0f);
                    ImGui::TextUnformatted(why[step].text.c_str());
                    ImGui::PopTextWrapPos();
                    ImGui::EndTooltip();
                }
                ++step;
            }
        }
    }
    ImGui::EndChild();
    if (s.step >= 0 && size_t(s.step) < why.size())
        ImGui::TextWrapped("why: %s", why[size_t(s.step)].text.c_str());
    ImGui::End();
}

}  // namespace lancer::viewer
