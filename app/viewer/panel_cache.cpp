#include "app/viewer/panel_cache.h"

#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

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

/// Draw `lists` through ImGui's OpenGL backend into the bound framebuffer, which shows the
/// rectangle at `pos` of `size` (framebuffer pixels).
void drawLists(std::vector<ImDrawList*>& lists, ImVec2 pos, ImVec2 size) {
    ImDrawData dd;
    dd.Valid = true;
    dd.CmdLists = lists.data();
    dd.CmdListsCount = int(lists.size());
    for (const ImDrawList* l : lists) {
        dd.TotalVtxCount += l->VtxBuffer.Size;
        dd.TotalIdxCount += l->IdxBuffer.Size;
    }
    dd.DisplayPos = pos;
    dd.DisplaySize = size;
    dd.FramebufferScale = ImVec2(1.0f, 1.0f);
    ImGui_ImplOpenGL3_RenderDrawData(&dd);
}

}  // namespace

PanelCache::~PanelCache() {
    for (auto& [id, e] : entries_) {
        glDeleteFramebuffers(1, &e.fbo);
        glDeleteTextures(1, &e.tex);
    }
}

void PanelCache::render(ImDrawData* dd, int fbWidth, int fbHeight) {
    redrawn_ = 0;
    if (!dd || fbWidth <= 0 || fbHeight <= 0) return;
    const ImVec2 scale = dd->FramebufferScale;
    // A rounded panel leaves its corners transparent in its texture: draw everything directly.
    const ImGuiStyle& style = ImGui::GetStyle();
    if (style.WindowRounding > 0.0f || style.PopupRounding > 0.0f) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        ImGui_ImplOpenGL3_RenderDrawData(dd);
        return;
    }
    // Which top-level window each draw list belongs to.
    std::unordered_map<const ImDrawList*, ImGuiWindow*> owner;
    for (ImGuiWindow* w : ImGui::GetCurrentContext()->Windows)
        if (w->Active && !w->Hidden) owner[w->DrawList] = w->RootWindow;
    for (auto& [id, e] : entries_) e.used = false;

    // The lists in drawing order, each run of one window's lists as one panel.
    std::vector<ImDrawList*> group;
    ImGuiWindow* groupWindow = nullptr;
    auto flush = [&] {
        if (group.empty()) return;
        if (!groupWindow || (groupWindow->Flags & ImGuiWindowFlags_NoBackground)) {
            // No window, or one that lets the image show through: drawn directly.
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            ImDrawData direct = *dd;
            direct.CmdLists = group.data();
            direct.CmdListsCount = int(group.size());
            ImGui_ImplOpenGL3_RenderDrawData(&direct);
            group.clear();
            return;
        }
        // The panel's rectangle in framebuffer pixels, inside the framebuffer.
        const ImVec2 p = groupWindow->Pos, s = groupWindow->Size;
        const int x0 = std::max(0, int(std::floor((p.x - dd->DisplayPos.x) * scale.x)));
        const int y0 = std::max(0, int(std::floor((p.y - dd->DisplayPos.y) * scale.y)));
        const int x1 = std::min(fbWidth, int(std::ceil((p.x + s.x - dd->DisplayPos.x) * scale.x)));
        const int y1 = std::min(fbHeight, int(std::ceil((p.y + s.y - dd->DisplayPos.y) * scale.y)));
        if (x1 > x0 && y1 > y0) {
            uint64_t h = 1469598103934665603ull;
            const int rect[4] = {x0, y0, x1, y1};
            h = hashBytes(h, rect, sizeof rect);
            for (const ImDrawList* l : group) h = hashList(h, *l);
            Entry& e = entries_[groupWindow->ID];
            e.used = true;
            const int w = x1 - x0, hh = y1 - y0;
            if (e.tex == 0) {
                glGenTextures(1, &e.tex);
                glGenFramebuffers(1, &e.fbo);
            }
            if (e.w != w || e.h != hh) {
                glBindTexture(GL_TEXTURE_2D, e.tex);
                glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, hh, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                             nullptr);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
                glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
                glBindTexture(GL_TEXTURE_2D, 0);
                glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
                glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D,
                                       e.tex, 0);
                e.hash = 0;
            }
            if (e.hash != h || e.x0 != x0 || e.y0 != y0 || e.w != w || e.h != hh) {
                glBindFramebuffer(GL_FRAMEBUFFER, e.fbo);
                glDisable(GL_SCISSOR_TEST);
                glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
                glClear(GL_COLOR_BUFFER_BIT);
                drawLists(group, ImVec2(dd->DisplayPos.x + float(x0) / scale.x,
                                        dd->DisplayPos.y + float(y0) / scale.y),
                          ImVec2(float(w) / scale.x, float(hh) / scale.y));
                e.hash = h;
                ++redrawn_;
            }
            e.x0 = x0, e.y0 = y0, e.w = w, e.h = hh;
            glBindFramebuffer(GL_READ_FRAMEBUFFER, e.fbo);
            glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
            glDisable(GL_SCISSOR_TEST);
            glBlitFramebuffer(0, 0, w, hh, x0, fbHeight - y1, x1, fbHeight - y0,
                              GL_COLOR_BUFFER_BIT, GL_NEAREST);
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
        }
        group.clear();
    };
    for (int i = 0; i < dd->CmdListsCount; ++i) {
        ImDrawList* l = dd->CmdLists[i];
        auto it = owner.find(l);
        ImGuiWindow* w = it == owner.end() ? nullptr : it->second;
        if (w != groupWindow || !w) flush();
        groupWindow = w;
        group.push_back(l);
    }
    flush();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbWidth, fbHeight);
    // Panels gone since the last frame.
    for (auto it = entries_.begin(); it != entries_.end();) {
        if (!it->second.used) {
            glDeleteFramebuffers(1, &it->second.fbo);
            glDeleteTextures(1, &it->second.tex);
            it = entries_.erase(it);
        } else {
            ++it;
        }
    }
}

}  // namespace lancer::viewer
