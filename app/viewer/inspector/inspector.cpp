#include "app/viewer/inspector/inspector.h"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "app/viewer/camera_control.h"
#include "app/viewer/gl.h"
#include "app/viewer/gl/batch.h"
#include "app/viewer/gl/program.h"
#include "app/viewer/gl/transforms.h"

namespace lancer::viewer::inspector {

namespace {

bool sameCamera(const Camera& a, const Camera& b) {
    return a.from == b.from && a.at == b.at && a.up == b.up && a.fov == b.fov &&
           a.projection == b.projection && a.orthoHeight == b.orthoHeight;
}

/// The surfaces are traced at this fraction of the viewport (at most kMaxSurfaceWidth wide):
/// lines are depth-tested against them, so a coarser trace only blurs where lines meet
/// surfaces, and a trace of 320 x 360 pixels of balls4 takes one thread tens of milliseconds.
constexpr int kMaxSurfaceWidth = 480;

void surfaceSize(int vw, int vh, int& sw, int& sh) {
    int f = 2;
    while (vw / f > kMaxSurfaceWidth) ++f;
    sw = std::max(1, vw / f);
    sh = std::max(1, vh / f);
}

const glm::vec3 kBackground{0.1f, 0.1f, 0.12f};

}  // namespace

Inspector::Inspector(std::function<void()> wake) {
    if (wake) tracer_.setOnReady(std::move(wake));
    batches_ = std::make_unique<gl::BatchRenderer>();
    lines_ = std::make_unique<gl::GpuBatch>();
    selection_ = std::make_unique<gl::GpuBatch>();
    frustumGpu_ = std::make_unique<gl::GpuBatch>();
    surfaceProgram_ =
        std::make_unique<gl::Program>("inspector_surface.vert", "inspector_surface.frag");
    glGenFramebuffers(1, &fbo_);
    GLuint tex[3];
    glGenTextures(3, tex);
    colorTex_ = tex[0];
    surfColorTex_ = tex[1];
    surfDepthTex_ = tex[2];
    for (GLuint t : tex) {
        glBindTexture(GL_TEXTURE_2D, t);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    // The traced colour is magnified smoothly; its depth stays nearest (no blend across an
    // object's silhouette).
    glBindTexture(GL_TEXTURE_2D, surfColorTex_);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenRenderbuffers(1, &depthRb_);
    glGenRenderbuffers(1, &nextDepthRb_);
    glGenTextures(1, &nextColorTex_);
    glBindTexture(GL_TEXTURE_2D, nextColorTex_);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    glGenVertexArrays(1, &vao_);
    // The picture's framebuffer of one pixel until render() gives it the view's size, its
    // drawing states readied now, before any frame.
    glBindTexture(GL_TEXTURE_2D, colorTex_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glBindTexture(GL_TEXTURE_2D, 0);
    glBindRenderbuffer(GL_RENDERBUFFER, depthRb_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, 1, 1);
    glBindRenderbuffer(GL_RENDERBUFFER, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colorTex_, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthRb_);
    fboW_ = fboH_ = vw_ = vh_ = 1;
    warmUp();
    vw_ = vh_ = 0;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

Inspector::~Inspector() {
    GLuint tex[4] = {colorTex_, nextColorTex_, surfColorTex_, surfDepthTex_};
    glDeleteTextures(4, tex);
    GLuint rb[2] = {depthRb_, nextDepthRb_};
    glDeleteRenderbuffers(2, rb);
    glDeleteFramebuffers(1, &fbo_);
    glDeleteVertexArrays(1, &vao_);
}

void Inspector::setShown(bool on) {
    if (opt_.show == on) return;
    opt_.show = on;
    dirtyModel_ = true;
}

PixelRect Inspector::viewport(int fbWidth, int fbHeight) {
    return {fbWidth / 2, 0, fbWidth, fbHeight};
}

PixelRect Inspector::area(int fbWidth, int fbHeight) const {
    if (area_.x1 > area_.x0 && area_.y1 > area_.y0) return area_;
    return viewport(fbWidth, fbHeight);
}

void Inspector::setCamera(const Camera& c) {
    camera_ = c;
    cameraFramed_ = true;
    dirtyPicture_ = true;
    if (!dragging_) dirtyModel_ = true;  // what is in view changed
}

void Inspector::update(const std::shared_ptr<const SceneBuild>& structure, const MainView& main,
                       int fbWidth, int fbHeight, int64_t selected) {
    takeSurfaces();
    if (!opt_.show) return;
    const PixelRect v = area(fbWidth, fbHeight);
    if (v.x1 - v.x0 != vw_ || v.y1 - v.y0 != vh_) {
        vw_ = std::max(1, v.x1 - v.x0);
        vh_ = std::max(1, v.y1 - v.y0);
        dirtyModel_ = true;
    }
    if (structure != structure_) {
        const bool newScene = !structure_ || !structure || structure_->spec != structure->spec;
        structure_ = structure;
        view_ = structure_
                    ? std::make_shared<const StructureView>(*structure_->scene, *structure_->accel)
                    : nullptr;
        if (structure_ && (newScene || !cameraFramed_)) {
            if (restore_ && restore_->scene == structure_->spec) {
                camera_ = restore_->camera;
            } else {
                // Beside the main camera, turned about the up axis, so its frustum shows.
                Camera turned = main.camera;
                orbit(turned, 0.7, 0.35);
                Box3 all = view_->worldBounds();
                all.expand(main.camera.from);
                camera_ = frameBox(all, turned.at - turned.from, 40.0, double(vw_) / double(vh_));
            }
            restore_.reset();  // the first structure only: a scene opened later is framed
            cameraScene_ = structure_->spec;
            cameraFramed_ = true;
        }
        dirtyModel_ = true;
    }
    if (pendingFrame_ && structure_) {
        setCamera(framedOn(camera_, *pendingFrame_, double(vw_) / double(vh_)));
        pendingFrame_.reset();
    }
    if (!sameCamera(main.camera, main_.camera) || main.width != main_.width ||
        main.height != main_.height) {
        main_ = main;
        // Only the frustum shows the main camera, and it is built apart from the model: a turn
        // of the main camera rebuilt all of balls4's leaves each frame (106 ms a frame), and
        // with the frustum on 4-10 ms of the irregular slabs' model (2026-12-06).
        if (opt_.frustum) rebuildFrustum();
    }
    if (selected != selected_) {
        selected_ = selected;
        dirtyModel_ = true;
    }
    if (job_.pending()) {
        if (std::optional<InspectorModel> m = job_.poll()) {
            model_ = std::move(*m);
            dirtyBatch_ = true;
            dirtyPicture_ = true;
        }
    }
    if (dirtyModel_ && !dragging_ && !job_.pending()) rebuildModel();
}

void Inspector::buildInBackground(std::function<void()> wake) {
    background_ = true;
    wake_ = std::move(wake);
}

void Inspector::rebuildFrustum() {
    frustum_ = view_ && opt_.frustum ? frustumLines(*view_, main_) : gl::Batch{};
    frustumGpu_->upload(frustum_);  // a few lines: the model's batch is not copied again
    dirtyPicture_ = true;
}

void Inspector::rebuildModel() {
    dirtyModel_ = false;
    ++modelBuilds_;
    rebuildFrustum();
    InspectorOptions opt = opt_;
    opt.frustum = false;  // frustum_, apart
    const InspectorView iv{camera_, vw_, vh_};
    if (!view_ || !background_) {
        model_ = view_ ? buildModel(*view_, opt, main_, iv, selected_) : InspectorModel{};
        dirtyBatch_ = true;
        dirtyPicture_ = true;
        return;
    }
    // The view and the structure it reads kept alive by the worker; the last model is drawn
    // until this one comes (update()).
    job_.start([view = view_, structure = structure_, opt, main = main_, iv,
                selected = selected_] { return buildModel(*view, opt, main, iv, selected); },
               wake_);
}

void Inspector::depthBounds(double& near, double& far) const {
    Box3 all = view_ ? view_->worldBounds() : Box3{Vec3(-1.0), Vec3(1.0)};
    for (const gl::Batch* b : {&model_.lines, &frustum_})
        for (const gl::BatchVertex& v : b->lines) all.expand(Vec3(v.position));
    depthRange(camera_, all, near, far);
}

bool Inspector::handleMouse(int fbWidth, int fbHeight, std::optional<int64_t>& picked) {
    if (!opt_.show) return false;
    ImGuiIO& io = ImGui::GetIO();
    const PixelRect v = area(fbWidth, fbHeight);
    const float mx = io.MousePos.x * io.DisplayFramebufferScale.x;
    const float my = io.MousePos.y * io.DisplayFramebufferScale.y;
    const bool inside =
        mx >= float(v.x0) && mx < float(v.x1) && my >= float(v.y0) && my < float(v.y1);
    if (!dragging_) {
        if (io.WantCaptureMouse || !inside) return false;
        for (int b = 0; b < 3; ++b)
            if (ImGui::IsMouseClicked(b)) {
                dragging_ = true;
                dragButton_ = b;
            }
        // A drag begun over the image goes on moving the main camera.
        if (!dragging_ && ImGui::IsAnyMouseDown()) return false;
        if (io.MouseWheel != 0.0f) {
            Camera c = camera_;
            zoom(c, std::pow(0.9, double(io.MouseWheel)));
            setCamera(c);
        }
        return true;
    }
    const float dx = io.MouseDelta.x * io.DisplayFramebufferScale.x;
    const float dy = io.MouseDelta.y * io.DisplayFramebufferScale.y;
    if (dx != 0.0f || dy != 0.0f) {
        Camera c = camera_;
        if (dragButton_ == ImGuiMouseButton_Left)
            orbit(c, -0.008 * dx, 0.008 * dy);
        else if (dragButton_ == ImGuiMouseButton_Middle)
            pan(c, dx, dy, vh_);
        else
            zoom(c, std::exp(0.01 * dy));
        setCamera(c);
    }
    if (!ImGui::IsMouseDown(dragButton_)) {
        dragging_ = false;
        dirtyModel_ = true;  // cull for the camera the drag ended on
        if (dragButton_ == ImGuiMouseButton_Left &&
            io.MouseDragMaxDistanceSqr[ImGuiMouseButton_Left] < 9.0f)
            picked = pick(double(mx - float(v.x0)), double(my - float(v.y0)));
    }
    return true;
}

int64_t Inspector::pick(double x, double y) const {
    if (vw_ <= 0 || vh_ <= 0) return -1;
    // Camera::primaryRay adds half a pixel: continuous coordinates minus a half.
    const Ray ray = camera_.primaryRay(x - 0.5, y - 0.5, vw_, vh_);
    const int i = pickRegion(ray, model_.regions);
    return i < 0 ? -1 : int64_t(model_.regions[size_t(i)].id);
}

bool Inspector::settled() const {
    return !opt_.show || !structure_ ||
           (!dirtyModel_ && !job_.pending() && !picturePending() &&
            (!opt_.surfaces || surfacesShown()));
}

bool Inspector::surfacesShown() const {
    return opt_.surfaces && surfaces_ && structure_ && surfaces_->structure == structure_ &&
           sameCamera(surfaces_->camera, camera_);
}

void Inspector::requestSurfaces() {
    if (!opt_.surfaces || !structure_ || vw_ <= 0) return;
    int sw, sh;
    surfaceSize(vw_, vh_, sw, sh);
    if (surfacesRequested_ && sameCamera(requestedCamera_, camera_) && requestedW_ == sw &&
        requestedH_ == sh && surfaces_ && surfaces_->structure == structure_)
        return;
    if (surfacesRequested_ && sameCamera(requestedCamera_, camera_) && requestedW_ == sw &&
        requestedH_ == sh && tracer_.busy())
        return;
    tracer_.request(structure_, camera_, sw, sh);
    surfacesRequested_ = true;
    requestedCamera_ = camera_;
    requestedW_ = sw;
    requestedH_ = sh;
}

void Inspector::takeSurfaces() {
    if (std::optional<SurfaceImage> s = tracer_.poll()) {
        surfaces_ = std::move(s);
        surfUploaded_ = false;
        dirtyPicture_ = true;
    }
}

bool Inspector::waitSurfaces(int ms) {
    requestSurfaces();
    const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    while (std::chrono::steady_clock::now() < until) {
        takeSurfaces();
        if (surfacesShown()) return true;
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return false;
}

int Inspector::makeFramebuffer() {
    if (fboW_ == vw_ && fboH_ == vh_) return 0;
    if (nextW_ != vw_ || nextH_ != vh_) {  // a new size: what was made for another is made again
        nextW_ = vw_;
        nextH_ = vh_;
        nextColorMade_ = nextDepthMade_ = false;
    }
    // Each storage is made when its learned cost fits (after kPatienceFrames draws of waiting
    // whatever the budget), at most one of them a draw under a budget: the picture's
    // framebuffer at 1280x720, colour and depth made with the clear in one draw, took 21.6 ms
    // of the first piece that was estimated at 6 (balls4, 2026-12-07).
    const double texels = double(vw_) * double(vh_);
    for (bool* made : {&nextColorMade_, &nextDepthMade_}) {
        if (*made) continue;
        if (budget_ &&
            !budget_->fits(storageCost_.estimateMs(texels), reserveMs(), storagePatience_))
            return -1;
        const double start = budget_ ? budget_->spentMs() : 0.0;
        if (made == &nextColorMade_) {
            glBindTexture(GL_TEXTURE_2D, nextColorTex_);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, vw_, vh_, 0, GL_RGBA, GL_UNSIGNED_BYTE,
                         nullptr);
            glBindTexture(GL_TEXTURE_2D, 0);
        } else {
            glBindRenderbuffer(GL_RENDERBUFFER, nextDepthRb_);
            glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, vw_, vh_);
            glBindRenderbuffer(GL_RENDERBUFFER, 0);
        }
        *made = true;
        if (budget_) {
            glFinish();  // timed: the storage is made
            storageCost_.record(texels, budget_->spentMs() - start);
        }
    }
    // Both made beside the picture on screen, which stayed whole until now: they replace it.
    std::swap(colorTex_, nextColorTex_);
    std::swap(depthRb_, nextDepthRb_);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, colorTex_, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depthRb_);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    fboW_ = vw_;
    fboH_ = vh_;
    nextW_ = nextH_ = 0;
    dirtyPicture_ = true;  // the new framebuffer holds no picture yet
    return 1;
}

void Inspector::render() {
    dirtyPicture_ = false;
    const double start = budget_ ? budget_->spentMs() : 0.0;
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, vw_, vh_);
    glDisable(GL_SCISSOR_TEST);
    glDepthMask(GL_TRUE);
    glClearColor(kBackground.x, kBackground.y, kBackground.z, 1.0f);
    glClearDepth(1.0);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (budget_ && partLines_ > 0) {
        glFinish();  // timed: the clear is done
        startCost_.record(1, budget_->spentMs() - start);
    }
    double near, far;
    depthBounds(near, far);
    const bool surfaces = surfacesShown();
    pictureToClip_ = gl::worldToClip(camera_, vw_, vh_, near, far);
    pictureSurfaces_ = surfaces;
    if (surfaces) {
        const Image& img = surfaces_->image;
        if (!surfUploaded_) {
            const double copyStart = budget_ ? budget_->spentMs() : 0.0;
            surfW_ = img.width;
            surfH_ = img.height;
            std::vector<uint8_t> rgba(size_t(img.width) * size_t(img.height) * 4);
            img.rgba8Into(rgba.data(), 0, img.height, true);
            // Depth along the camera's forward axis (the projection's depth), bottom row first;
            // -1 where the ray missed.
            std::vector<float> depth(size_t(img.width) * size_t(img.height));
            const PrimaryRays rays(surfaces_->camera, img.width, img.height);
            Vec3 f, r, u;
            surfaces_->camera.basis(f, r, u);
            for (int y = 0; y < img.height; ++y)
                for (int x = 0; x < img.width; ++x) {
                    const float t = img.depth[img.index(x, y)];
                    const size_t o = size_t(img.height - 1 - y) * size_t(img.width) + size_t(x);
                    if (!std::isfinite(t)) {
                        depth[o] = -1.0f;
                        rgba[o * 4 + 0] = uint8_t(kBackground.x * 255.0f);
                        rgba[o * 4 + 1] = uint8_t(kBackground.y * 255.0f);
                        rgba[o * 4 + 2] = uint8_t(kBackground.z * 255.0f);
                    } else {
                        depth[o] = float(double(t) * glm::dot(rays(x, y).d, f));
                    }
                }
            glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
            glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
            glBindTexture(GL_TEXTURE_2D, surfColorTex_);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, img.width, img.height, 0, GL_RGBA,
                         GL_UNSIGNED_BYTE, rgba.data());
            glBindTexture(GL_TEXTURE_2D, surfDepthTex_);
            glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, img.width, img.height, 0, GL_RED, GL_FLOAT,
                         depth.data());
            glBindTexture(GL_TEXTURE_2D, 0);
            surfUploaded_ = true;
            if (budget_) surfaceCopyCost_.record(1, budget_->spentMs() - copyStart);
        }
    }
    pictureNear_ = near;
    pictureFar_ = far;
    surfaceRows_ = surfaces ? 0 : vh_;
    if (dirtyBatch_) {
        lines_->beginUpload(model_.lines);
        selection_->upload(model_.selection);
        dirtyBatch_ = false;
    }
    picturedLines_ = 0;
    renderMore();
}

