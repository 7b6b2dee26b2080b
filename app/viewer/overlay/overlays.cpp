#include "app/viewer/overlay/overlays.h"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "app/viewer/colormap.h"
#include "app/viewer/gl.h"
#include "app/viewer/gl/transforms.h"
#include "engine/model/csg.h"

namespace lancer::viewer::overlay {

namespace {

std::string boxText(const Box3& b) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "[%.4g %.4g %.4g] .. [%.4g %.4g %.4g]", b.lo.x, b.lo.y, b.lo.z,
                  b.hi.x, b.hi.y, b.hi.z);
    return buf;
}

/// The depth strip (DepthStrip) as a bar the width of about 20 characters: each slab a segment
/// in the colour its wire has in the image (by its index in the zone), the current one framed
/// in white, `depth` (the hit's) marked by a white line, and the depth range written under it.
void depthStripBar(const DepthStrip& s, std::optional<double> depth) {
    if (s.slabs.empty()) return;
    const float w = ImGui::GetFontSize() * 20.0f, h = ImGui::GetFontSize();
    ImDrawList* dl = ImGui::GetWindowDrawList();
    const ImVec2 p = ImGui::GetCursorScreenPos();
    auto x = [&](double z) { return p.x + float(s.at(z)) * w; };
    auto u32 = [](glm::vec3 c) {
        return ImGui::ColorConvertFloat4ToU32(ImVec4(c.x, c.y, c.z, 1.0f));
    };
    const ImU32 white = IM_COL32(255, 255, 255, 255), edge = IM_COL32(20, 20, 20, 255);
    for (size_t k = 0; k < s.slabs.size(); ++k) {
        const float x0 = x(s.slabs[k].z0), x1 = std::max(x(s.slabs[k].z1), x0 + 1.0f);
        dl->AddRectFilled({x0, p.y}, {x1, p.y + h}, u32(levelColor(int(k))));
        if (k > 0) dl->AddLine({x0, p.y}, {x0, p.y + h}, edge);
    }
    if (s.current >= 0) {
        const DepthStrip::Slab& c = s.slabs[size_t(s.current)];
        dl->AddRect({x(c.z0), p.y}, {std::max(x(c.z1), x(c.z0) + 1.0f), p.y + h}, white, 0.0f, 0,
                    2.0f);
    }
    if (depth) dl->AddLine({x(*depth), p.y - 3.0f}, {x(*depth), p.y + h + 3.0f}, white, 2.0f);
    ImGui::Dummy({w, h + 3.0f});
    ImGui::TextWrapped("depth %.4g to %.4g, one cell a slab", s.z0(), s.z1());
    if (s.current >= 0)
        ImGui::TextWrapped("slab %d of %zu: depth %.4g to %.4g, %zu primitives", s.current,
                           s.slabs.size(), s.slabs[size_t(s.current)].z0,
                           s.slabs[size_t(s.current)].z1, s.slabs[size_t(s.current)].prims);
}

bool sameCamera(const Camera& a, const Camera& b) {
    return a.from == b.from && a.at == b.at && a.up == b.up && a.fov == b.fov &&
           a.projection == b.projection && a.orthoHeight == b.orthoHeight;
}

}  // namespace

Overlays::Overlays()
    : renderer_(std::make_unique<gl::BatchRenderer>()),
      cuts_(std::make_unique<gl::GpuBatch>()),
      fills_(std::make_unique<gl::GpuBatch>()),
      wires_(std::make_unique<gl::GpuBatch>()),
      wiresLongestFirst_(std::make_unique<gl::GpuBatch>()) {}

Overlays::~Overlays() {
    glDeleteFramebuffers(1, &layerFbo_);
    glDeleteTextures(1, &layerTex_);
}

bool Overlays::select(uint32_t id) {
    if (!view_) {  // before the first structure: applied when it arrives
        pendingSelect_ = id;
        hasPendingSelect_ = true;
        return true;
    }
    if (id >= view_->regionCount()) {
        selection_.reset();
        return false;
    }
    const RegionInfo r = view_->region(id);
    Selection s;
    s.region = id;
    // A light's slab is a zone of the light's structure, none of the frames the overlay draws.
    s.zone = r.light >= 0 ? -1 : r.zone;
    s.frame =
        r.kind == RegionKind::ProjectiveSlab ? ZoneFrameKind::Projective : ZoneFrameKind::Camera;
    selection_ = s;
    return true;
}

