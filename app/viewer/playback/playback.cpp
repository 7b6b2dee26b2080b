#include "app/viewer/playback/playback.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

namespace lancer::viewer::playback {

WalkCounts countsOf(const TracedRay& r) {
    WalkCounts c;
    for (const WalkEvent& e : r.events) {
        if (e.kind() == WalkEvent::PrimTest) ++c.primTests;
        if (e.kind() == WalkEvent::MailboxHit) ++c.mailboxHits;
        if (e.kind() == WalkEvent::Region) ++c.regions;
    }
    return c;
}

void RayPlayback::setTree(const PickedPixel& pixel, RayTree tree) {
    pixel_ = pixel;
    tree_ = std::move(tree);
    ++version_;
    previous_.clear();
    playing_ = false;
    carried_ = 0.0;
    if (!empty()) setState(0, 0);
}

void RayPlayback::retrace(RayTree tree) {
    previous_.clear();
    for (const TracedRay& r : tree_.rays) previous_.push_back(countsOf(r));
    const PlaybackState was = state_;
    tree_ = std::move(tree);
    ++version_;
    if (empty()) return;
    setState(std::min(was.ray, int(tree_.rays.size()) - 1), std::max(was.step, 0));
}

void RayPlayback::clear() {
    tree_ = RayTree{};
    ++version_;
    steps_.clear();
    previous_.clear();
    state_ = PlaybackState{};
    playing_ = false;
}

void RayPlayback::setState(int ray, int step) {
    state_.ray = ray;
    steps_ = tree_.rays[size_t(ray)].regionSteps();
    const size_t events = tree_.rays[size_t(ray)].events.size();
    if (steps_.empty()) {
        // A ray that walks no region (the light buffer cleared it, or it misses the structure):
        // its one state shows all of its events.
        state_.step = -1;
        state_.eventBegin = 0;
        state_.eventEnd = events;
        return;
    }
    state_.step = std::clamp(step, 0, int(steps_.size()) - 1);
    // A step runs from its Region event to the next one; the last step takes the ray's end.
    state_.eventBegin = steps_[size_t(state_.step)];
    state_.eventEnd =
        size_t(state_.step) + 1 < steps_.size() ? steps_[size_t(state_.step) + 1] : events;
}

void RayPlayback::selectRay(int k) {
    if (empty()) return;
    setState(std::clamp(k, 0, int(tree_.rays.size()) - 1), 0);
    playing_ = false;
}

void RayPlayback::seek(int k) {
    if (empty()) return;
    setState(state_.ray, k);
}

bool RayPlayback::forward() {
    if (empty() || state_.step + 1 >= stepCount()) return false;
    setState(state_.ray, state_.step + 1);
    return true;
}

bool RayPlayback::back() {
    if (empty() || state_.step <= 0) return false;
    setState(state_.ray, state_.step - 1);
    return true;
}

void RayPlayback::play() {
    if (empty()) return;
    // Play from the start once the end was reached, as a media player does.
    if (state_.step + 1 >= stepCount()) first();
    playing_ = stepCount() > 1;
    carried_ = 0.0;
}

void RayPlayback::setSpeed(double stepsPerSecond) {
    speed_ = std::clamp(stepsPerSecond, 0.1, 100.0);
}

bool RayPlayback::advance(double seconds) {
    if (!playing_) return false;
    carried_ += std::max(seconds, 0.0) * speed_;
    bool moved = false;
    while (carried_ >= 1.0) {
        carried_ -= 1.0;
        if (!forward()) {
            playing_ = false;
            break;
        }
        moved = true;
    }
    if (state_.step + 1 >= stepCount()) playing_ = false;
    return moved;
}

const walk::Region* RayPlayback::region() const {
    if (empty() || state_.step < 0) return nullptr;
    return &ray().events[state_.eventBegin].as<walk::Region>();
}

std::optional<WalkCounts> RayPlayback::previousCounts(int k) const {
    if (k < 0 || size_t(k) >= previous_.size()) return std::nullopt;
    return previous_[size_t(k)];
}

std::vector<uint32_t> visitedRegions(const RayPlayback& play) {
    std::vector<uint32_t> ids;
    if (play.empty()) return ids;
    for (size_t e : play.steps()) ids.push_back(play.ray().events[e].as<walk::Region>().region);
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
}

std::vector<SpanRow> stepSpans(const RayPlayback& play) {
    std::vector<SpanRow> rows;
    if (play.empty() || play.state().step < 0) return rows;
    const std::vector<WalkEvent>& ev = play.ray().events;
    for (size_t i = play.state().eventBegin; i < play.state().eventEnd; ++i) {
        if (const auto* test = ev[i].get<walk::PrimTest>()) {
            rows.push_back({test->prim, false, test->spans});
        } else if (const auto* mail = ev[i].get<walk::MailboxHit>()) {
            // The mailbox holds the spans of this primitive's last test along the ray.
            SpanRow r{mail->prim, true, {}};
            for (size_t j = i; j-- > 0;) {
                const auto* earlier = ev[j].get<walk::PrimTest>();
                if (earlier && earlier->prim == mail->prim) {
                    r.spans = earlier->spans;
                    break;
                }
            }
            rows.push_back(std::move(r));
        } else if (const auto* spans = ev[i].get<walk::Spans>()) {
            rows.push_back({kNoPrim, false, spans->spans});
        }
    }
    return rows;
}

const std::vector<StepCsg>& RayCsgCache::steps(const RayPlayback& play, const StructureView& view) {
    const int ray = play.empty() ? -1 : play.state().ray;
    if (version_ == play.treeVersion() && ray_ == ray && view_ == &view) return steps_;
    version_ = play.treeVersion();
    ray_ = ray;
    view_ = &view;
    steps_.clear();
    waste_ = RayWaste{};
    if (ray >= 0) {
        steps_ = rayCsg(view.scene(), view, play.ray());
        waste_ = wastedWork(view.scene(), play.ray(), steps_);
    }
    return steps_;
}

namespace {

/// The spans hold the ray's hit as one of their boundaries.
bool holdsHit(const SpanList& spans, const Hit& hit) {
    for (const Span& s : spans)
        for (const Boundary& b : {s.in, s.out})
            if (b.t == hit.t && b.prim == hit.prim) return true;
    return false;
}

}  // namespace

std::vector<StripRow> regionStrip(const std::vector<StepCsg>& steps, const RayWaste& waste,
                                  const TracedRay& ray, int k) {
    std::vector<StripRow> rows;
    if (k < 0 || size_t(k) >= steps.size()) return rows;
    const StepCsg& s = steps[size_t(k)];
    // The step that found the hit: the ray's last, its first boundary the hit.
    const bool hitHere = size_t(k) + 1 == steps.size() && ray.hit.valid() && s.first &&
                         s.first->t == ray.hit.t && s.first->prim == ray.hit.prim;
    // The primitives as read, each test with its class (tests come in event order).
    size_t next = s.event + 1;
    for (const PrimSpans& p : s.inputs) {
        StripRow r;
        r.prim = p.prim;
        r.mailbox = p.mailbox || s.carried;
        r.spans = p.spans;
        r.onHit = hitHere && p.prim == ray.hit.prim && holdsHit(p.spans, ray.hit);
        if (!r.mailbox) {
            auto testOf = [&](size_t i) {
                const auto* test = ray.events[i].get<walk::PrimTest>();
                return test && test->prim == p.prim;
            };
            while (next < ray.events.size() && !testOf(next)) ++next;
            if (next < waste.perEvent.size()) r.waste = waste.perEvent[next++];
        }
        rows.push_back(std::move(r));
    }
    for (const NodeSpans& n : s.nodes) {
        StripRow r;
        r.node = true;
        r.op = n.op;
        r.prim = n.prim;
        r.depth = n.depth;
        r.evaluated = n.evaluated;
        r.spans = n.spans;
        r.onHit = hitHere && holdsHit(n.spans, ray.hit);
        rows.push_back(std::move(r));
    }
    return rows;
}

RayStrip rayStrip(const std::vector<StepCsg>& steps, const RayWaste& waste, const TracedRay& ray) {
    RayStrip out;
    std::vector<uint32_t> order;  // primitives in the order first read
    std::unordered_map<uint32_t, size_t> rowOf;
    StripRow result;
    result.node = true;
    for (size_t k = 0; k < steps.size(); ++k) {
        const StepCsg& s = steps[k];
        out.bands.push_back({s.t0, s.t1, s.region, int(k)});
        for (const PrimSpans& p : s.inputs) {
            auto [it, fresh] = rowOf.emplace(p.prim, out.rows.size());
            if (fresh) {
                StripRow r;
                r.prim = p.prim;
                r.mailbox = true;
                r.spans = p.spans;
                out.rows.push_back(std::move(r));
            }
        }
        // The result the walk used here: the tree's spans inside the step's window.
        if (!s.evaluated) continue;
        for (const Span& sp : s.result) {
            if (sp.out.t < s.lo || sp.in.t > s.hi) continue;
            Span c = sp;
            if (c.in.t < s.lo) c.in.t = s.lo;
            if (c.out.t > s.hi) c.out.t = s.hi;
            result.spans.push_back(c);
        }
    }
    // Each primitive's first test: tested (not only read from the mailbox), and its class.
    for (size_t i = 0; i < ray.events.size(); ++i) {
        const auto* test = ray.events[i].get<walk::PrimTest>();
        if (!test) continue;
        auto it = rowOf.find(test->prim);
        if (it == rowOf.end()) continue;
        StripRow& r = out.rows[it->second];
        if (!r.mailbox) continue;
        r.mailbox = false;
        r.waste = i < waste.perEvent.size() ? waste.perEvent[i] : Waste::None;
    }
    if (ray.hit.valid())
        for (StripRow& r : out.rows) r.onHit = r.prim == ray.hit.prim && holdsHit(r.spans, ray.hit);
    result.onHit = ray.hit.valid() && holdsHit(result.spans, ray.hit);
    out.rows.push_back(std::move(result));
    return out;
}

std::vector<TestedBox> testedBoxes(const RayPlayback& play, const Scene& scene) {
    std::vector<TestedBox> out;
    if (play.empty() || play.state().step < 0) return out;
    const std::vector<WalkEvent>& ev = play.ray().events;
    for (size_t i = play.state().eventBegin; i < play.state().eventEnd; ++i) {
        const auto* test = ev[i].get<walk::PrimTest>();
        const auto* mail = ev[i].get<walk::MailboxHit>();
        if (!test && !mail) continue;
        const uint32_t prim = test ? test->prim : mail->prim;
        if (prim >= scene.minBox.size() || scene.minBox[prim].isEmpty()) continue;
        out.push_back({prim, scene.minBox[prim], mail != nullptr});
    }
    return out;
}

namespace {

/// A word or a path as one shell argument: quoted unless made of safe characters only.
std::string shellWord(const std::string& s) {
    const bool safe = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) ||
               std::string("-_./:,=+@").find(c) != std::string::npos;
    });
    if (safe) return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

}  // namespace

std::string traceCommand(const std::string& scene, const std::string& cameraFile,
                         const PickedPixel& px, const BuildParams& b, const ShadingOptions& sh) {
    std::ostringstream os;
    os.precision(17);
    os << "lancer trace " << shellWord(scene) << " --camera " << shellWord(cameraFile)
       << " --width " << px.width << " --height " << px.height << " --pixel " << px.x << " " << px.y
       << " --scheme " << toString(b);  // the scheme, its own knobs, mailboxes, light buffer
    os << " --bounces " << sh.bounces << " --offset " << sh.offsetScale;
    if (!sh.shadows) os << " --no-shadows";
    if (!sh.reflections) os << " --no-reflections";
    if (!sh.refractions) os << " --no-refractions";
    return os.str();
}

}  // namespace lancer::viewer::playback