void Inspector::warmUp() {
    // One line of no length at the far corner, with and without the depth test, then cleared
    // by render(): the driver readies what drawing lines into this framebuffer needs now,
    // before any frame, not with the picture's first part.
    gl::Batch dot;
    const glm::vec3 corner(1.0f, 1.0f, 1.0f);  // clip space (toClip below is the identity)
    dot.line(corner, corner, gl::Rgba8{});
    glViewport(0, 0, vw_, vh_);
    gl::DrawOptions o;
    for (bool depth : {false, true}) {
        o.depthTest = depth;
        batches_->drawNow(dot, glm::mat4(1.0f), o);
    }
    // The surfaces' textures of their formats (one texel until the trace comes: the driver's
    // program depends on them; the first band of balls4's surfaces took 29 ms without this).
    if (!surfUploaded_) {
        const uint8_t texel[4] = {0, 0, 0, 0};
        const float depth = -1.0f;
        glBindTexture(GL_TEXTURE_2D, surfColorTex_);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, 1, 1, 0, GL_RGBA, GL_UNSIGNED_BYTE, texel);
        glBindTexture(GL_TEXTURE_2D, surfDepthTex_);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_R32F, 1, 1, 0, GL_RED, GL_FLOAT, &depth);
        glBindTexture(GL_TEXTURE_2D, 0);
    }
    drawSurfaceRows(0, 1);
}