void Overlays::update(const std::shared_ptr<const SceneBuild>& structure, const Camera& view,
                      int width, int height, bool moving, bool copy) {
    if (structure && structure != structure_) {
        // The new structure replaces the old one only now that it is ready: until then the old
        // overlays stayed on screen. Region ids of the old one mean nothing in the new one.
        structure_ = structure;
        view_ = std::make_shared<const StructureView>(*structure->scene, *structure->accel);
        if (selection_ && !select(selection_->region)) selection_.reset();
        if (hasPendingSelect_) {
            hasPendingSelect_ = false;
            select(pendingSelect_);
        }
    }
    if (!view_) return;
    if (copy) uploadMore();
    if (job_.pending()) {  // a build under way: the batches on screen stay until it is done
        std::optional<OverlayGeometry> g = job_.poll();
        if (!g) return;
        take(std::move(*g), jobInputs_,
             std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - jobStart_)
                 .count(),
             copy);
    }
    // The counts a cost colouring reads: the last complete image's, on this structure.
    std::shared_ptr<const ImageCosts> costs;
    if (options.usesCosts() && costsFit(costs_.get(), structure_.get(), options.costRays))
        costs = costs_;
    // Batches over the cap are culled for a view. Culled again at each step of a drag, balls4's
    // BVH nodes (over 100,000) took 68 ms of every frame (2026-12-06, scripts/frame-times): the
    // batches are in world space, so those of an earlier view are drawn right, only fewer.
    const bool viewMoved = geometry_.cameraDependent && !sameCamera(builtCamera_, view);
    const bool stale = builtView_ != view_.get() || builtOptions_ != options ||
                       builtWidth_ != width || builtHeight_ != height || costs != builtCosts_ ||
                       (viewMoved && !moving);
    if (!stale) return;
    BuildInputs in{structure_, view_, view, width, height, options, costs};
    if (!background_) {
        const auto t0 = std::chrono::steady_clock::now();
        OverlayGeometry g = build(in);
        take(std::move(g), in,
             std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                 .count(),
             true);
        return;
    }
    // On the worker: balls4's slabs (1.2 M lines) took the UI thread 0.83 s a structure
    // (2026-12-06, scripts/frame-times).
    jobInputs_ = in;
    jobStart_ = std::chrono::steady_clock::now();
    job_.start([in] { return build(in); }, wake_);
}

void Overlays::buildInBackground(std::function<void()> wake) {
    background_ = true;
    wake_ = std::move(wake);
}

OverlayGeometry Overlays::build(const BuildInputs& in) {
    if (!in.options.any()) return {};
    return buildOverlayGeometry(*in.view, in.camera, in.width, in.height, in.options,
                                in.costs ? &in.costs->costs : nullptr);
}

void Overlays::take(OverlayGeometry geometry, const BuildInputs& in, double ms, bool copy) {
    geometry_ = std::move(geometry);
    cuts_->beginUpload(geometry_.cuts);
    fills_->beginUpload(geometry_.fills);
    wiresLongestFirst_->beginUpload(geometry_.wiresLongestFirst);
    wires_->beginUpload(geometry_.wires);
    if (background_) {
        if (copy) uploadMore();  // the rest in the next frames
    } else {
        for (gl::GpuBatch* b : {cuts_.get(), fills_.get(), wiresLongestFirst_.get(), wires_.get()})
            b->uploadMore(SIZE_MAX);
    }
    lastBuildMs_ = ms;
    builtView_ = in.view.get();
    builtCosts_ = in.costs;
    builtOptions_ = in.options;
    builtCamera_ = in.camera;
    builtWidth_ = in.width;
    builtHeight_ = in.height;
    ++rebuilds_;
}

void Overlays::uploadMore() {
    // With the frame's budget: once a frame (update() runs twice in one), and only while the
    // budget is not spent; the copy goes on in the next frames.
    // A part is as large as what the budget leaves holds at its learned cost per byte,
    // look.uploadBytes at most and a 16th of it at least, and starts when its least fits (the
    // first of a frame also after kPatienceFrames frames of waiting): a part of uploadBytes let
    // in over the budget after its patience took frames to 33.0-35.8 ms of UI CPU on balls4's
    // slabs (2026-12-07), where the least is a fraction of a millisecond.
    const size_t most = std::max<size_t>(look.uploadBytes, 1),
                 least = std::max<size_t>(most / 16, 1);
    const auto fits = [&] {
        return !budget_ || budget_->fits(uploadCost_.estimateMs(double(least)), budgetReserveMs_,
                                         uploadPatience_);
    };
    const auto partBytes = [&] {
        if (!budget_) return most;
        const double fit = uploadCost_.unitsIn(budget_->leftMs(budgetReserveMs_));
        return std::clamp(size_t(std::min(fit, double(most))), least, most);
    };
    if (budget_ && !uploaded()) {
        if (budget_->frame() == uploadFrame_ || !fits()) return;
        uploadFrame_ = budget_->frame();
    }
    const auto t0 = std::chrono::steady_clock::now();
    bool first = true;  // let in above
    for (gl::GpuBatch* b : {cuts_.get(), fills_.get(), wiresLongestFirst_.get(), wires_.get()}) {
        b->uploadMore(0);  // one with nothing left to copy (an empty one) is done, at no cost
        while (!b->uploaded()) {
            if (!first && !fits()) return;
            first = false;
            const double start = budget_ ? budget_->spentMs() : 0.0;
            const size_t before = copiedBytes();
            b->uploadMore(partBytes());
            glFinish();  // timed: the copy is done
            if (budget_)
                uploadCost_.record(double(copiedBytes() - before), budget_->spentMs() - start);
            if (std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                    .count() >= look.uploadMs)
                return;
        }
    }
}

