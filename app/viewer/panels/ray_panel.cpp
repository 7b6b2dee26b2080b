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

/// An operator's sign drawn with lines (the font has no ∪ ∩ −), in a box of side `sz` at `at`.
void opIcon(ImDrawList* dl, ImVec2 at, float sz, Op op, ImU32 col) {
    const float l = at.x + 1.0f, r = at.x + sz - 2.0f, t = at.y + 2.0f, b = at.y + sz - 2.0f;
    const float mx = 0.5f * (l + r), rad = 0.5f * (r - l);
    switch (op) {
        case Op::Union:
            dl->PathLineTo(ImVec2(l, t));
            dl->PathArcTo(ImVec2(mx, b - rad), rad, 3.14159265f, 0.0f, 10);
            dl->PathLineTo(ImVec2(r, t));
            dl->PathStroke(col, 0, 1.5f);
            break;
        case Op::Intersection:
            dl->PathLineTo(ImVec2(l, b));
            dl->PathArcTo(ImVec2(mx, t + rad), rad, 3.14159265f, 2.0f * 3.14159265f, 10);
            dl->PathLineTo(ImVec2(r, b));
            dl->PathStroke(col, 0, 1.5f);
            break;
        case Op::Difference:
            dl->AddLine(ImVec2(l, 0.5f * (t + b)), ImVec2(r, 0.5f * (t + b)), col, 1.5f);
            break;
        case Op::Primitive:
            break;
    }
}

/// The t range a strip shows: [lo, hi] widened to every finite span end and the hit, from the
/// ray's tmin, padded.
void stripRange(const std::vector<playback::StripRow>& rows, const TracedRay& ray, double& lo,
                double& hi) {
    for (const playback::StripRow& r : rows)
        for (const Span& sp : r.spans)
            for (double t : {sp.in.t, sp.out.t})
                if (std::isfinite(t)) lo = std::min(lo, t), hi = std::max(hi, t);
    if (ray.hit.valid()) hi = std::max(hi, ray.hit.t);
    lo = std::max(lo, ray.tmin);
    if (!(hi > lo)) hi = lo + 1.0;
    const double pad = 0.03 * (hi - lo);
    lo -= pad;
    hi += pad;
}

/// The label of a strip row: "p3", "p3 mb", "p3 repeat" (waste), a node's operator sign
/// indented by depth (drawn, its text empty) or a leaf's "p3".
std::string rowLabel(const playback::StripRow& r) {
    std::string s;
    if (r.node && r.op != Op::Primitive) return s;
    if (r.node && r.prim == kNoPrim) return "result";
    s = "p" + std::to_string(r.prim);
    if (!r.node && r.mailbox) s += " mb";
    if (!r.node && r.waste != Waste::None) s += std::string(" ") + wasteName(r.waste);
    return s;
}

