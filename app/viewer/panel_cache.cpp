#include "app/viewer/panel_cache.h"

#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "app/viewer/gl.h"

namespace lancer::viewer {

namespace {

/// FNV-1a over bytes, continued from `h`.
uint64_t hashBytes(uint64_t h, const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 1099511628211ull;
    return h;
}

/// Everything a draw list draws: vertices, indices and commands (clip rectangles, textures,
/// counts). Two lists with the same hash draw the same pixels.
uint64_t hashList(uint64_t h, const ImDrawList& l) {
    h = hashBytes(h, l.VtxBuffer.Data, size_t(l.VtxBuffer.Size) * sizeof(ImDrawVert));
    h = hashBytes(h, l.IdxBuffer.Data, size_t(l.IdxBuffer.Size) * sizeof(ImDrawIdx));
    for (const ImDrawCmd& c : l.CmdBuffer) {
        h = hashBytes(h, &c.ClipRect, sizeof c.ClipRect);
        h = hashBytes(h, &c.TextureId, sizeof c.TextureId);
        h = hashBytes(h, &c.VtxOffset, sizeof c.VtxOffset);
        h = hashBytes(h, &c.IdxOffset, sizeof c.IdxOffset);
        h = hashBytes(h, &c.ElemCount, sizeof c.ElemCount);
        const bool callback = c.UserCallback != nullptr;
        h = hashBytes(h, &callback, sizeof callback);
    }
    return h;
}

bool overlap(int ax0, int ay0, int ax1, int ay1, int bx0, int by0, int bx1, int by1) {
    return ax0 < bx1 && bx0 < ax1 && ay0 < by1 && by0 < ay1;
}

}  // namespace

PanelCache::~PanelCache() {
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    if (tex_) glDeleteTextures(1, &tex_);
}

void PanelCache::render(ImDrawData* dd, int fbWidth, int fbHeight) {
    redrawn_ = 0;
    if (!dd || fbWidth <= 0 || fbHeight <= 0) return;
    // Drawn directly when a panel's pixels are not all inside its rectangle and opaque: a
    // rounded panel leaves its corners transparent, and at a framebuffer scale other than 1 a
    // panel's anti-aliased border reaches a pixel outside it (blended over the image there,
    // over nothing in the layer).
    const ImGuiStyle& style = ImGui::GetStyle();
    if (style.WindowRounding > 0.0f || style.PopupRounding > 0.0f ||
        dd->FramebufferScale.x != 1.0f || dd->FramebufferScale.y != 1.0f) {
        last_.clear();
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        ImGui_ImplOpenGL3_RenderDrawData(dd);
        return;
    }
    bool redrawAll = false;
    if (w_ != fbWidth || h_ != fbHeight) {
        if (!tex_) {
            glGenTextures(1, &tex_);
            glGenFramebuffers(1, &fbo_);
        }
        glBindTexture(GL_TEXTURE_2D, tex_);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, fbWidth, fbHeight, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                     nullptr);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glBindTexture(GL_TEXTURE_2D, 0);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, tex_, 0);
        w_ = fbWidth, h_ = fbHeight;
        redrawAll = true;
    }

    // Which top-level window each draw list belongs to.
    std::unordered_map<const ImDrawList*, ImGuiWindow*> owner;
    for (ImGuiWindow* w : ImGui::GetCurrentContext()->Windows)
        if (w->Active && !w->Hidden) owner[w->DrawList] = w->RootWindow;

    // The draw data as runs: a panel's lists (a window and its children), or lists drawn
    // directly (no window, or a window without a background).
    struct Run {
        ImGuiWindow* window = nullptr;
        std::vector<ImDrawList*> lists;
        Panel panel;
    };
    std::vector<Run> runs;
    for (int i = 0; i < dd->CmdListsCount; ++i) {
        ImDrawList* l = dd->CmdLists[i];
        auto it = owner.find(l);
        ImGuiWindow* w = it == owner.end() ? nullptr : it->second;
        if (w && (w->Flags & ImGuiWindowFlags_NoBackground)) w = nullptr;
        if (runs.empty() || runs.back().window != w || !w) runs.push_back({w, {}, {}});
        runs.back().lists.push_back(l);
    }
    const ImVec2 scale = dd->FramebufferScale;
    std::vector<Panel> panels;
    for (Run& r : runs) {
        if (!r.window) continue;
        const ImVec2 p = r.window->Pos, s = r.window->Size;
        Panel& q = r.panel;
        q.id = r.window->ID;
        q.x0 = std::max(0, int(std::floor((p.x - dd->DisplayPos.x) * scale.x)));
        q.y0 = std::max(0, int(std::floor((p.y - dd->DisplayPos.y) * scale.y)));
        q.x1 = std::min(fbWidth, int(std::ceil((p.x + s.x - dd->DisplayPos.x) * scale.x)));
        q.y1 = std::min(fbHeight, int(std::ceil((p.y + s.y - dd->DisplayPos.y) * scale.y)));
        q.hash = 1469598103934665603ull;
        for (const ImDrawList* l : r.lists) q.hash = hashList(q.hash, *l);
        panels.push_back(q);
    }
    // A panel that moved, appeared, vanished or changed places leaves the layer stale where it
    // was: then every panel is drawn again (windows move rarely; a tooltip follows the mouse).
    bool sameLayout = panels.size() == last_.size();
    for (size_t i = 0; sameLayout && i < panels.size(); ++i) {
        const Panel &a = panels[i], &b = last_[i];
        sameLayout = a.id == b.id && a.x0 == b.x0 && a.y0 == b.y0 && a.x1 == b.x1 && a.y1 == b.y1;
    }
    if (!sameLayout) redrawAll = true;
    // Otherwise a panel whose content changed is drawn again, with every panel above that
    // overlaps it (drawing it covers their pixels in the layer).
    std::vector<char> dirty(panels.size(), redrawAll ? 1 : 0);
    for (size_t i = 0; !redrawAll && i < panels.size(); ++i) {
        if (panels[i].hash != last_[i].hash) dirty[i] = 1;
        if (!dirty[i]) continue;
        for (size_t j = i + 1; j < panels.size(); ++j)
            if (overlap(panels[i].x0, panels[i].y0, panels[i].x1, panels[i].y1, panels[j].x0,
                        panels[j].y0, panels[j].x1, panels[j].y1))
                dirty[j] = 1;
    }

    size_t k = 0;  // index of the next panel
    for (Run& r : runs) {
        if (!r.window) {
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            ImDrawData direct = *dd;
            direct.CmdLists = r.lists.data();
            direct.CmdListsCount = int(r.lists.size());
            ImGui_ImplOpenGL3_RenderDrawData(&direct);
            continue;
        }
        const Panel& q = panels[k];
        const bool redraw = dirty[k++] != 0;
        if (q.x1 <= q.x0 || q.y1 <= q.y0) continue;  // off the framebuffer
        if (redraw) {
            // Into the layer as ImGui draws on the framebuffer: the same projection and pixels.
            glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
            glEnable(GL_SCISSOR_TEST);
            glScissor(q.x0, fbHeight - q.y1, q.x1 - q.x0, q.y1 - q.y0);
            glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
            glClear(GL_COLOR_BUFFER_BIT);
            glDisable(GL_SCISSOR_TEST);
            ImDrawData one = *dd;
            one.CmdLists = r.lists.data();
            one.CmdListsCount = int(r.lists.size());
            ImGui_ImplOpenGL3_RenderDrawData(&one);
            ++redrawn_;
        }
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        glDisable(GL_SCISSOR_TEST);
        const int gy0 = fbHeight - q.y1, gy1 = fbHeight - q.y0;  // GL's rows go up
        glBlitFramebuffer(q.x0, gy0, q.x1, gy1, q.x0, gy0, q.x1, gy1, GL_COLOR_BUFFER_BIT,
                          GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbWidth, fbHeight);
    last_ = std::move(panels);
}

}  // namespace lancer::viewer