bool Overlays::uploaded() const {
    return cuts_->uploaded() && fills_->uploaded() && wiresLongestFirst_->uploaded() &&
           wires_->uploaded();
}

size_t Overlays::copiedBytes() const {
    size_t vertices = 0;
    for (const gl::GpuBatch* b :
         {cuts_.get(), fills_.get(), wiresLongestFirst_.get(), wires_.get()})
        vertices += 2 * b->lineCount() + 3 * b->triangleCount();
    return vertices * sizeof(gl::BatchVertex);
}

size_t Overlays::layerReady() const {
    auto ready = [](const gl::GpuBatch& b, size_t copied) {
        return b.uploaded() ? SIZE_MAX : copied;
    };
    return std::min({ready(*cuts_, cuts_->lineCount()), ready(*fills_, fills_->triangleCount() / 2),
                     ready(*wiresLongestFirst_, wiresLongestFirst_->lineCount())});
}

void Overlays::drawLayerRange(const Camera& view, int width, int height, size_t first, size_t count,
                              bool longestFirst) {
    if (!view_ || width <= 0 || height <= 0 || !options.any() || count == 0) return;
    const auto [nearDepth, farDepth] = clipDepths(*view_, view);
    const glm::mat4 toClip = gl::worldToClip(view, width, height, nearDepth, farDepth);
    glViewport(0, 0, width, height);
    const size_t end = count > SIZE_MAX - first ? SIZE_MAX : first + count;
    gl::DrawOptions fill;
    fill.opacity = look.fillOpacity;
    fill.lines = false;
    if (longestFirst) {  // a zone is two triangles
        fill.firstTriangle = first > SIZE_MAX / 2 ? SIZE_MAX : 2 * first;
        fill.triangleLimit = count > SIZE_MAX / 2 ? SIZE_MAX : 2 * count;
    }
    renderer_->draw(*fills_, toClip, fill);
    gl::DrawOptions wire;
    wire.opacity = look.lineOpacity;
    wire.triangles = false;
    wire.firstLine = first;
    wire.lineLimit = count;
    renderer_->draw(longestFirst ? *wiresLongestFirst_ : *wires_, toClip, wire);
    gl::DrawOptions cuts = wire;  // in cut order: shallow first, up to the replayed cut
    const size_t replayed =
        look.replayCuts >= 0 ? size_t(look.replayCuts) * geometry_.linesPerCut : SIZE_MAX;
    cuts.lineLimit = std::min(replayed, end) > first ? std::min(replayed, end) - first : 0;
    renderer_->draw(*cuts_, toClip, cuts);
}

size_t Overlays::layerLines() const {
    return std::max({geometry_.wires.lineCount(), geometry_.cuts.lineCount(),
                     geometry_.fills.triangleCount() / 2});
}

void Overlays::drawLayers(const Camera& view, int width, int height, size_t lines) {
    const bool capped = lines < geometry_.wires.lineCount() || lines < geometry_.cuts.lineCount();
    drawLayerRange(view, width, height, 0, lines, capped);
}

void Overlays::drawSelection(const Camera& view, int width, int height, int x0, int y0) {
    if (!view_ || width <= 0 || height <= 0) return;
    if (!selection_ || selection_->region >= view_->regionCount()) return;
    const auto [nearDepth, farDepth] = clipDepths(*view_, view);
    const glm::mat4 toClip = gl::worldToClip(view, width, height, nearDepth, farDepth);
    glViewport(x0, y0, width, height);
    // The selected region: its faces tinted, its edges bright.
    const std::array<Vec3, 8> wc = view_->regionCorners(selection_->region);
    std::array<glm::vec3, 8> c;
    for (size_t i = 0; i < 8; ++i) c[i] = glm::vec3(wc[i]);
    gl::Batch b;
    b.fillBox(c, gl::rgba8(glm::vec3(0.2f, 1.0f, 1.0f), 0.18f));
    b.box(c, gl::rgba8(glm::vec3(0.3f, 1.0f, 1.0f)));
    renderer_->drawNow(b, toClip);
}