/// A strip: rows of spans on a t axis [lo, hi]; `bands` (the whole ray's regions) shaded
/// alternately under the rows with their ids in a top row, the current one lit, and `stretch`
/// (the current region's, when no bands) shaded; the hit as a vertical line; flipped boundaries
/// (a difference's subtrahend exposing its inside) as small ticks. Returns the step of the
/// band clicked, or -1.
int drawStrip(const std::vector<playback::StripRow>& rows,
              const std::vector<playback::StripBand>& bands, const walk::Region* stretch, double lo,
              double hi, const TracedRay& ray, int currentStep, const char* id) {
    const float labelW = 118.0f, rowH = 14.0f;
    const float top = bands.empty() ? 0.0f : rowH;
    const float h = top + rowH * float(rows.size() + 1);
    int clicked = -1;
    const float childH = std::min(h + 4.0f, 170.0f);
    if (!ImGui::BeginChild(id, ImVec2(0, childH), false)) {
        ImGui::EndChild();
        return clicked;
    }
    const ImVec2 origin = ImGui::GetCursorScreenPos();
    const float w = std::max(ImGui::GetContentRegionAvail().x - labelW, 50.0f);
    ImDrawList* dl = ImGui::GetWindowDrawList();
    auto X = [&](double t) {
        return origin.x + labelW + float((std::clamp(t, lo, hi) - lo) / (hi - lo)) * w;
    };
    const float bottom = origin.y + top + rowH * float(rows.size());
    // The regions' stretches, alternately shaded, the current one lit; their ids on top.
    for (size_t i = 0; i < bands.size(); ++i) {
        const playback::StripBand& b = bands[i];
        const double t1 = std::isfinite(b.t1) ? b.t1 : hi;
        const float x0 = X(b.t0), x1 = std::max(X(t1), x0 + 1.0f);
        const bool current = b.step == currentStep;
        const ImU32 shade = current ? IM_COL32(255, 216, 26, 60)
                            : i % 2 ? IM_COL32(255, 255, 255, 14)
                                    : IM_COL32(255, 255, 255, 30);
        dl->AddRectFilled(ImVec2(x0, origin.y), ImVec2(x1, bottom), shade);
        const std::string rid = std::to_string(b.region);
        if (ImGui::CalcTextSize(rid.c_str()).x + 2.0f < x1 - x0)
            dl->AddText(ImVec2(x0 + 1.0f, origin.y),
                        current ? IM_COL32(255, 216, 26, 255) : IM_COL32(170, 170, 170, 255),
                        rid.c_str());
        const ImVec2 m = ImGui::GetIO().MousePos;
        if (ImGui::IsWindowHovered() && m.x >= x0 && m.x < x1 && m.y >= origin.y && m.y < bottom) {
            ImGui::SetTooltip("region %u, step %d: t = [%.6g, %.6g]", b.region, b.step + 1, b.t0,
                              b.t1);
            if (ImGui::IsMouseClicked(ImGuiMouseButton_Left)) clicked = b.step;
        }
    }
    if (!bands.empty())
        dl->AddText(ImVec2(origin.x, origin.y), IM_COL32(170, 170, 170, 255), "regions");
    if (stretch) {
        const double t1 = std::isfinite(stretch->t1) ? stretch->t1 : hi;
        dl->AddRectFilled(ImVec2(X(stretch->t0), origin.y), ImVec2(X(t1), bottom),
                          IM_COL32(255, 216, 26, 40));
    }
    for (size_t i = 0; i < rows.size(); ++i) {
        const playback::StripRow& r = rows[i];
        const float y = origin.y + top + rowH * float(i);
        const bool dim = !r.evaluated;
        const float indent = r.node ? 9.0f * float(r.depth) : 0.0f;
        const ImU32 text = dim || r.mailbox         ? IM_COL32(140, 140, 140, 255)
                           : r.waste != Waste::None ? IM_COL32(255, 150, 90, 255)
                                                    : IM_COL32(230, 230, 230, 255);
        if (r.onHit)
            dl->AddRectFilled(ImVec2(origin.x, y + 1.0f), ImVec2(origin.x + 3.0f, y + rowH - 1.0f),
                              IM_COL32(40, 255, 80, 255));
        const ImVec2 at(origin.x + 5.0f + indent, y);
        if (r.node && r.op != Op::Primitive)
            opIcon(dl, at, rowH - 1.0f, r.op, text);
        else
            dl->AddText(at, text, rowLabel(r).c_str());
        dl->AddLine(ImVec2(origin.x + labelW, y + rowH * 0.5f),
                    ImVec2(origin.x + labelW + w, y + rowH * 0.5f),
                    dim ? IM_COL32(60, 60, 60, 255) : IM_COL32(80, 80, 80, 255));
        const ImU32 fill =
            r.node && r.prim == kNoPrim && r.op == Op::Primitive
                ? IM_COL32(255, 60, 220, 255)  // the whole ray's result
            : r.node && r.op != Op::Primitive
                ? (r.depth == 0 ? IM_COL32(255, 60, 220, 255) : IM_COL32(220, 120, 230, 255))
            : r.mailbox || r.node ? IM_COL32(110, 110, 140, 255)
                                  : IM_COL32(90, 160, 255, 255);
        for (const Span& sp : r.spans) {
            const float x0 = X(sp.in.t), x1 = std::max(X(sp.out.t), x0 + 2.0f);
            dl->AddRectFilled(ImVec2(x0, y + 3.0f), ImVec2(x1, y + rowH - 3.0f), fill);
            // A boundary a difference turned inside out: the subtrahend's surface exposed.
            for (const Boundary* bd : {&sp.in, &sp.out})
                if (bd->flip && bd->t >= lo && bd->t <= hi) {
                    const float bx = X(bd->t);
                    dl->AddTriangleFilled(ImVec2(bx - 3.0f, y), ImVec2(bx + 3.0f, y),
                                          ImVec2(bx, y + 4.0f), IM_COL32(255, 170, 40, 255));
                }
        }
        if (dim)
            dl->AddText(ImVec2(origin.x + labelW + 4.0f, y), IM_COL32(110, 110, 110, 255),
                        "not evaluated");
        const ImVec2 m = ImGui::GetIO().MousePos;
        if (ImGui::IsWindowHovered() && m.y >= y && m.y < y + rowH && m.x >= origin.x &&
            m.x < origin.x + labelW + w) {
            std::string tip = r.node && r.op != Op::Primitive ? opName(r.op) : rowLabel(r);
            tip += dim ? ": not evaluated (an empty left operand)" : ": " + toString(r.spans);
            ImGui::SetTooltip("%s", tip.c_str());
        }
    }
    if (ray.hit.valid() && ray.hit.t >= lo && ray.hit.t <= hi)
        dl->AddLine(ImVec2(X(ray.hit.t), origin.y + top), ImVec2(X(ray.hit.t), bottom),
                    IM_COL32(40, 255, 80, 255), 2.0f);
    // The axis: its two ends' t.
    char buf[64];
    std::snprintf(buf, sizeof buf, "t %.4g", lo);
    dl->AddText(ImVec2(origin.x + labelW, bottom), IM_COL32(200, 200, 200, 255), buf);
    std::snprintf(buf, sizeof buf, "%.4g", hi);
    dl->AddText(ImVec2(origin.x + labelW + w - ImGui::CalcTextSize(buf).x, bottom),
                IM_COL32(200, 200, 200, 255), buf);
    ImGui::Dummy(ImVec2(labelW + w, h));
    ImGui::EndChild();
    return clicked;
}

