#include "app/viewer/panel_cache.h"

#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "app/viewer/gl.h"
#include "engine/util/hash.h"

namespace lancer::viewer {

namespace {

/// Everything a draw list draws: vertices, indices and commands (clip rectangles, textures,
/// counts). Two lists with the same hash draw the same pixels.
uint64_t hashList(uint64_t h, const ImDrawList& l) {
    h = hashBytes(l.VtxBuffer.Data, size_t(l.VtxBuffer.Size) * sizeof(ImDrawVert), h);
    h = hashBytes(l.IdxBuffer.Data, size_t(l.IdxBuffer.Size) * sizeof(ImDrawIdx), h);
    for (const ImDrawCmd& c : l.CmdBuffer) {
        h = hashBytes(&c.ClipRect, sizeof c.ClipRect, h);
        h = hashBytes(&c.TextureId, sizeof c.TextureId, h);
        h = hashBytes(&c.VtxOffset, sizeof c.VtxOffset, h);
        h = hashBytes(&c.IdxOffset, sizeof c.IdxOffset, h);
        h = hashBytes(&c.ElemCount, sizeof c.ElemCount, h);
        const bool callback = c.UserCallback != nullptr;
        h = hashBytes(&callback, sizeof callback, h);
    }
    return h;
}

bool empty(const PixelRect& r) { return r.x1 <= r.x0 || r.y1 <= r.y0; }

/// `r`'s pixels (0 when empty).
double area(const PixelRect& r) {
    return empty(r) ? 0.0 : double(r.x1 - r.x0) * double(r.y1 - r.y0);
}

bool overlap(const PixelRect& a, const PixelRect& b) {
    return a.x0 < b.x1 && b.x0 < a.x1 && a.y0 < b.y1 && b.y0 < a.y1;
}

bool operator==(const PixelRect& a, const PixelRect& b) {
    return a.x0 == b.x0 && a.y0 == b.y0 && a.x1 == b.x1 && a.y1 == b.y1;
}

/// `dd` with only `lists`, drawn by ImGui's backend into the bound framebuffer.
void drawLists(const ImDrawData& dd, std::vector<ImDrawList*>& lists) {
    ImDrawData part = dd;
    part.CmdLists = lists.data();
    part.CmdListsCount = int(lists.size());
    ImGui_ImplOpenGL3_RenderDrawData(&part);
}

}  // namespace

PanelCache::~PanelCache() {
    if (fbo_) glDeleteFramebuffers(1, &fbo_);
    if (tex_) glDeleteTextures(1, &tex_);
}

const std::vector<PixelRect>& PanelCache::layout(ImDrawData* dd, int fbWidth, int fbHeight) {
    dd_ = dd;
    fbWidth_ = fbWidth, fbHeight_ = fbHeight;
    runs_.clear();
    panels_.clear();
    covered_.clear();
    // Drawn directly when a panel's pixels are not all inside its rectangle and opaque: a
    // rounded panel leaves its corners transparent, and at a framebuffer scale other than 1 a
    // panel's anti-aliased border reaches a pixel outside it (blended over the image there,
    // over nothing in the layer).
    const ImGuiStyle& style = ImGui::GetStyle();
    direct_ = !dd || fbWidth <= 0 || fbHeight <= 0 || style.WindowRounding > 0.0f ||
              style.PopupRounding > 0.0f || dd->FramebufferScale.x != 1.0f ||
              dd->FramebufferScale.y != 1.0f;
    if (direct_) return covered_;

    // Which top-level window each draw list belongs to.
    std::unordered_map<const ImDrawList*, const ImGuiWindow*> owner;
    for (const ImGuiWindow* w : ImGui::GetCurrentContext()->Windows)
        if (w->Active && !w->Hidden) owner[w->DrawList] = w->RootWindow;
    for (int i = 0; i < dd->CmdListsCount; ++i) {
        ImDrawList* l = dd->CmdLists[i];
        auto it = owner.find(l);
        const ImGuiWindow* w = it == owner.end() ? nullptr : it->second;
        if (w && (w->Flags & ImGuiWindowFlags_NoBackground)) w = nullptr;
        if (runs_.empty() || runs_.back().window != w || !w) runs_.push_back({w, {}, -1});
        runs_.back().lists.push_back(l);
    }
    for (Run& r : runs_) {
        if (!r.window) continue;
        const ImVec2 s = r.window->Size;
        const ImVec2 p(r.window->Pos.x - dd->DisplayPos.x, r.window->Pos.y - dd->DisplayPos.y);
        Panel q;
        q.id = r.window->ID;
        q.rect = {std::max(0, int(std::floor(p.x))), std::max(0, int(std::floor(p.y))),
                  std::min(fbWidth, int(std::ceil(p.x + s.x))),
                  std::min(fbHeight, int(std::ceil(p.y + s.y)))};
        q.hash = kHashStart;
        for (const ImDrawList* l : r.lists) q.hash = hashList(q.hash, *l);
        r.panel = int(panels_.size());
        panels_.push_back(q);
        if (!empty(q.rect)) covered_.push_back(q.rect);
    }
    return covered_;
}

PanelCache::Plan PanelCache::plan() const {
    // The layer must hold, under every panel's rectangle, the topmost panel there as it is
    // now. A panel is drawn again when it is new, moved or resized (its rectangle in the layer
    // is stale), when a panel of the last frame that vanished or moved overlapped it (that
    // panel's pixels are left in the layer), when a panel drawn again below it overlaps it
    // (drawing that one covers its pixels), and when its content changed. Only the last is
    // optional: with the frame's budget spent it waits for a later frame, the layer showing
    // its last content meanwhile. A change of the panels' order, or of the layer's size,
    // redraws them all.
    Plan p;
    bool redrawAll = w_ != fbWidth_ || h_ != fbHeight_;
    p.need.assign(panels_.size(), redrawAll ? kMust : kNone);
    p.lastOf.assign(panels_.size(), SIZE_MAX);
    std::vector<char> matched(last_.size(), 0);
    for (size_t i = 0; !redrawAll && i < panels_.size(); ++i) {
        for (size_t j = 0; j < last_.size(); ++j)
            if (last_[j].id == panels_[i].id) p.lastOf[i] = j;
        if (p.lastOf[i] == SIZE_MAX) {
            p.need[i] = kMust;
            continue;
        }
        const Panel& was = last_[p.lastOf[i]];
        if (!(was.rect == panels_[i].rect)) {
            p.need[i] = kMust;
            continue;
        }
        matched[p.lastOf[i]] = 1;
        if (was.hash != panels_[i].hash ||
            std::find(invalid_.begin(), invalid_.end(), panels_[i].id) != invalid_.end())
            p.need[i] = kContent;
    }
    for (size_t i = 1; !redrawAll && i < panels_.size(); ++i)  // the order kept
        for (size_t k = 0; k < i; ++k)
            if (p.lastOf[i] != SIZE_MAX && p.lastOf[k] != SIZE_MAX && p.lastOf[k] > p.lastOf[i])
                redrawAll = true;
    if (redrawAll) std::fill(p.need.begin(), p.need.end(), char(kMust));
    for (size_t j = 0; j < last_.size(); ++j) {  // vanished or moved: its old place is stale
        if (matched[j]) continue;
        for (size_t i = 0; i < panels_.size(); ++i)
            if (overlap(last_[j].rect, panels_[i].rect)) p.need[i] = kMust;
    }
    return p;
}

double PanelCache::estimateMs() const {
    if (!dd_) return 0.0;
    if (direct_) return copyCost_.estimateMs(1);
    // The panels drawn whatever the budget: those that must be, and those above them that
    // they overlap.
    const Plan p = plan();
    std::vector<char> drawn(panels_.size(), 0);
    double pixels = 0.0;
    for (size_t i = 0; i < panels_.size(); ++i) {
        if (p.need[i] == kMust) drawn[i] = 1;
        if (!drawn[i]) continue;
        pixels += area(panels_[i].rect);
        for (size_t j = i + 1; j < panels_.size(); ++j)
            if (overlap(panels_[i].rect, panels_[j].rect)) drawn[j] = 1;
    }
    return copyCost_.estimateMs(1) + redrawCost_.estimateMs(pixels);
}

void PanelCache::render() {
    redrawn_ = 0;
    deferred_ = 0;
    if (!dd_) return;
    const double start = budget_ ? budget_->spentMs() : 0.0;
    double redrawMs = 0.0;  // of the panels drawn again, learned apart from the copies
    if (direct_) {
        last_.clear();
        invalid_.clear();
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        ImGui_ImplOpenGL3_RenderDrawData(dd_);
        if (budget_) {
            glFinish();  // timed: the panels are drawn
            copyCost_.record(1, budget_->spentMs() - start);
        }
        return;
    }
    const int fbWidth = fbWidth_, fbHeight = fbHeight_;
    Plan p = plan();
    std::vector<char>& need = p.need;
    const std::vector<size_t>& lastOf = p.lastOf;
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
    }
    // Which are drawn: bottom to top, a content change within the budget; each drawn panel
    // makes the ones above it that it overlaps drawn too.
    std::vector<char> dirty(panels_.size(), 0);
    std::vector<unsigned> stillInvalid;
    // Each panel's patience, kept for the frame's panels only (a closed one's is dropped).
    std::vector<std::pair<unsigned, Patience>> patience;
    patience.reserve(panels_.size());
    for (const Panel& panel : panels_) {
        auto it = std::find_if(patience_.begin(), patience_.end(),
                               [&](const auto& e) { return e.first == panel.id; });
        patience.emplace_back(panel.id,
                              it != patience_.end() ? it->second : Patience("a panel's redraw"));
    }
    patience_ = std::move(patience);
    for (size_t i = 0; i < panels_.size(); ++i) {
        if (need[i] == kContent && !dirty[i] && budget_ &&
            !budget_->fits(redrawEstimateMs(area(panels_[i].rect)),
                           budgetReserveMs_ + copyCost_.estimateMs(1), patience_[i].second)) {
            ++deferred_;
            if (std::find(invalid_.begin(), invalid_.end(), panels_[i].id) != invalid_.end())
                stillInvalid.push_back(panels_[i].id);
            panels_[i].hash = last_[lastOf[i]].hash;  // still the layer's content
            continue;
        }
        if (need[i] != kNone) dirty[i] = 1;
        if (!dirty[i]) continue;
        for (size_t j = i + 1; j < panels_.size(); ++j)
            if (overlap(panels_[i].rect, panels_[j].rect)) dirty[j] = 1;
    }