bool Overlays::layerStale(const Camera& view, int width, int height) const {
    return !(layerTex_ != 0 && !layerPartial_ && layerRebuild_ == rebuilds_ &&
             layerWidth_ == width && layerHeight_ == height && layerLook_ == look &&
             sameCamera(layerCamera_, view));
}

unsigned Overlays::layerTexture(const Camera& view, int width, int height, bool moving) {
    layerDeferred_ = false;
    if (!view_ || !options.any() || width <= 0 || height <= 0) return 0;
    if (!layerStale(view, width, height)) return layerTex_;
    if (moving && look.movingLines == 0) return 0;
    const bool sameLayer = layerTex_ != 0 && layerRebuild_ == rebuilds_ && layerWidth_ == width &&
                           layerHeight_ == height && layerLook_ == look &&
                           sameCamera(layerCamera_, view);
    if (moving && layerPartial_ && sameLayer) return layerTex_;  // the capped layer of this view
    const bool newSize = layerWidth_ != width || layerHeight_ != height;
    const double texels = double(width) * double(height);
    // At rest a texture of a new size (the first structure's, a resized window's) is made
    // only when its learned cost fits in what the frame's budget leaves: llvmpipe zeroes its
    // storage (10 ms at 1280x720, 2026-12-07). Made with the layer's first drawing and its
    // read-back in one frame, whatever the first part's estimate (none for an empty layer),
    // they took balls4's first structure 21-32 ms of the overlays step. Until then the layer
    // shown stays. A texture that no frame's budget less the reserve would hold is made at
    // once (a larger window's viewer never settled), and one that would fit but not beside
    // what the frames spend before it is made after kPatienceFrames frames of waiting (on a
    // quiet machine it waited for ever).
    const double textureMs = textureCost_.estimateMs(texels);
    if (newSize && !moving && budget_ && textureMs <= budget_->budgetMs() - budgetReserveMs_ &&
        !budget_->fits(textureMs, budgetReserveMs_, texturePatience_)) {
        layerDeferred_ = true;
        return layerVersion_ == 0 ? 0 : layerTex_;
    }
    if (layerTex_ == 0) {
        glGenTextures(1, &layerTex_);
        glGenFramebuffers(1, &layerFbo_);
    }
    if (newSize) {
        const double madeAt = budget_ ? budget_->spentMs() : 0.0;
        glBindTexture(GL_TEXTURE_2D, layerTex_);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                     nullptr);
        glBindTexture(GL_TEXTURE_2D, 0);
        glBindFramebuffer(GL_FRAMEBUFFER, layerFbo_);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, layerTex_, 0);
        if (budget_) {
            glFinish();  // timed: the storage is made
            textureCost_.record(texels, budget_->spentMs() - madeAt);
        }
        layerWidth_ = width;
        layerHeight_ = height;
        // Nothing of the layer is in it: its first part starts afresh, at rest in a later
        // frame, so that the layer's first drawing and its read-back (ImageView::setOverlay,
        // 10 ms into a new buffer at 1280x720) do not fall in this one too.
        layerRebuild_ = ~uint64_t(0);
        layerPartial_ = false;
        layerDrawn_ = 0;
        if (!moving && budget_) {
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            layerDeferred_ = true;
            return layerVersion_ == 0 ? 0 : layerTex_;  // the texture's id is the same
        }
    }
    const auto t0 = std::chrono::steady_clock::now();
    glBindFramebuffer(GL_FRAMEBUFFER, layerFbo_);
    glDisable(GL_SCISSOR_TEST);
    glViewport(0, 0, width, height);
    // At rest a layer too large for one frame goes on from where the texture stands (a moving
    // camera's cap is its first part, longest lines first); else it starts afresh.
    const size_t total = layerLines();
    // Batches still being copied to GL are drawn in parts as they come, from what is copied.
    const size_t ready = std::min(total, layerReady());
    const bool inParts = !moving && (total > look.restLines || !uploaded());
    const bool resume = inParts && sameLayer && layerPartial_ && layerDrawn_ < total;
    if (resume && layerDrawn_ >= ready) {  // nothing more copied yet: the texture is unchanged
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        return layerTex_;
    }
    // At rest the layer is optional work: when its first part's learned cost does not fit in
    // what the frame's budget leaves, the texture stays as it is (the last one, whole or in
    // part) and is drawn in a later frame (after kPatienceFrames at most). A moving camera's layer
    // draws a first part in any case (it follows the view), as many lines as fit
    // (OverlayLook::movingMinLines at least), its others when they fit.
    const size_t partLines = std::max<size_t>(look.restLines, 1);
    StepCost& cost = moving ? movingLineCost_ : restLineCost_;
    const size_t from = resume ? layerDrawn_ : 0;
    layerDeferred_ =
        !moving && budget_ &&
        !budget_->fits(cost.estimateMs(double(
                           std::min(inParts ? partLines : total, ready - std::min(ready, from)))),
                       budgetReserveMs_, partPatience_);
    if (layerDeferred_) {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        return layerVersion_ == 0 ? 0 : layerTex_;  // none before the first drawing
    }
    if (!resume) {
        glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
        glClear(GL_COLOR_BUFFER_BIT);
        layerDrawn_ = 0;
    }
    if (moving || inParts) {
        // Parts until the frame's share is spent (GL finished: timed), the longest lines
        // first; while moving, up to the cap.
        const size_t end = moving ? std::min(look.movingLines, ready) : ready;
        const double budget = moving ? look.movingMs : look.restMs;
        for (bool first = true;; first = false) {
            size_t part = std::min(partLines, end - layerDrawn_);
            if (first && moving && budget_) {
                const double fit = cost.unitsIn(budget_->leftMs(budgetReserveMs_));
                part = std::min(part, std::max(look.movingMinLines, size_t(std::min(fit, 1e9))));
            } else if (!first && budget_ &&
                       !budget_->fits(cost.estimateMs(double(part)), budgetReserveMs_)) {
                break;
            }
            const double start = budget_ ? budget_->spentMs() : 0.0;
            drawLayerRange(view, width, height, layerDrawn_, part, true);
            layerDrawn_ += part;
            glFinish();
            if (budget_) cost.record(double(part), budget_->spentMs() - start);
            if (layerDrawn_ >= end ||
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                        .count() >= budget)
                break;
        }
    } else {  // whole in one frame, the wireframe in its own order
        drawLayers(view, width, height, SIZE_MAX);
        layerDrawn_ = total;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    // Finished here, so the time is the drawing's (it happens on a change only).
    glFinish();
    lastLayerMs_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    layerRebuild_ = rebuilds_;
    layerLook_ = look;
    layerCamera_ = view;
    layerMoving_ = moving;
    layerPartial_ = moving || layerDrawn_ < total;
    ++layerVersion_;
    return layerTex_;
}