/// The CSG along the ray in the current step: one row per primitive read (tested, or from the
/// mailbox greyed, each wasted test tagged), then the region's restricted tree node by node in
/// pre-order (operators indented by depth, the nodes the evaluator skipped dimmed), on a t axis
/// covering the region's stretch (shaded) and every finite span end; the hit's chain marked.
void regionCsgStrip(playback::RayPlayer& player) {
    const playback::RayPlayback& play = player.playback();
    const walk::Region* region = play.region();
    if (!region) return;
    const std::vector<StepCsg>& steps = player.csgSteps();
    const int k = play.state().step;
    if (k < 0 || size_t(k) >= steps.size()) return;
    const std::vector<playback::StripRow> rows =
        playback::regionStrip(steps, player.waste(), play.ray(), k);
    if (rows.empty()) {
        hintText("No primitive read in this region.");
        return;
    }
    if (steps[size_t(k)].carried)
        hintText("The region shares the previous one's restricted tree: its spans are reused.");
    double lo = region->t0, hi = std::isfinite(region->t1) ? region->t1 : region->t0;
    stripRange(rows, play.ray(), lo, hi);
    drawStrip(rows, {}, region, lo, hi, play.ray(), k, "region strip");
}

/// The whole ray: every region's stretch (alternately shaded, ids on top; a click plays that
/// step), each primitive read along the ray and the result the walk used in each region.
void rayCsgStrip(playback::RayPlayer& player) {
    playback::RayPlayback& play = player.playback();
    const std::vector<StepCsg>& steps = player.csgSteps();
    if (steps.empty()) return;
    const playback::RayStrip strip = playback::rayStrip(steps, player.waste(), play.ray());
    double lo = strip.bands.front().t0, hi = lo;
    for (const playback::StripBand& b : strip.bands)
        if (std::isfinite(b.t1)) hi = std::max(hi, b.t1);
    stripRange(strip.rows, play.ray(), lo, hi);
    const int clicked = drawStrip(strip.rows, strip.bands, nullptr, lo, hi, play.ray(),
                                  play.state().step, "ray strip");
    if (clicked >= 0) {
        play.pause();
        play.seek(clicked);
    }
}

}  // namespace

/// Rows of the "Worst rays" list.
constexpr size_t kWorstRays = 20;

