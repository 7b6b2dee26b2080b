// The viewer's side of the ray playback: picks (a Shift+click on the image, the Ray panel's x y
// fields, `--pick`), tracing the picked pixel with the structure, shading, camera and size on
// screen, tracing it again when a rebuild publishes a new structure, and the playing clock. No
// GL: the frame draws rayBatch() of it (ray_drawing.h).
#pragma once

#include <memory>
#include <optional>

#include "app/viewer/playback/playback.h"
#include "app/viewer/viewer_state.h"
#include "engine/accel/structure_view.h"

namespace lancer::viewer::playback {

/// A scripted pick (`--pick X Y [--ray K] --step N`).
struct ScriptedPick {
    int x = 0, y = 0;
    int ray = 0;
    int step = 0;  ///< from 0; negative: the last step
};

class RayPlayer {
  public:
    /// Pick pixel (x, y) of the image on screen: traced at the next update().
    void pick(int x, int y) { pending_ = ScriptedPick{x, y, 0, 0}; }
    /// Pick, then select ray `s.ray` and stop at step `s.step` once traced.
    void pickScripted(const ScriptedPick& s) {
        pending_ = s;
        scripted_ = true;
    }
    /// Once a frame, before the panels: trace a pending pick, trace again after a rebuild, and
    /// play `seconds` of the clock. True when what is drawn changed.
    bool update(const ViewerState& st, double seconds);
    /// A pick is waiting for a structure or an image size.
    bool pending() const { return pending_.has_value(); }

    RayPlayback& playback() { return play_; }
    const RayPlayback& playback() const { return play_; }
    /// The structure the tree was traced in (null before the first pick).
    const StructureView* view() const { return view_.get(); }
    /// The played ray's steps with their node spans and its wasted work (empty before a pick).
    const std::vector<StepCsg>& csgSteps() {
        static const std::vector<StepCsg> none;
        return view_ ? csg_.steps(play_, *view_) : none;
    }
    /// The current step of csgSteps(), or null.
    const StepCsg* currentStep() {
        const std::vector<StepCsg>& steps = csgSteps();
        const int k = play_.state().step;
        return k >= 0 && size_t(k) < steps.size() ? &steps[size_t(k)] : nullptr;
    }
    /// The wasted work of the ray csgSteps() analysed.
    const RayWaste& waste() const { return csg_.waste(); }
    /// Why the last pick was refused (outside the image), or empty.
    const std::string& note() const { return note_; }

    /// The `lancer trace` command for the picked pixel, writing the camera to `cameraFile`.
    /// Empty (with note() set) when nothing is picked or the file cannot be written.
    std::string copyTraceCommand(const ViewerState& st, const std::string& cameraFile);

  private:
    RayTree trace(const ViewerState& st, int x, int y) const;

    RayPlayback play_;
    RayCsgCache csg_;
    std::optional<ScriptedPick> pending_;
    bool scripted_ = false;
    std::shared_ptr<const SceneBuild> traced_;  ///< the build the tree was traced in
    std::unique_ptr<StructureView> view_;
    Camera camera_;  ///< the camera the pixel was picked with
    std::string note_;
};

}  // namespace lancer::viewer::playback