bool Overlays::pickAt(const Camera& view, int width, int height, double x, double y, float depth) {
    if (!view_) return false;
    const auto p = pick(*view_, view, width, height, x, y, depth, options.projective);
    if (!p) return false;
    selection_ = Selection{p->region, p->zone, p->frame};
    return true;
}

void Overlays::tooltip(const Camera& view, int width, int height, double x, double y, float depth) {
    if (!view_ || !look.tooltip) return;
    const auto p = pick(*view_, view, width, height, x, y, depth, options.projective);
    if (!p) return;
    const RegionInfo r = view_->region(p->region);
    ImGui::BeginTooltip();
    if (view_->irregular() && p->zone >= 0) {
        const ZoneFrameView* fr = view_->frame(p->frame);
        ImGui::Text("zone %lld (%s frame)", static_cast<long long>(p->zone),
                    p->frame == ZoneFrameKind::Projective ? "projective" : "camera");
        if (fr) {
            ImGui::Text("%zu primitives, %zu slabs", fr->zonePrims(uint32_t(p->zone)).size(),
                        fr->slabs(uint32_t(p->zone)).size());
            depthStripBar(depthStrip(*fr, uint32_t(p->zone), p->frameDepth, p->region),
                          p->frameDepth);
        }
    }
    ImGui::Text("%s %u: %zu primitives", regionKindName(r.kind), r.id, r.prims.size());
    if (r.level >= 0) ImGui::Text("level %d", r.level);
    if (builtCosts_ && r.id < builtCosts_->costs.regions())
        ImGui::Text("%llu visits, %llu tests (%s)",
                    static_cast<unsigned long long>(builtCosts_->costs.visits(r.id)),
                    static_cast<unsigned long long>(builtCosts_->costs.tests(r.id)),
                    costRaysName(builtCosts_->costs.rays));
    ImGui::TextDisabled("Ctrl+click selects");
    ImGui::EndTooltip();
}

void Overlays::leafColorCombo(const char* label) {
    int color = int(options.leafColor);
    const char* by[] = {"level", "primitives", "region visits", "prim tests"};
    if (ImGui::Combo(label, &color, by, 4)) options.leafColor = LeafColor(color);
}

void Overlays::costLine() {
    OverlayOptions& o = options;
    if (!o.usesCosts()) return;
    int rays = int(o.costRays);
    const char* which[] = {"all rays", "primary rays"};
    if (ImGui::Combo("cost of", &rays, which, 2)) o.costRays = CostRays(rays);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("The rays of the last complete image whose visits and tests count");
    if (builtCosts_)
        ImGui::TextDisabled("counts of the last complete image (%d x %d, %.0f ms to count)",
                            builtCosts_->costs.width, builtCosts_->costs.height, builtCosts_->ms);
    else
        ImGui::TextDisabled("counting once the image is complete...");
}