/// The costliest pixels of the complete image on screen, ranked by tests, region visits or
/// time; a row picks its pixel (its ray tree is then traced and played).
void worstRays(ViewerState& st, playback::RayPlayer& player) {
    PanelNotes& notes = st.notes();
    ImGui::SetNextItemOpen(notes.worstOpen);
    notes.worstOpen = ImGui::CollapsingHeader("Worst rays");
    notes.worstFirstRow[0] = notes.worstFirstRow[1] = -1.0f;
    if (!notes.worstOpen) return;
    static const char* by[] = {"prim tests", "region visits", "time"};
    ImGui::SetNextItemWidth(140);
    ImGui::Combo("ranked by", &notes.worstBy, by, 3);
    if (!st.shownComplete()) {
        hintText("listed once the image is complete");
        return;
    }
    if (notes.worstJob != st.shownJob() || notes.worstListedBy != notes.worstBy) {
        notes.worst =
            playback::costliestPixels(st.shown(), playback::RayCost(notes.worstBy), kWorstRays);
        notes.worstJob = st.shownJob();
        notes.worstListedBy = notes.worstBy;
    }
    const float rowH = ImGui::GetTextLineHeightWithSpacing();
    const ImGuiTableFlags flags = ImGuiTableFlags_Borders | ImGuiTableFlags_RowBg |
                                  ImGuiTableFlags_ScrollY | ImGuiTableFlags_SizingStretchProp;
    if (!ImGui::BeginTable("worst", 4, flags, ImVec2(0, rowH * 8.5f))) return;
    ImGui::TableSetupScrollFreeze(0, 1);
    ImGui::TableSetupColumn("pixel");
    ImGui::TableSetupColumn("tests");
    ImGui::TableSetupColumn("visits");
    ImGui::TableSetupColumn("µs");
    ImGui::TableHeadersRow();
    const playback::RayPlayback& play = player.playback();
    for (size_t i = 0; i < notes.worst.size(); ++i) {
        const playback::CostlyPixel& p = notes.worst[i];
        ImGui::TableNextRow();
        ImGui::TableNextColumn();
        char label[32];
        std::snprintf(label, sizeof label, "%d %d##w%zu", p.x, p.y, i);
        const bool picked = !play.empty() && play.pixel().x == p.x && play.pixel().y == p.y;
        if (ImGui::Selectable(label, picked, ImGuiSelectableFlags_SpanAllColumns))
            player.pick(p.x, p.y);
        if (i == 0) {
            const ImVec2 lo = ImGui::GetItemRectMin(), hi = ImGui::GetItemRectMax();
            notes.worstFirstRow[0] = 0.5f * (lo.x + hi.x);
            notes.worstFirstRow[1] = 0.5f * (lo.y + hi.y);
        }
        ImGui::TableNextColumn();
        ImGui::Text("%u", p.tests);
        ImGui::TableNextColumn();
        ImGui::Text("%u", p.visits);
        ImGui::TableNextColumn();
        ImGui::Text("%.1f", double(p.us));
    }
    ImGui::EndTable();
}

/// The step list's least height, in lines: a user reads the steps around the current one.
constexpr float kStepLines = 8.5f;