void Inspector::drawSurfaceRows(int rowBegin, int rowEnd) {
    // The traced picture, its depth written as the line pass's projection would write it; rows
    // [rowBegin, rowEnd) of the viewport (GL's, from the bottom).
    glEnable(GL_SCISSOR_TEST);
    glScissor(0, rowBegin, vw_, rowEnd - rowBegin);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_ALWAYS);
    glDisable(GL_BLEND);
    const unsigned prog = surfaceProgram_->id();
    glUseProgram(prog);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, surfColorTex_);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, surfDepthTex_);
    glUniform1i(surfaceProgram_->uniform("colorTex"), 0);
    glUniform1i(surfaceProgram_->uniform("depthTex"), 1);
    glUniform1i(surfaceProgram_->uniform("ortho"),
                camera_.projection == Projection::Orthographic ? 1 : 0);
    glUniform1f(surfaceProgram_->uniform("nearDepth"), float(pictureNear_));
    glUniform1f(surfaceProgram_->uniform("farDepth"), float(pictureFar_));
    glBindVertexArray(vao_);
    glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
    glBindVertexArray(0);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
    glDepthFunc(GL_LESS);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_SCISSOR_TEST);
}

int Inspector::nextBandRows() const {
    const bool surfaces = dirtyPicture_ ? surfacesShown() : surfaceRows_ < vh_;
    if (!surfaces) return 0;
    const int from = dirtyPicture_ ? 0 : surfaceRows_;
    const int band = partLines_ > 0 ? std::max(1, (vh_ + kSurfaceBands - 1) / kSurfaceBands) : vh_;
    return std::min(band, vh_ - from);
}