void Overlays::panel(bool* open) {
    if (!ImGui::Begin("Overlays", open)) {
        ImGui::End();
        return;
    }
    if (!view_) {
        ImGui::TextDisabled("no structure yet");
        ImGui::End();
        return;
    }
    OverlayOptions& o = options;
    if (view_->irregular()) {
        const bool hasProjective = view_->frame(ZoneFrameKind::Projective) != nullptr;
        ImGui::Checkbox("BSP cut lines", &o.bsp);
        ImGui::SameLine();
        ImGui::Checkbox("zones", &o.zones);
        ImGui::SameLine();
        ImGui::Checkbox("slabs", &o.slabs);
        if (hasProjective) ImGui::Checkbox("projective zones (else camera frame)", &o.projective);
        const ZoneFrameView* fr = overlayFrame(*view_, o.projective);
        if (fr)
            ImGui::TextDisabled("%s frame, %s: %zu zones",
                                fr->kind() == ZoneFrameKind::Projective ? "projective" : "camera",
                                fr->mapsToImage() ? "maps to pixels" : "drawn in perspective",
                                fr->zoneCount());
        if (o.bsp) {
            int all = int(geometry_.cuts.lineCount() / std::max<size_t>(1, geometry_.linesPerCut));
            int n = look.replayCuts < 0 ? all : std::min(look.replayCuts, all);
            if (ImGui::SliderInt("cuts replayed", &n, 0, all)) look.replayCuts = n >= all ? -1 : n;
            ImGui::TextDisabled("%zu cuts, depth 0..%d", geometry_.cutsTotal,
                                geometry_.maxCutDepth);
        }
        if (o.zones) {
            int fill = int(o.zoneFill);
            const char* fills[] = {"primitives", "slabs", "region visits", "prim tests"};
            if (ImGui::Combo("zones by", &fill, fills, 4)) o.zoneFill = ZoneFill(fill);
            ImGui::SliderFloat("fill opacity", &look.fillOpacity, 0.0f, 1.0f);
        }
        if (o.slabs) {
            int sc = int(o.slabColor);
            const char* by[] = {"order in depth", "region visits", "prim tests"};
            if (ImGui::Combo("slabs by", &sc, by, 3)) o.slabColor = SlabColor(sc);
        }
        if (o.zones || o.slabs)
            ImGui::Text("zones drawn: %zu of %zu", geometry_.zonesDrawn, geometry_.zonesTotal);
    } else if (view_->regular()) {
        ImGui::Checkbox("leaves", &o.leaves);
        ImGui::SameLine();
        ImGui::Checkbox("directory grid", &o.grid);
        leafColorCombo("leaves by");
        const auto& extra = view_->accelerator().info().extra;
        const int top = std::max(1, extra.value("effective_max_level", 1));
        ImGui::DragIntRange2("levels", &o.levelMin, &o.levelMax, 0.1f, 0, top, "from %d", "to %d");
        o.levelMin = std::clamp(o.levelMin, 0, top);
        o.levelMax = std::clamp(o.levelMax, o.levelMin, std::max(top, o.levelMax));
        if (o.grid) {
            int gc = int(o.gridColor);
            ImGui::TextUnformatted("grid by");
            ImGui::SameLine();
            ImGui::RadioButton("kind", &gc, int(GridColor::Kind));
            ImGui::SameLine();
            ImGui::RadioButton("level", &gc, int(GridColor::Level));
            ImGui::SameLine();
            ImGui::RadioButton("table depth", &gc, int(GridColor::TableDepth));
            o.gridColor = GridColor(gc);
        }
        ImGui::TextDisabled("levels: BSP levels (a grid entry's leaf's)");
    } else if (view_->bvh()) {
        ImGui::Checkbox("nodes", &o.leaves);
        leafColorCombo("nodes by");
    } else {
        ImGui::TextDisabled("brute force has no subdivision to draw");
    }
    costLine();
    ImGui::SliderFloat("line opacity", &look.lineOpacity, 0.0f, 1.0f);
    int moving = int(std::min<size_t>(look.movingLines, 10000000));
    // Short labels: the columns are 250 units wide at least, the hover says the rest.
    if (ImGui::InputInt("moving lines", &moving, 500, 5000))
        look.movingLines = size_t(std::max(0, moving));
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Lines drawn while the camera moves");
    const size_t lines = geometry_.wires.lineCount();
    if (lines > 0)
        ImGui::TextDisabled("%zu lines; up to %zu drawn while the camera moves", lines,
                            std::min(lines, look.movingLines));
    int cap = int(std::min<size_t>(o.cap, 10000000));
    if (ImGui::InputInt("cap", &cap, 1000, 100000)) o.cap = size_t(std::max(0, cap));
    if (ImGui::IsItemHovered()) ImGui::SetTooltip("Most regions and cuts drawn, visible first");
    if (geometry_.regionsTotal > 0)
        ImGui::Text(
            "regions drawn: %zu of %zu%s", geometry_.regionsDrawn, geometry_.regionsTotal,
            geometry_.regionsDrawn < geometry_.regionsTotal ? " (visible first, capped)" : "");
    ImGui::Checkbox("hover tooltip", &look.tooltip);
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped("batches built in %.1f ms (%llu builds), drawn in %.1f ms", lastBuildMs_,
                       static_cast<unsigned long long>(rebuilds_), lastLayerMs_);
    ImGui::PopStyleColor();
    ImGui::End();
}