void rayPanel(ViewerState& st, playback::RayPlayer& player, bool* open) {
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
    const char* hint = "or Shift+click the image";
    // In a narrow column the hint goes under the button rather than a letter a line.
    if (ImGui::GetContentRegionAvail().x < ImGui::CalcTextSize(hint).x) ImGui::NewLine();
    hintText(hint);
    errorText(player.note().rfind("pixel", 0) == 0 ? player.note() : "");
    worstRays(st, player);
    if (play.empty()) {
        ImGui::End();
        return;
    }
    const Scene* scene = st.sceneBuild() ? st.sceneBuild()->scene.get() : nullptr;
    const RayTree& tree = play.tree();
    ImGui::TextWrapped("%s", tree.counters.toString().c_str());

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
    ImGui::SetNextItemWidth(80);
    if (ImGui::SliderFloat("steps/s", &speed, 0.1f, 20.0f, "%.1f", ImGuiSliderFlags_Logarithmic))
        play.setSpeed(speed);
    if (play.stepCount() > 0)
        ImGui::Text("step %d / %d", play.state().step + 1, play.stepCount());
    else
        ImGui::TextUnformatted("walks no region");
    ImGui::SameLine();

    if (ImGui::Button("Copy as trace command")) {
        const std::string file =
            (std::filesystem::temp_directory_path() / "lancer-pick-camera.json").string();
        const std::string cmd = player.copyTraceCommand(st, file);
        if (!cmd.empty()) ImGui::SetClipboardText(cmd.c_str());
    }
    // The filter of both views, on the same line when the column is wide enough.
    const char* only = "only its regions";
    ImGui::SameLine();
    if (ImGui::GetContentRegionAvail().x < ImGui::CalcTextSize(only).x + 40.0f) ImGui::NewLine();
    ImGui::Checkbox(only, &st.settings().rayRegionsOnly);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "Overlays and inspector draw only the regions this ray visits\n"
            "(--show visited). Keys: Left / Right step, Home / End first / last,\n"
            "Space play / pause, Up / Down ray, F frame the step's region.");
    if (player.note().rfind("pixel", 0) != 0 && !player.note().empty())
        hintText(player.note().c_str());
    const TracedRay& ray = play.ray();
    if (std::optional<playback::WalkCounts> was = play.previousCounts(play.state().ray))
        ImGui::TextWrapped("after the rebuild: %s",
                           compareCounts(*was, playback::countsOf(ray)).c_str());

    // The wasted work (docs/viewer.md): the ray's, this step's, and each wasted test's class in
    // the step list.
    const bool analysed = !player.csgSteps().empty();
    const RayWaste& waste = player.waste();
    const int stepNo = play.state().step;
    if (analysed) {
        std::string line = "ray: " + waste.total.toString();
        if (stepNo >= 0 && size_t(stepNo) < waste.perStep.size())
            line += "; this step: " + waste.perStep[size_t(stepNo)].toString();
        ImGui::TextWrapped("%s", line.c_str());
    }

    // The ray's events as `lancer trace` prints them, the current step's lit; each region
    // step's reason (explainSteps: how the walk goes on from it) as its line's tooltip, and the
    // current step's under the list.
    const playback::PlaybackState& s = play.state();
    const std::vector<StepReason> why =
        player.view() ? explainSteps(ray, *player.view(), &player.view()->scene())
                      : std::vector<StepReason>();
    // The list keeps kStepLines lines, and grows into what the panel has beyond what the
    // rest of it (the reason, the rays, the CSG strips) took last frame; the panel scrolls to
    // the rest when it is short.
    static float restHeight = 0.0f;
    const float line = ImGui::GetTextLineHeightWithSpacing();
    const float least = kStepLines * line + 2.0f * ImGui::GetStyle().WindowPadding.y;
    const float listH = std::max(least, ImGui::GetContentRegionAvail().y - restHeight);
    if (ImGui::BeginChild("steps", ImVec2(0, listH), true, ImGuiWindowFlags_HorizontalScrollbar)) {
        size_t step = 0, regionNo = 0;
        for (size_t i = 0; i < ray.events.size(); ++i) {
            const bool current = i >= s.eventBegin && i < s.eventEnd;
            std::string line = ray.events[i].toString(scene);
            if (ray.events[i].isRegion() && regionNo < waste.perStep.size())
                line += "   [" + waste.perStep[regionNo++].toString() + "]";
            if (i < waste.perEvent.size() && waste.perEvent[i] != Waste::None)
                line += std::string("   [wasted: ") + wasteName(waste.perEvent[i]) + "]";
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
    const float restTop = ImGui::GetCursorPosY();
    if (s.step >= 0 && size_t(s.step) < why.size())
        ImGui::TextWrapped("why: %s", why[size_t(s.step)].text.c_str());
    // The tree: one line per ray, as `lancer trace` prints it; a click plays that ray.
    if (ImGui::BeginChild("rays", ImVec2(0, 90), true, ImGuiWindowFlags_HorizontalScrollbar)) {
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

    if (ImGui::CollapsingHeader("CSG in this region", ImGuiTreeNodeFlags_DefaultOpen))
        regionCsgStrip(player);
    if (ImGui::CollapsingHeader("CSG along the whole ray", ImGuiTreeNodeFlags_DefaultOpen))
        rayCsgStrip(player);

    restHeight = ImGui::GetCursorPosY() - restTop;
    ImGui::End();
}

}  // namespace lancer::viewer