double Inspector::nextPieceMs() const {
    const int rows = nextBandRows();
    double ms = rows > 0 ? rowCost_.estimateMs(rows) : partCost_.estimateMs(1);
    // A new picture is cleared first, and new surfaces are converted and copied to GL.
    if (dirtyPicture_) ms += startCost_.estimateMs(1);
    if (dirtyPicture_ && surfacesShown() && !surfUploaded_) ms += surfaceCopyCost_.estimateMs(1);
    return ms;
}

void Inspector::renderMore() {
    const auto t0 = std::chrono::steady_clock::now();
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glViewport(0, 0, vw_, vh_);
    glDisable(GL_SCISSOR_TEST);
    // The frame's CPU time so far (the budget's clock), to learn what a piece costs.
    auto spent = [this] { return budget_ ? budget_->spentMs() : 0.0; };
    auto overTime = [&] {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                   .count() >= partMs_;
    };
    // The first piece of a draw() was let in by draw() (nextPieceMs()); each further one
    // starts only when its learned cost fits in what the frame's budget leaves.
    bool first = true;
    auto fits = [&](double ms) {
        if (first || partLines_ == 0 || !budget_) return true;
        return budget_->fits(ms, reserveMs());
    };
    // The surfaces first (the lines are tested against their depth), in bands.
    while (surfaceRows_ < vh_) {
        const int end = surfaceRows_ + nextBandRows();
        if (!fits(rowCost_.estimateMs(end - surfaceRows_))) {
            picturePending_ = true;
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            return;
        }
        first = false;
        const double start = spent();
        drawSurfaceRows(surfaceRows_, end);
        if (partLines_ > 0) {
            glFinish();  // timed: the band is drawn
            rowCost_.record(end - surfaceRows_, spent() - start);
        }
        surfaceRows_ = end;
        if (partLines_ == 0 || surfaceRows_ >= vh_) break;
        if (overTime()) {
            picturePending_ = true;
            glBindFramebuffer(GL_FRAMEBUFFER, 0);
            return;
        }
    }
    gl::DrawOptions o;
    o.depthTest = pictureSurfaces_;
    // The model's lines in order, in parts (drawInParts()) as they are copied to GL: the
    // picture is the one drawing them at once would give.
    const size_t part = partLines_ > 0 ? partLines_ : SIZE_MAX;
    for (;;) {
        if (!fits(partCost_.estimateMs(1))) break;
        first = false;
        const double start = spent();
        if (!lines_->uploaded()) lines_->uploadMore(partLines_ > 0 ? kPartBytes : SIZE_MAX);
        gl::DrawOptions range = o;
        range.firstLine = picturedLines_;
        range.lineLimit = std::min(part, lines_->lineCount() - picturedLines_);
        batches_->draw(*lines_, pictureToClip_, range);
        picturedLines_ += range.lineLimit;
        if (partLines_ > 0) {
            glFinish();  // timed: the part is drawn
            partCost_.record(1, spent() - start);
        }
        if (lines_->uploaded() && picturedLines_ >= lines_->lineCount()) break;
        if (partLines_ == 0) continue;
        if (overTime()) break;
    }
    picturePending_ = !lines_->uploaded() || picturedLines_ < lines_->lineCount();
    // Over the lines drawn so far (again after each part: the same pixels once whole).
    batches_->draw(*frustumGpu_, pictureToClip_, o);
    // The selection over everything: it must be found even behind a surface.
    batches_->draw(*selection_, pictureToClip_, {});
    // Lines another room adds (the ray played), over everything as the selection is.
    if (!extra_.empty()) batches_->drawNow(extra_, pictureToClip_, {});
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void Inspector::drawInParts(size_t lines, double ms) {
    partLines_ = lines;
    partMs_ = ms;
}

void Inspector::setExtraLines(gl::Batch batch) {
    extra_ = std::move(batch);
    dirtyPicture_ = true;
}

void Inspector::draw(int fbWidth, int fbHeight) {
    if (!opt_.show || vw_ <= 0 || vh_ <= 0) return;
    requestSurfaces();
    takeSurfaces();
    if (dirtyBatch_) dirtyPicture_ = true;
    // The picture is optional work under the frame's budget: with it spent, the picture on
    // screen stays as it is (dirtyPicture_ or picturePending_ kept) and is drawn later.
    const bool work = dirtyPicture_ || picturePending_;
    // The frame's GL work so far finished first, so the budget sees what it cost (llvmpipe
    // draws at a flush: 3-7 ms on balls4's slabs, 2026-12-07); then the first piece starts only
    // if its learned cost fits in what is left. Finished with nothing to draw too, so that the
    // picture's copy is learned apart from that work.
    if (budget_) glFinish();
    // A framebuffer of a new size is a step of its own before the picture's first piece,
    // which then starts in a later draw under a budget (where its own estimate fits or waits).
    const int framebuffer = work ? makeFramebuffer() : 0;
    const bool deferred =
        work && (framebuffer < 0 || (framebuffer > 0 && budget_) ||
                 (budget_ && !budget_->fits(nextPieceMs(), reserveMs(), piecePatience_)));
    pictureDeferred_ = deferred;
    if (!deferred && dirtyPicture_)
        render();
    else if (!deferred && picturePending_)
        renderMore();
    const PixelRect v = area(fbWidth, fbHeight);
    const double showStart = budget_ ? budget_->spentMs() : 0.0;
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glDisable(GL_SCISSOR_TEST);
    glBlitFramebuffer(0, 0, fboW_, fboH_, v.x0, fbHeight - v.y1, v.x1, fbHeight - v.y0,
                      GL_COLOR_BUFFER_BIT, GL_NEAREST);
    if (budget_) {
        glFinish();  // timed: the copy is done
        showCost_.record(1, budget_->spentMs() - showStart);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fbWidth, fbHeight);
}

double Inspector::reserveMs() const { return budgetReserveMs_ + showCost_.estimateMs(1); }

void Inspector::panel(bool* open) {
    if (!ImGui::Begin("Inspector", open)) {
        ImGui::End();
        return;
    }
    bool changed = false;
    const bool regular = view_ && view_->scheme() == SchemeKind::Regular;
    const bool irregular = view_ && view_->scheme() == SchemeKind::Irregular;
    changed |= ImGui::Checkbox(irregular ? "slabs" : "regions", &opt_.regions);
    ImGui::SameLine();
    if (irregular) {
        changed |= ImGui::Checkbox("zones", &opt_.zones);
        ImGui::SameLine();
    }
    if (regular) {
        changed |= ImGui::Checkbox("directory", &opt_.grid);
        if (ImGui::IsItemHovered())
            ImGui::SetTooltip(
                "Directory entries: grey a single cell, teal a block stored as one\n"
                "entry, orange a block stored as a sub-table");
        ImGui::SameLine();
    }
    changed |= ImGui::Checkbox("boxes", &opt_.boxes);
    changed |= ImGui::Checkbox("frustum", &opt_.frustum);
    ImGui::SameLine();
    changed |= ImGui::Checkbox("surfaces", &opt_.surfaces);
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip(
            "The scene traced from the inspector's camera (exact CSG, primary rays);\n"
            "lines behind a surface are hidden");
    int by = int(opt_.colorBy);
    ImGui::TextUnformatted("colour by");
    ImGui::SameLine();
    ImGui::RadioButton("primitives", &by, 0);
    ImGui::SameLine();
    ImGui::RadioButton(irregular ? "slab index" : "level", &by, 1);
    if (by != int(opt_.colorBy)) {
        opt_.colorBy = ColorBy(by);
        changed = true;
    }
    if (regular) {
        const int top = std::max(model_.maxLevel, 1);
        changed |= ImGui::DragIntRange2("levels", &opt_.levelLo, &opt_.levelHi, 0.1f, 0, top);
    }
    if (irregular) {
        int only = opt_.zoneSlabsOnly ? 1 : 0;
        ImGui::TextUnformatted("slabs of");
        ImGui::SameLine();
        ImGui::RadioButton("every zone", &only, 0);
        ImGui::SameLine();
        ImGui::RadioButton("the selected zone", &only, 1);
        if (only != int(opt_.zoneSlabsOnly)) {
            opt_.zoneSlabsOnly = only == 1;
            changed = true;
        }
    }
    if (view_) {
        const Box3 b = view_->worldBounds();
        changed |= ImGui::Checkbox("slice", &opt_.slab.on);
        ImGui::SameLine();
        int axis = opt_.slab.axis;
        ImGui::RadioButton("x", &axis, 0);
        ImGui::SameLine();
        ImGui::RadioButton("y", &axis, 1);
        ImGui::SameLine();
        ImGui::RadioButton("z", &axis, 2);
        if (axis != opt_.slab.axis || (opt_.slab.lo == 0.0 && opt_.slab.hi == 0.0)) {
            opt_.slab.axis = axis;
            const double mid = 0.5 * (b.lo[axis] + b.hi[axis]);
            const double w = 0.05 * (b.hi[axis] - b.lo[axis]);
            opt_.slab.lo = mid - w;
            opt_.slab.hi = mid + w;
            changed = true;
        }
        if (opt_.slab.on) {
            float lo = float(opt_.slab.lo), hi = float(opt_.slab.hi);
            const float speed = float(b.hi[axis] - b.lo[axis]) / 400.0f;
            if (ImGui::DragFloatRange2("slab", &lo, &hi, speed, float(b.lo[axis]),
                                       float(b.hi[axis]), "%.4g")) {
                opt_.slab.lo = lo;
                opt_.slab.hi = hi;
                changed = true;
            }
        }
    }
    if (ImGui::InputInt("cap", &opt_.cap, 1000, 10000)) {
        opt_.cap = std::clamp(opt_.cap, 0, 5000000);
        changed = true;
    }
    if (ImGui::IsItemHovered())
        ImGui::SetTooltip("Regions (and blocks, boxes) drawn at most, among those in view");
    ImGui::Text("%zu of %zu regions drawn%s", model_.regions.size(), model_.total,
                model_.kept > model_.regions.size() ? " (cap reached)" : "");
    if (selected_ >= 0) ImGui::Text("selected: region %lld", (long long)selected_);
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyleColorVec4(ImGuiCol_TextDisabled));
    ImGui::TextWrapped(
        "Over the inspector: left drag orbits, middle drag pans, right drag or wheel zooms, a "
        "click selects the region under the cursor.");
    ImGui::PopStyleColor();
    ImGui::End();
    if (changed) dirtyModel_ = true;
}

}  // namespace lancer::viewer::inspector