namespace {

/// A node of a restricted tree and its subtrees; with `eval` (the played ray's evaluation of
/// this tree), the nodes evaluated show their spans and the others are dimmed.
void csgTreeNode(const CsgTree& pool, int node, const Scene& scene,
                 const std::vector<NodeSpans>* eval) {
    if (node < 0 || size_t(node) >= pool.nodes.size()) return;
    const CsgNode& n = pool.nodes[size_t(node)];
    const NodeSpans* e = nullptr;
    if (eval)
        for (const NodeSpans& x : *eval)
            if (x.node == node) e = &x;
    const bool dim = eval && (!e || !e->evaluated);
    std::string spans;
    if (e && e->evaluated) {
        // Short: t to 4 digits, the spans' ends only.
        char buf[64];
        spans = "  {";
        for (const Span& sp : e->spans) {
            std::snprintf(buf, sizeof buf, "%s[%.4g, %.4g]", spans.size() > 3 ? " " : "", sp.in.t,
                          sp.out.t);
            spans += buf;
        }
        spans += "}";
    }
    ImGui::PushID(node);
    if (dim) ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    if (n.op == Op::Primitive) {
        const char* kind = n.prim < scene.prims.size() ? shapeName(scene.prims[n.prim].shape) : "?";
        ImGui::BulletText("%s %u%s", kind, n.prim, spans.c_str());
    } else if (ImGui::TreeNodeEx("op", ImGuiTreeNodeFlags_DefaultOpen, "%s%s", opName(n.op),
                                 spans.c_str())) {
        csgTreeNode(pool, n.left, scene, eval);
        csgTreeNode(pool, n.right, scene, eval);
        ImGui::TreePop();
    }
    if (dim) ImGui::PopStyleColor();
    ImGui::PopID();
}

}  // namespace

