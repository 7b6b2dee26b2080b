#include "app/viewer/viewer_state.h"

#include <imgui.h>
#include <imgui_internal.h>  // MarkIniSettingsDirty

#include <cmath>
#include <iostream>

#include "app/viewer/camera_control.h"
#include "engine/accel/structure_view.h"
#include "engine/scene/builtin_scenes.h"

namespace lancer::viewer {

namespace {

double msSince(ViewerState::Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(ViewerState::Clock::now() - t).count();
}

}  // namespace

ViewerState::ViewerState(ViewerSettings& settings, bool logTimings, std::function<void()> wake)
    : s_(settings), logTimings_(logTimings), wake_(wake) {
    if (wake) {
        renderer_.setOnPass(wake);
        builder_.setOnReady(wake);
    }
    notes_.pathInput = isBuiltinSpec(s_.scene) ? "" : s_.scene;
    requestBuild(true, "open scene");
}

ViewerState::~ViewerState() {
    if (speedup_) speedup_->cancel = true;
    if (speedupThread_.joinable()) speedupThread_.join();
    if (costJob_) costJob_->cancel = true;
    if (costThread_.joinable()) costThread_.join();
    renderer_.cancel();
}

void ViewerState::logTiming(const std::string& line) const {
    if (logTimings_) std::cerr << "timing: " << line << std::endl;
}

void ViewerState::openScene(const std::string& spec) {
    s_.scene = spec;
    if (!isBuiltinSpec(spec)) notes_.pathInput = spec;  // a dropped file shows
    ImGui::MarkIniSettingsDirty();
    requestBuild(true, "open scene");
}

void ViewerState::setViewMode(ViewMode mode) {
    s_.mode = mode;
    // The other counter is uploaded whole (rows uploaded earlier hold the old one).
    uploadDue_ = true;
    changed_.add(0, shown_.height);
    updateAutoScale();
    if (s_.mode != ViewMode::Color && s_.autoScale) scale_ = autoScale_;
}

void ViewerState::updateAutoScale() {
    if (s_.mode == ViewMode::Color) return;
    const compare::CounterImage* old = diff_.old();
    if (abStatus_.comparable && ab_ == compare::AbView::Diff) {
        autoScale_ = decadeScale(compare::diffAutoScale(
            compare::diffChannel(*old, shown_, s_.mode, 0, abStatus_.rows, abStatus_.rows)));
        return;
    }
    autoScale_ = autoScale(heatChannel(shown_, s_.mode));
    if (abStatus_.comparable) {
        // One scale for both images, so flipping between them compares colours.
        if (oldScaleGeneration_ != diff_.generation()) {
            for (int m = 1; m < kViewModeCount; ++m)
                oldScale_[m] = autoScale(compare::counterChannel(*old, ViewMode(m), 0, -1));
            oldScaleGeneration_ = diff_.generation();
        }
        autoScale_ = std::max(autoScale_, oldScale_[int(s_.mode)]);
    }
    // Whole decades: the key reads 1, 10, 100, ..., and a rebuild that keeps the 99th
    // percentile within its decade keeps the colours.
    autoScale_ = decadeScale(autoScale_);
}

void ViewerState::setAbView(compare::AbView v) {
    ab_ = v;
    uploadDue_ = true;
    changed_.add(0, shown_.height);
    updateAutoScale();
    if (s_.mode != ViewMode::Color && s_.autoScale) scale_ = autoScale_;
}

bool ViewerState::heatDiverging() const {
    return s_.mode != ViewMode::Color &&
           (ab_ == compare::AbView::Diff || (ab_ == compare::AbView::Old && !abStatus_.comparable));
}

std::vector<float> ViewerState::heatRows(int rowBegin, int rowEnd) const {
    if (s_.mode == ViewMode::Color) return {};
    const compare::CounterImage* old = diff_.old();
    if (ab_ == compare::AbView::New) return heatChannel(shown_, s_.mode, rowBegin, rowEnd);
    if (!abStatus_.comparable) {  // nothing to show: every pixel "not compared"
        size_t first, last;
        shown_.pixelRange(rowBegin, rowEnd, first, last);
        return std::vector<float>(last - first, kNoDiff);
    }
    if (ab_ == compare::AbView::Old)
        return compare::counterChannel(*old, s_.mode, rowBegin, rowEnd);
    return compare::diffChannel(*old, shown_, s_.mode, rowBegin, rowEnd, abStatus_.rows);
}

bool ViewerState::updateAb() {
    // Rows of the render on screen done at full resolution, when it is the latest job's (the
    // new structure's): the rows B has to compare.
    const bool current = shownJob_ == startedJob_ && startedJob_ != 0 && !renderDirty_;
    const int done = current && shownStride_ == 1 ? shownRows_ : 0;
    abStatus_ = diff_.status(jobKey_, done);
    // What the heat map compares changed: the whole image is uploaded again (within a pass,
    // the bands uploaded as they come cover the rows that start to compare).
    uint64_t sig = uint64_t(ab_) | uint64_t(abStatus_.comparable) << 2 | uint64_t(done > 0) << 3 |
                   uint64_t(s_.mode) << 4 | diff_.generation() << 8;
    sig = sig * 1000003u ^ startedJob_;
    const bool changed = sig != abSignature_;
    if (changed) {
        abSignature_ = sig;
        if (ab_ != compare::AbView::New) {
            uploadDue_ = true;
            changed_.add(0, shown_.height);
        }
    }
    if (!changed && !snapped_) return false;
    abTotals_ = {};
    if (!abStatus_.comparable) return changed;
    const compare::CounterImage& old = *diff_.old();
    abTotals_.a = compare::sumRows(old, abStatus_.rows);
    abTotals_.b = compare::sumRows(shown_, abStatus_.rows);
    abTotals_.complete = abStatus_.rows == abStatus_.height && shownComplete_;
    if (abTotals_.complete) {
        abTotals_.aCounters = old.counters;
        abTotals_.aRenderMs = old.renderMs;
        for (const PassRecord& p : renderer_.passes()) {
            abTotals_.bCounters += p.counters;
            abTotals_.bRenderMs += p.renderMs;
        }
    }
    return changed;
}

void ViewerState::setHeatScale(float scale) {
    s_.autoScale = false;
    s_.heatScale = scale;
}

void ViewerState::setCamera(const Camera& c) {
    camera_ = c;
    markRender("camera");
    if (s_.build.scheme == SchemeKind::Irregular) cameraMovedForBuild_ = true;
}

void ViewerState::copyCameraJson() { ImGui::SetClipboardText(camera_.toJson().c_str()); }

bool ViewerState::pasteCameraJson() {
    const char* clip = ImGui::GetClipboardText();
    notes_.cameraJson = clip ? clip : "";
    try {
        setCamera(cameraFromJson(notes_.cameraJson, camera_));
        notes_.cameraError.clear();
        return true;
    } catch (const std::exception& e) {
        notes_.cameraError = e.what();
        return false;
    }
}

void ViewerState::requestBuild(bool reloadScene, const char* why) {
    BuildRequest r;
    r.params = s_.build;
    if (reloadScene || !sceneBuild_) {
        r.spec = s_.scene;
        r.cameraFile = s_.cameraPath;
        r.read = s_.read;
    } else {
        r.spec = sceneBuild_->spec;
        r.loaded = sceneBuild_->scene;
        r.camera = camera_;
        r.previous = sceneBuild_->accel;
    }
    buildChangeAt_ = Clock::now();
    buildWhy_ = why;
    builder_.request(std::move(r));
}

void ViewerState::markRender(const char* why) {
    renderDirty_ = true;
    renderWhy_ = why;
    changeAt_ = Clock::now();
}

void ViewerState::restartRender(const char* why) {
    if (!sceneBuild_ || jobWidth_ <= 0 || jobHeight_ <= 0) return;
    ProgressiveJob job;
    job.scene = sceneBuild_->scene;
    job.accel = sceneBuild_->accel;
    job.options.width = jobWidth_;
    job.options.height = jobHeight_;
    job.options.threads = s_.threads;
    job.options.shading = s_.shading;
    job.options.camera = camera_;
    if (speedup_ && !speedup_->done) speedup_->cancel = true;  // its view is gone
    if (costJob_ && !costJob_->done) costJob_->cancel = true;  // its image is gone
    jobOptions_ = job.options;
    jobBuild_ = sceneBuild_;
    jobKey_ = {sceneBuild_->spec, camera_, jobWidth_, jobHeight_, s_.shading};
    jobParams_ = sceneBuild_->accel->params();
    renderer_.start(std::move(job), changeAt_);
    startedJob_ = renderer_.job();
    changeWhy_ = why;
    passesLogged_ = 0;
    renderDirty_ = false;
}

void ViewerState::poll() {
    // Read before taking the snapshot: if the job was finished then, the snapshot below is final.
    finishedBefore_ = renderer_.finished();
    // Likewise: a builder idle before the poll has nothing left that this frame has not taken.
    builtBefore_ = !builder_.busy();
    pollBuilder();
    takeSnapshot();
    takeCosts();
    // The A/B's status follows the job and snapshot; its totals and the scale only change with
    // a snapshot or what is compared.
    if (updateAb() || snapped_) updateAutoScale();
    snapped_ = false;
    if (s_.mode != ViewMode::Color) scale_ = s_.autoScale ? autoScale_ : s_.heatScale;
}

bool ViewerState::takeUpload(RowRange& rows) {
    rows = changed_;
    const bool due = uploadDue_;
    changed_ = {};
    uploadDue_ = false;
    return due;
}

void ViewerState::pollBuilder() {
    std::optional<BuildResult> r = builder_.poll();
    if (!r) return;
    const bool first = !started_;
    started_ = true;
    if (r->sceneBuild) {
        const bool newScene = !sceneBuild_ || sceneBuild_->spec != r->sceneBuild->spec;
        logTiming(buildWhy_ + ": structure ready " + std::to_string(msSince(buildChangeAt_)) +
                  " ms after the change (load " + std::to_string(r->sceneBuild->loadMs) +
                  " ms, build " + std::to_string(r->sceneBuild->accel->info().buildMs) + " ms)");
        if (newScene) {
            diff_.clear();
        } else if (sceneBuild_) {
            // The image on screen is the old structure's: A, if it is complete (the last band
            // may still wait in the renderer: take it first).
            takeSnapshot(true);
            const bool complete = shownComplete_ && shownJob_ == startedJob_ && !renderDirty_;
            diff_.rebuilt(shown_, complete, jobKey_, jobParams_,
                          complete ? renderer_.passes() : std::vector<PassRecord>{});
        }
        sceneBuild_ = r->sceneBuild;
        if (newScene) {
            s_.cameraPath.clear();  // --camera is the first scene's, not the next ones'
            home_ = sceneBuild_->scene->camera;
            camera_ = home_;
            s_.scene = sceneBuild_->spec;
            // What the panels said of the previous scene no longer applies.
            notes_.builtinSize = -1;
            notes_.cameraError.clear();
            notes_.screenshotNote.clear();
            if (speedup_) speedup_->cancel = true;
            speedup_.reset();
        }
        if (sceneBuild_->accel->params().scheme == s_.build.scheme) error_.clear();
        changeAt_ = buildChangeAt_;
        renderDirty_ = true;
        renderWhy_ = buildWhy_;
        return;
    }
    error_ = (r->sceneFailed ? "Scene not loaded: " : "Structure not built: ") + r->error;
    if (r->sceneFailed) s_.cameraPath.clear();
    std::cerr << "lancer view: " << error_ << "\n";
    if (sceneBuild_) {
        // Keep what is on screen, and the settings that describe it.
        if (r->sceneFailed)
            s_.scene = sceneBuild_->spec;
        else
            s_.build = sceneBuild_->accel->params();
    } else if (!r->sceneFailed && first) {
        // The structure the run starts with is refused: the options are wrong, and a
        // brute-force image in its place would hide it (the run ends, window.cpp).
        startRefusal_ = r->error;
    } else if (!r->sceneFailed && s_.build.scheme != SchemeKind::Brute) {
        // Nothing on screen yet: show the scene with the reference scheme meanwhile.
        s_.build.scheme = SchemeKind::Brute;
        requestBuild(true, "fallback to brute force");
    }
}

bool ViewerState::takeSnapshot(bool whole) {
    ProgressiveRenderer::Shown what;
    // A pass comes in parts: a whole 1280x720 image (32 bytes a pixel) took 13-17 ms of the UI
    // thread to copy, and its conversion and upload as much again. A new view's rows are held
    // off the screen (holdImage) until the last part is in, never mixed with the old view's.
    // A drag may bring a new view every frame: the renderer keeps the view begun for the
    // parts still to come, so each view begun is finished in parts (taking one whole every
    // third frame, to show one, took 40-45 ms of CPU). shown_ has the render's size before
    // its first pass (startWork), so the first image of a size comes in parts too.
    const int maxRows =
        whole || shown_.width <= 0 ? 0 : std::max(1, kSnapshotPixels / shown_.width);
    if (!renderer_.snapshot(shownVersion_, shown_, &what, maxRows)) return false;
    snapshotBehind_ = what.behind || what.stale;
    holding_ = what.behind && (holding_ || what.job != screenJob_);
    if (!what.behind) screenJob_ = what.job;
    uploadDue_ = true;
    changed_.add(what.changedBegin, what.changedEnd < 0 ? shown_.height : what.changedEnd);
    shownJob_ = what.job;
    shownStride_ = what.stride;
    shownRows_ = what.rows;
    shownComplete_ = what.stride == 1 && what.rows >= shown_.height;
    snapped_ = true;
    if (!logTimings_) return true;
    // Passes this snapshot holds whole (one may have finished since it was taken), logged once
    // the frame showing them is on screen (presented()).
    if (what.job != startedJob_) return true;  // a replaced job's: its passes are gone
    std::vector<PassRecord> passes = renderer_.passes();
    for (; passesLogged_ < passes.size(); ++passesLogged_) {
        const PassRecord& p = passes[passesLogged_];
        if (p.stride < what.stride || (p.stride == what.stride && what.rows < shown_.height)) break;
        pendingLogs_.push_back(
            {changeWhy_ + ": pass stride " + std::to_string(p.stride) + " visible ",
             " ms after the change (pass render " + std::to_string(p.renderMs) + " ms, " +
                 std::to_string(shown_.width) + "x" + std::to_string(shown_.height) + ")",
             changeAt_});
        if (p.stride == 1)
            pendingLogs_.push_back(
                {changeWhy_ + ": full image ", " ms after the change", changeAt_});
    }
    return true;
}

std::optional<std::pair<int, int>> ViewerState::pixelUnderMouse() const {
    const ImGuiIO& io = ImGui::GetIO();
    if (!ImGui::IsMousePosValid()) return std::nullopt;
    // Framebuffer pixels, then the image's: the viewport's corner is the image's pixel (0, 0).
    const int x = int(std::floor(io.MousePos.x * io.DisplayFramebufferScale.x)) - imageArea_.x0;
    const int y = int(std::floor(io.MousePos.y * io.DisplayFramebufferScale.y)) - imageArea_.y0;
    if (x < 0 || y < 0 || x >= imageArea_.x1 - imageArea_.x0 || y >= imageArea_.y1 - imageArea_.y0)
        return std::nullopt;
    return std::pair{x, y};
}

void ViewerState::startWork(int fbWidth, int fbHeight) {
    if (fbWidth > 0 && fbHeight > 0 && (fbWidth != jobWidth_ || fbHeight != jobHeight_)) {
        jobWidth_ = fbWidth;
        jobHeight_ = fbHeight;
        if (!renderDirty_) markRender("window size");  // else keep the pending change's time
        // The image of the new size made now, frames before its first pass: its snapshots
        // then come in parts (held off the screen until whole) like any other. Made by the
        // first snapshot, it was a whole copy into a new image: 40-41 ms of CPU in one frame
        // (poll 14-15, upload 11, image 9-10; 2026-12-06, scripts/frame-times).
        shown_ = Image(jobWidth_, jobHeight_);
        // Rows of the old size not uploaded yet: the screen keeps its picture until the new
        // size's is whole.
        changed_.clear();
        uploadDue_ = false;
        shownComplete_ = false;
    }
    // The irregular scheme's regions live in the camera frame: rebuild once the drag ends.
    if (cameraMovedForBuild_ && !ImGui::IsAnyMouseDown()) {
        cameraMovedForBuild_ = false;
        if (s_.build.scheme == SchemeKind::Irregular)
            requestBuild(false, "camera (irregular frame)");
    }
    if (renderDirty_ && sceneBuild_) {
        restartRender(renderWhy_.c_str());
        finishedBefore_ = false;  // the snapshot of this frame is of the job just cancelled
        // The frame does not wait for the first pass: the worker wakes the window when it is
        // ready, and the next frame shows it. (Waiting up to 40 ms here, to show it in this
        // frame, saved about 5 ms of latency on balls4 and cost a frame of up to 40 ms at
        // every change: below 60 frames a second.)
    }
    updateCosts();
}

void ViewerState::takeCosts() {
    if (costJob_ && costJob_->done) {
        if (costThread_.joinable()) costThread_.join();
        if (!costJob_->cancel) {
            costsTriedJob_ = costJob_->job;
            costsTriedRays_ = costJob_->rays;
            costsError_ = costJob_->error;
            if (costJob_->result) costs_ = costJob_->result;
            if (costJob_->result)
                logTiming("region costs counted in " + std::to_string(costs_->ms) + " ms");
        }
        costJob_.reset();
    }
}

void ViewerState::updateCosts() {
    takeCosts();
    costsDue_ = false;
    if (!costsWanted_) return;
    const CostRays rays = *costsWanted_;
    costsWanted_.reset();
    // Only a complete image: its counts are the render's (a coarse pass's are not the image's).
    const bool complete = jobBuild_ && shownComplete_ && shownJob_ == startedJob_ &&
                          !renderDirty_ && renderer_.finished() && jobBuild_ == sceneBuild_;
    if (!complete) return;
    if (costsTriedJob_ == shownJob_ && costsTriedRays_ == rays) return;  // done (or failed)
    costsDue_ = true;
    if (costJob_ && costJob_->job == shownJob_ && costJob_->rays == rays) return;  // under way
    if (costJob_) costJob_->cancel = true;
    if (costThread_.joinable()) costThread_.join();
    auto job = std::make_shared<CostJob>();
    job->job = shownJob_;
    job->rays = rays;
    costJob_ = job;
    std::shared_ptr<const SceneBuild> build = jobBuild_;
    RenderOptions opt = jobOptions_;
    std::function<void()> wake = wake_;
    costThread_ = std::thread([job, build, opt, wake] {
        lowerThreadPriority();
        try {
            const auto t0 = Clock::now();
            auto r = std::make_shared<ImageCosts>();
            r->build = build;
            r->job = job->job;
            const size_t regions = StructureView(*build->scene, *build->accel).regionCount();
            if (countRegionCosts(*build->scene, *build->accel, opt, regions, job->rays, r->costs,
                                 &job->cancel)) {
                r->ms = msSince(t0);
                job->result = r;
            }
        } catch (const std::exception& e) {
            job->error = e.what();
        }
        job->done = true;
        if (wake) wake();
    });
}

bool ViewerState::settledSince() const {
    return builtBefore_ && !builder_.busy() && !costsDue_ && !snapshotBehind_ &&
           (!sceneBuild_ || (!renderDirty_ && finishedBefore_ && renderer_.finished()));
}

bool ViewerState::eager(bool settled) const {
    if (builder_.busy() || builder_.ready() || renderDirty_ || shownJob_ != renderer_.job() ||
        snapshotBehind_)
        return true;
    const ProgressiveRenderer::Shown next = renderer_.latest();
    return next.stride != shownStride_ || (renderer_.finished() && !settled);
}

void ViewerState::presented() {
    for (const PendingLog& l : pendingLogs_)
        logTiming(l.before + std::to_string(msSince(l.since)) + l.after);
    pendingLogs_.clear();
}

void ViewerState::measureSpeedup(int stride) {
    if (!sceneBuild_) return;
    notes_.speedupStride = stride;
    if (speedupThread_.joinable()) speedupThread_.join();
    auto sp = std::make_shared<SpeedupJob>();
    sp->stride = stride;
    sp->result.scheme = schemeName(sceneBuild_->accel->params().scheme);
    speedup_ = sp;
    RenderOptions opt;
    opt.width = jobWidth_;
    opt.height = jobHeight_;
    opt.threads = s_.threads;
    opt.shading = s_.shading;
    opt.camera = camera_;
    std::shared_ptr<const SceneBuild> st = sceneBuild_;
    // As `lancer bench` measures it, on the pixels of the current view the panel samples.
    speedupThread_ = std::thread([sp, st, opt] {
        lowerThreadPriority();
        try {
            BuildParams bp = st->accel->params();
            bp.scheme = SchemeKind::Brute;
            auto brute = buildAccelerator(*st->scene, bp);
            Image img(opt.width, opt.height);
            const bench::SpeedupBaseline baseline(*st->scene, *brute, opt,
                                                  PassLattice{sp->stride, 0}, img, &sp->cancel);
            SpeedupResult& r = sp->result;
            r.speedup = baseline.measure(*st->accel, img);
            if (r.speedup.cancelled()) r.error = "cancelled: the view changed";
        } catch (const std::exception& e) {
            sp->result.error = e.what();
        }
        sp->done = true;
    });
}

std::optional<SpeedupResult> ViewerState::speedupResult() const {
    if (!speedup_ || !speedup_->done) return std::nullopt;
    return speedup_->result;
}

}  // namespace lancer::viewer
