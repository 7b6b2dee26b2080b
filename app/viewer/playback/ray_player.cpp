#include "app/viewer/playback/ray_player.h"

#include <fstream>

namespace lancer::viewer::playback {

RayTree RayPlayer::trace(const ViewerState& st, int x, int y) const {
    const SceneBuild& b = *st.sceneBuild();
    return tracePixel(*b.scene, *b.accel, st.settings().shading, st.camera(), x, y, st.width(),
                      st.height());
}

bool RayPlayer::update(const ViewerState& st, double seconds) {
    const std::shared_ptr<const SceneBuild>& build = st.sceneBuild();
    bool changed = false;
    if (pending_ && build && st.width() > 0 && st.height() > 0) {
        const ScriptedPick p = *pending_;
        pending_.reset();
        if (p.x < 0 || p.y < 0 || p.x >= st.width() || p.y >= st.height()) {
            note_ = "pixel " + std::to_string(p.x) + " " + std::to_string(p.y) +
                    " is outside the " + std::to_string(st.width()) + "x" +
                    std::to_string(st.height()) + " image";
        } else {
            note_.clear();
            traced_ = build;
            view_ = std::make_unique<StructureView>(*build->scene, *build->accel);
            camera_ = st.camera();
            play_.setTree({p.x, p.y, st.width(), st.height()}, trace(st, p.x, p.y));
            if (scripted_) {
                // A scripted pick names a ray and a step that exist, or fails.
                const int rays = int(play_.tree().rays.size());
                if (p.ray >= rays) {
                    note_ = "--ray " + std::to_string(p.ray) + ": the pixel's tree has " +
                            std::to_string(rays) + " rays";
                    play_.clear();
                } else {
                    play_.selectRay(p.ray);
                    if (p.step < 0) {
                        play_.last();
                    } else if (p.step > 0 && p.step >= play_.stepCount()) {
                        note_ = "--step " + std::to_string(p.step) + ": ray " +
                                std::to_string(p.ray) + " has " +
                                std::to_string(play_.stepCount()) + " steps";
                        play_.clear();
                    } else {
                        play_.seek(p.step);
                    }
                }
            }
        }
        scripted_ = false;
        changed = true;
    } else if (!play_.empty() && build && build != traced_) {
        // A rebuild published a new structure: the same pixel, walked again in it, with the
        // image's size and camera as they are now (a rebuild for a moved camera walks the ray
        // the image now shows there).
        const PickedPixel px = play_.pixel();
        traced_ = build;
        view_ = std::make_unique<StructureView>(*build->scene, *build->accel);
        camera_ = st.camera();
        if (px.x < st.width() && px.y < st.height())
            play_.retrace(trace(st, px.x, px.y));
        else
            play_.clear();
        changed = true;
    }
    if (play_.advance(seconds)) changed = true;
    return changed;
}

std::string RayPlayer::copyTraceCommand(const ViewerState& st, const std::string& cameraFile) {
    if (play_.empty() || !traced_) {
        note_ = "no pixel picked";
        return "";
    }
    std::ofstream f(cameraFile);
    f << camera_.toJson() << "\n";
    if (!f) {
        note_ = "cannot write " + cameraFile;
        return "";
    }
    note_ = "camera written to " + cameraFile;
    return traceCommand(traced_->spec, cameraFile, play_.pixel(), traced_->accel->params(),
                        st.settings().shading);
}

}  // namespace lancer::viewer::playback