void Overlays::selectionPanel(bool* open) {
    if (!ImGui::Begin("Selection", open)) {
        ImGui::End();
        return;
    }
    if (!view_ || !selection_ || selection_->region >= view_->regionCount()) {
        ImGui::TextWrapped("Nothing selected: Ctrl+click the image (or --select REGION).");
        ImGui::End();
        return;
    }
    const RegionInfo r = view_->region(selection_->region);
    const Scene& scene = view_->scene();
    ImGui::Text("%s %u", regionKindName(r.kind), r.id);
    if (r.level >= 0) ImGui::Text("level %d", r.level);
    if (r.zone >= 0) {
        ImGui::Text("zone %lld, slab %u", static_cast<long long>(r.zone), r.slab);
        if (const ZoneFrameView* fr = view_->frame(selection_->frame))
            depthStripBar(depthStrip(*fr, uint32_t(r.zone), std::nullopt, r.id), std::nullopt);
    }
    ImGui::TextWrapped("box (%s frame): %s",
                       r.kind == RegionKind::Leaf
                           ? (view_->regular()->frame().turned ? "grid" : "world")
                       : r.kind == RegionKind::SceneBox ? "world"
                       : r.kind == RegionKind::Slab     ? "camera"
                                                        : "projective",
                       boxText(r.frameBox).c_str());
    if (ImGui::Button("clear")) selection_.reset();
    if (!selection_) {
        ImGui::End();
        return;
    }
    if (ImGui::CollapsingHeader("primitives", ImGuiTreeNodeFlags_DefaultOpen)) {
        ImGui::Text("%zu listed", r.prims.size());
        const size_t shown = std::min<size_t>(r.prims.size(), 200);
        if (ImGui::BeginTable("prims", 3, ImGuiTableFlags_Borders | ImGuiTableFlags_ScrollY,
                              ImVec2(0, 140))) {
            // The box wraps in the column the id and kind leave.
            ImGui::TableSetupColumn("id", ImGuiTableColumnFlags_WidthFixed);
            ImGui::TableSetupColumn("kind", ImGuiTableColumnFlags_WidthFixed);
            ImGui::TableSetupColumn("minimized box", ImGuiTableColumnFlags_WidthStretch);
            ImGui::TableHeadersRow();
            for (size_t i = 0; i < shown; ++i) {
                const uint32_t p = r.prims[i];
                ImGui::TableNextColumn();
                ImGui::Text("%u", p);
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(p < scene.prims.size() ? shapeName(scene.prims[p].shape)
                                                              : "?");
                ImGui::TableNextColumn();
                ImGui::TextWrapped("%s",
                                   p < scene.minBox.size() ? boxText(scene.minBox[p]).c_str() : "");
            }
            ImGui::EndTable();
        }
        if (shown < r.prims.size()) ImGui::TextDisabled("(first %zu shown)", shown);
    }
    if (ImGui::CollapsingHeader("restricted CSG tree", ImGuiTreeNodeFlags_DefaultOpen)) {
        if (r.root < 0 || !r.pool)
            ImGui::TextDisabled("empty");
        else {
            const bool played =
                evalRegion_ == int64_t(r.id) && evalPool_ == r.pool && !evalNodes_.empty();
            if (played) {
                ImGui::PushStyleColor(ImGuiCol_Text,
                                      ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
                ImGui::TextWrapped("the played ray's evaluation: nodes reached lit, with spans");
                ImGui::PopStyleColor();
            }
            csgTreeNode(*r.pool, r.root, scene, played ? &evalNodes_ : nullptr);
        }
    }
    if (ImGui::CollapsingHeader("neighbours", ImGuiTreeNodeFlags_DefaultOpen)) {
        const bool regular = r.kind == RegionKind::Leaf;
        ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
        ImGui::TextWrapped("%s", regular
                                     ? "ropes across each face"
                                     : "corner pointers (the region beyond each face's corner)");
        ImGui::PopStyleColor();
        static const char* axes[3] = {"x", "y", "z"};
        std::optional<uint32_t> go;
        for (int a = 0; a < 3; ++a)
            for (int side = 0; side < 2; ++side) {
                const int64_t n = side ? r.hi[a] : r.lo[a];
                ImGui::Text("%s %s:", side ? "high" : "low", axes[a]);
                ImGui::SameLine();
                if (n >= 0) {
                    ImGui::PushID(a * 2 + side);
                    if (ImGui::SmallButton(std::to_string(n).c_str())) go = uint32_t(n);
                    ImGui::PopID();
                } else {
                    ImGui::TextDisabled("%s", n == kNoNeighbour         ? "border"
                                              : n == kSeveralNeighbours ? "several leaves"
                                                                        : "not linked");
                }
            }
        if (go) select(*go);
    }
    ImGui::End();
}

std::vector<std::string> applyShowList(const std::string& list, OverlayOptions& o) {
    OverlayOptions out = o;
    out.bsp = out.zones = out.slabs = out.leaves = out.grid = false;
    std::vector<std::string> notDrawn;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item == "bsp")
            out.bsp = true;
        else if (item == "zones")
            out.zones = true;
        else if (item == "slabs")
            out.slabs = true;
        else if (item == "leaves")
            out.leaves = true;
        else if (item == "grid")
            out.grid = true;
        else if (item == "visits" || item == "tests") {
            // The layers that colour regions, by the last complete image's cost in them.
            const bool v = item == "visits";
            out.leafColor = v ? LeafColor::Visits : LeafColor::Tests;
            out.zoneFill = v ? ZoneFill::Visits : ZoneFill::Tests;
            out.slabColor = v ? SlabColor::Visits : SlabColor::Tests;
        } else if (item == "none")
            continue;
        else if (item == "boxes" || item == "frustum" || item == "inspector" || item == "ray" ||
                 item == "visited" || item == "worst" || item == "tree")
            notDrawn.push_back(item);
        else
            throw std::invalid_argument(
                "unknown item '" + item +
                "' (expected bsp, zones, slabs, leaves, grid, visits, tests, boxes, frustum, "
                "inspector, ray, visited, worst, tree, none)");
    }
    o = out;
    return notDrawn;
}

std::string showListMismatch(const std::string& list, SchemeKind scheme) {
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
        const bool irregular = item == "bsp" || item == "zones" || item == "slabs";
        const bool regular = item == "leaves" || item == "grid";
        if (!irregular && !regular) continue;
        if (item == "leaves" && scheme == SchemeKind::Bvh) continue;  // the BVH's nodes
        const SchemeKind owner = irregular ? SchemeKind::Irregular : SchemeKind::Regular;
        if (owner == scheme) continue;
        return "--show " + item + ": the " + schemeName(scheme) + " scheme has no " + item +
               " (a layer of the " + schemeName(owner) + " scheme; --scheme " + schemeName(owner) +
               " draws it)";
    }
    return "";
}

}  // namespace lancer::viewer::overlay