    for (Run& r : runs_) {
        if (r.panel < 0) {
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            drawLists(*dd_, r.lists);
            continue;
        }
        const PixelRect& q = panels_[size_t(r.panel)].rect;
        if (empty(q)) continue;                                  // off the framebuffer
        const int gy0 = fbHeight - q.y1, gy1 = fbHeight - q.y0;  // GL's rows go up
        if (dirty[size_t(r.panel)]) {
            // Into the layer as ImGui draws on the framebuffer: the same projection and pixels.
            glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
            glEnable(GL_SCISSOR_TEST);
            glScissor(q.x0, gy0, q.x1 - q.x0, q.y1 - q.y0);
            glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
            glClear(GL_COLOR_BUFFER_BIT);
            glDisable(GL_SCISSOR_TEST);
            const double redrawStart = budget_ ? budget_->spentMs() : 0.0;
            drawLists(*dd_, r.lists);
            ++redrawn_;
            // Drawn now (the blit below reads it), so the budget sees what the redraw cost.
            if (budget_) {
                glFinish();
                const double ms = budget_->spentMs() - redrawStart;
                redrawCost_.record(area(q), ms);
                redrawMs += ms;
            }
        }
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        glDisable(GL_SCISSOR_TEST);
        glBlitFramebuffer(q.x0, gy0, q.x1, gy1, q.x0, gy0, q.x1, gy1, GL_COLOR_BUFFER_BIT,
                          GL_NEAREST);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbWidth, fbHeight);
    if (budget_) {
        glFinish();  // timed: the copies are done
        copyCost_.record(1, budget_->spentMs() - start - redrawMs);
    }
    last_ = panels_;
    invalid_ = std::move(stillInvalid);
}

}  // namespace lancer::viewer
