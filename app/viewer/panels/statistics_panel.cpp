#include <imgui.h>

#include "app/viewer/panels/panels.h"

namespace lancer::viewer {

void statisticsPanel(ViewerState& st) {
    ImGuiIO& io = ImGui::GetIO();
    ViewerSettings& s = st.settings();
    const ProgressiveRenderer& renderer = st.renderer();
    ImGui::Text("%d x %d, %d threads, %.0f fps", st.width(), st.height(),
                effectiveThreads(s.threads), io.Framerate);
    std::vector<PassRecord> passes = renderer.passes();
    RayCounters total;
    double renderMs = 0.0;
    if (ImGui::BeginTable("passes", 4,
                          ImGuiTableFlags_Borders | ImGuiTableFlags_SizingStretchProp)) {
        ImGui::TableSetupColumn("pass");
        ImGui::TableSetupColumn("render ms");
        ImGui::TableSetupColumn("since change");
        ImGui::TableSetupColumn("rays");
        ImGui::TableHeadersRow();
        for (const PassRecord& p : passes) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::Text("1/%d", p.stride * p.stride);
            ImGui::TableNextColumn();
            ImGui::Text("%.1f", p.renderMs);
            ImGui::TableNextColumn();
            ImGui::Text("%.1f", p.sinceStartMs);
            ImGui::TableNextColumn();
            ImGui::Text("%llu", (unsigned long long)p.counters.rays);
            total += p.counters;
            renderMs += p.renderMs;
        }
        // A row for each pass still to come, and the progress bar's line while none renders:
        // the panel keeps its height through a render, and the one under it stays put.
        for (size_t i = passes.size(); i < ProgressiveRenderer::kDefaultStrides.size(); ++i) {
            ImGui::TableNextRow();
            ImGui::TableNextColumn();
            ImGui::TextUnformatted("");
        }
        ImGui::EndTable();
    }
    if (st.rendering()) {
        size_t done = 0, count = 0;
        renderer.progress(done, count);
        ImGui::ProgressBar(count ? float(done) / float(count) : 0.0f, ImVec2(-1, 0),
                           "rendering next pass");
    } else {
        ImGui::AlignTextToFramePadding();  // as tall as the progress bar
        ImGui::TextDisabled("%s", st.sceneBuild() ? "render complete" : "nothing to render");
    }
    if (!total.rays) {
        // The lines below kept while a render has no pass yet (a drag starts one each frame):
        // the panel keeps its height, so the panels under it stay put and are not drawn again
        // (moved panels are; 4-5 ms a frame under llvmpipe, 2026-12-06).
        for (const char* line :
             {"rays -", "- Mrays/s", "prim tests / ray    -", "region visits / ray -",
              "mailbox hit rate    -", "unwalked shadow rays -"})
            ImGui::TextDisabled("%s", line);
    } else {
        const double rays = double(total.rays);
        ImGui::Text("rays %llu (%llu primary, %llu shadow)", (unsigned long long)total.rays,
                    (unsigned long long)total.primaryRays, (unsigned long long)total.shadowRays);
        ImGui::Text("%.3f Mrays/s", renderMs > 0 ? rays / renderMs / 1000.0 : 0.0);
        ImGui::Text("prim tests / ray    %.2f", double(total.primTests) / rays);
        ImGui::Text("region visits / ray %.2f", double(total.regionVisits) / rays);
        const double asked = double(total.primTests + total.mailboxHits);
        ImGui::Text("mailbox hit rate    %.1f %%",
                    asked > 0 ? 100.0 * double(total.mailboxHits) / asked : 0.0);
        if (total.shadowRays) {
            // Short enough for the narrowest column; the hover says what it counts.
            ImGui::Text("unwalked shadow rays %.1f %%",
                        100.0 * double(total.lightBufferSkips) / double(total.shadowRays));
            if (ImGui::IsItemHovered())
                ImGui::SetTooltip("Shadow rays the light buffer cleared without a walk");
        }
        if (total.walkErrors)
            ImGui::TextColored(ImVec4(1, 0.4f, 0.4f, 1), "walk errors %llu",
                               (unsigned long long)total.walkErrors);
    }

    ImGui::Separator();
    static const char* strides[] = {"every pixel", "1 in 4", "1 in 16", "1 in 64"};
    int& stride = st.notes().speedupStride;
    int si = stride == 1 ? 0 : stride == 2 ? 1 : stride == 4 ? 2 : 3;
    ImGui::SetNextItemWidth(110);
    if (ImGui::Combo("##sample", &si, strides, 4)) stride = 1 << si;
    ImGui::SameLine();
    if (st.measuringSpeedup()) {
        ImGui::TextUnformatted("measuring...");
    } else if (ImGui::Button("Speedup over brute force") && st.sceneBuild()) {
        st.measureSpeedup(stride);
    }
    if (std::optional<SpeedupResult> r = st.speedupResult()) {
        const bench::Speedup& m = r->speedup;
        if (!r->error.empty())
            ImGui::TextWrapped("%s", r->error.c_str());
        else
            ImGui::TextWrapped(
                "%s %.1f ms, brute %.1f ms on %zu pixels: speedup x%.2f; primitive tests per "
                "ray %.1f against %.1f",
                r->scheme.c_str(), m.scheme.renderMs, m.brute.renderMs, m.pixels, m.ratio(),
                m.schemeTestsPerRay(), m.bruteTestsPerRay());
    }
}

}  // namespace lancer::viewer
