// Ray playback (playback.h): step k of every ray is the k-th region event `lancer trace --json`
// prints for the same scene, size, parameters and pixel, with the corners the playback draws
// (both schemes, shadow and reflection rays included); stepping back and forth returns the same
// states; playing takes `speed` steps a second and stops at the last; a retrace keeps the old
// walks' counts.
#include "app/viewer/playback/playback.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/cli/options.h"
#include "engine/accel/structure_view.h"
#include "engine/scene/loader.h"

namespace lancer::viewer::playback {
namespace {

std::string run(const std::string& cmd) {
    std::string out;
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return out;
    char buf[65536];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    pclose(p);
    return out;
}

struct Picked {
    int x, y;
    RayTree tree;
};

/// Pixels of the scene (a coarse sweep) whose trees hold a ray of `kind` that walks at least one
/// region; the first such pixel.
std::optional<Picked> findPixel(const Scene& scene, const Accelerator& accel,
                                const ShadingOptions& sh, int w, int h, RayKind kind) {
    for (int y = h / 32; y < h; y += h / 16)
        for (int x = w / 32; x < w; x += w / 16) {
            RayTree t = tracePixel(scene, accel, sh, scene.camera, x, y, w, h);
            for (const TracedRay& r : t.rays)
                if (r.kind == kind && r.regionSteps().size() > 1) return Picked{x, y, std::move(t)};
        }
    return std::nullopt;
}

/// A structure configuration: the scheme and, for each, its walk's variant.
struct Walk {
    SchemeKind scheme;
    StepMethod step = StepMethod::Exact;
    IrregularFrame frame = IrregularFrame::Projective;
};

std::string walkName(const Walk& c) {
    std::string s = schemeName(c.scheme);
    if (c.scheme == SchemeKind::Regular) s += std::string("_") + stepName(c.step);
    if (c.scheme == SchemeKind::Irregular) s += std::string("_") + irregularFrameName(c.frame);
    return s;
}

std::string walkOptions(const Walk& c) {
    return std::string(" --scheme ") + schemeName(c.scheme) + " --step " + stepName(c.step) +
           " --irregular-frame " + irregularFrameName(c.frame) + " --no-cost-stop";
}

class PlaybackTrace : public ::testing::TestWithParam<Walk> {};

// Every ray kind (primary, shadow, reflection, refraction): step k of the playback is the k-th
// region event of `lancer trace --json` (region, interval, corners), and the event's "why" is
// the reason the engine gives for that step (explainSteps), the one the Ray panel shows.
TEST_P(PlaybackTrace, StepKIsTheKthRegionEventOfLancerTrace) {
    const std::string spec = "builtin:default";
    cli::CommonOptions o;
    o.scene = spec;
    o.knobs.build.scheme = GetParam().scheme;
    o.knobs.build.regular.step = GetParam().step;
    o.knobs.build.irregular.frame = GetParam().frame;
    // The report's split rule: the cost rule leaves builtin:default 2 leaves, too few for rays
    // of every kind to cross a region boundary (--no-cost-stop sets both schemes').
    o.knobs.build.regular.costStop = false;
    o.knobs.build.irregular.costStop = false;
    Scene scene = loadScene(spec);
    auto accel = buildAccelerator(scene, o.knobs.build);
    int w, h;
    cli::resolveSize(o, scene, w, h);
    const StructureView view(scene, *accel);
    int compared = 0;
    for (RayKind kind :
         {RayKind::Primary, RayKind::Shadow, RayKind::Reflection, RayKind::Refraction}) {
        std::optional<Picked> p = findPixel(scene, *accel, o.knobs.shading, w, h, kind);
        ASSERT_TRUE(p) << "no pixel with a " << rayKindName(kind) << " ray that walks";
        RayPlayback play;
        play.setTree({p->x, p->y, w, h}, std::move(p->tree));
        const nlohmann::json j = nlohmann::json::parse(
            run(std::string(LANCER_BINARY) + " trace " + spec + walkOptions(GetParam()) +
                " --pixel " + std::to_string(p->x) + " " + std::to_string(p->y) + " --json"));
        ASSERT_EQ(j["width"].get<int>(), w);
        ASSERT_EQ(j["rays"].size(), play.tree().rays.size());
        for (size_t k = 0; k < play.tree().rays.size(); ++k) {
            play.selectRay(int(k));
            const nlohmann::json& jr = j["rays"][k];
            EXPECT_EQ(jr["kind"].get<std::string>(), rayKindName(play.ray().kind));
            std::vector<nlohmann::json> regions;
            for (const nlohmann::json& e : jr["events"])
                if (e["event"] == "region") regions.push_back(e);
            ASSERT_EQ(int(regions.size()), play.stepCount()) << "ray " << k;
            const std::vector<StepReason> why = explainSteps(play.ray(), view, &scene);
            for (int s = 0; s < play.stepCount(); ++s) {
                play.seek(s);
                const walk::Region* e = play.region();
                ASSERT_NE(e, nullptr);
                EXPECT_EQ(e->region, regions[size_t(s)]["region"].get<uint32_t>());
                EXPECT_EQ(e->t0, regions[size_t(s)]["t0"].get<double>());
                if (!regions[size_t(s)]["t1"].is_null()) {
                    EXPECT_EQ(e->t1, regions[size_t(s)]["t1"].get<double>());
                }
                EXPECT_EQ(why[size_t(s)].text, regions[size_t(s)]["why"].get<std::string>());
                // The region drawn is the one the trace describes: the same 8 corners.
                const std::array<Vec3, 8> c = view.regionCorners(e->region);
                const nlohmann::json& jc = regions[size_t(s)]["corners"];
                ASSERT_EQ(jc.size(), 8u);
                for (size_t i = 0; i < 8; ++i)
                    for (int a = 0; a < 3; ++a) EXPECT_EQ(c[i][a], jc[i][size_t(a)].get<double>());
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 3);
}

INSTANTIATE_TEST_SUITE_P(
    Schemes, PlaybackTrace,
    ::testing::Values(Walk{SchemeKind::Regular, StepMethod::Exact},
                      Walk{SchemeKind::Regular, StepMethod::Push},
                      Walk{SchemeKind::Irregular, StepMethod::Exact, IrregularFrame::Projective},
                      Walk{SchemeKind::Irregular, StepMethod::Exact, IrregularFrame::Camera}),
    [](const auto& info) { return walkName(info.param); });

/// A pixel's tree on the irregular scheme (whose primary rays walk several slabs), with a
/// primary ray of several steps.
RayPlayback someRay() {
    cli::CommonOptions o;
    o.knobs.build.scheme = SchemeKind::Irregular;
    Scene scene = loadScene("builtin:default");
    auto accel = buildAccelerator(scene, o.knobs.build);
    int w, h;
    o.scene = "builtin:default";
    cli::resolveSize(o, scene, w, h);
    std::optional<Picked> p;
    for (int y = 0; y < h && !p; y += h / 16)
        for (int x = 0; x < w && !p; x += w / 16) {
            RayTree t = tracePixel(scene, *accel, o.knobs.shading, scene.camera, x, y, w, h);
            if (t.rays[0].regionSteps().size() > 2) p = Picked{x, y, std::move(t)};
        }
    RayPlayback play;
    if (p) play.setTree({p->x, p->y, w, h}, std::move(p->tree));
    return play;
}

/// Step forward to the end and back to the start on the ray played: the states met going back
/// are those met going forward; the steps tile the ray's events.
void backAndForth(RayPlayback& play) {
    std::vector<PlaybackState> forward{play.state()};
    while (play.forward()) forward.push_back(play.state());
    EXPECT_EQ(int(forward.size()), play.stepCount());
    EXPECT_FALSE(play.forward());  // at the end: no move
    EXPECT_EQ(play.state(), forward.back());
    for (int k = int(forward.size()) - 1; k >= 0; --k) {
        EXPECT_EQ(play.state(), forward[size_t(k)]) << "step " << k;
        if (k > 0) {
            EXPECT_TRUE(play.back());
        }
    }
    EXPECT_FALSE(play.back());
    // Steps tile the ray's events from its first region on, each opening with its Region event.
    for (size_t k = 0; k < forward.size(); ++k) {
        EXPECT_EQ(play.ray().events[forward[k].eventBegin].kind(), WalkEvent::Region);
        if (k + 1 < forward.size()) {
            EXPECT_EQ(forward[k].eventEnd, forward[k + 1].eventBegin);
        }
    }
    EXPECT_EQ(forward.back().eventEnd, play.ray().events.size());
    play.last();
    EXPECT_EQ(play.state(), forward.back());
    play.first();
    EXPECT_EQ(play.state(), forward.front());
    // Seeking anywhere gives the state stepping there gave.
    for (size_t k = 0; k < forward.size(); k += 3) {
        play.seek(int(k));
        EXPECT_EQ(play.state(), forward[k]);
    }
}

TEST(Playback, SteppingBackAndForthReturnsTheSameStates) {
    RayPlayback play = someRay();
    ASSERT_FALSE(play.empty());
    ASSERT_GT(play.stepCount(), 2);
    backAndForth(play);
}

// Both schemes (and their walks' variants), every ray of trees holding every ray kind: stepping
// back and forth returns the same states.
TEST(Playback, SteppingBackAndForthReturnsTheSameStatesOnEveryRay) {
    int rays = 0;
    for (const Walk& c :
         {Walk{SchemeKind::Regular, StepMethod::Exact}, Walk{SchemeKind::Regular, StepMethod::Push},
          Walk{SchemeKind::Irregular, StepMethod::Exact, IrregularFrame::Projective},
          Walk{SchemeKind::Irregular, StepMethod::Exact, IrregularFrame::Camera}}) {
        SCOPED_TRACE(walkName(c));
        cli::CommonOptions o;
        o.scene = "builtin:default";
        o.knobs.build.scheme = c.scheme;
        o.knobs.build.regular.step = c.step;
        o.knobs.build.irregular.frame = c.frame;
        Scene scene = loadScene(o.scene);
        auto accel = buildAccelerator(scene, o.knobs.build);
        int w, h;
        cli::resolveSize(o, scene, w, h);
        for (RayKind kind : {RayKind::Shadow, RayKind::Refraction}) {
            std::optional<Picked> p = findPixel(scene, *accel, o.knobs.shading, w, h, kind);
            ASSERT_TRUE(p) << rayKindName(kind);
            RayPlayback play;
            play.setTree({p->x, p->y, w, h}, std::move(p->tree));
            for (int k = 0; k < int(play.tree().rays.size()); ++k) {
                play.selectRay(k);
                if (play.stepCount() == 0) continue;
                SCOPED_TRACE("ray " + std::to_string(k));
                backAndForth(play);
                ++rays;
            }
        }
    }
    EXPECT_GT(rays, 8);
}

TEST(Playback, PlayTakesSpeedStepsASecondAndStopsAtTheLast) {
    RayPlayback play = someRay();
    ASSERT_GT(play.stepCount(), 2);
    play.setSpeed(2.0);
    play.play();
    EXPECT_TRUE(play.playing());
    EXPECT_FALSE(play.advance(0.25));  // half a step
    EXPECT_EQ(play.state().step, 0);
    EXPECT_TRUE(play.advance(0.75));  // 1.5 steps more: two whole steps taken in all
    EXPECT_EQ(play.state().step, 2);
    play.pause();
    EXPECT_FALSE(play.advance(10.0));
    EXPECT_EQ(play.state().step, 2);
    play.play();
    play.advance(1000.0);
    EXPECT_EQ(play.state().step, play.stepCount() - 1);
    EXPECT_FALSE(play.playing());
}

TEST(Playback, RetraceKeepsTheRayAndStepAndTheOldCounts) {
    RayPlayback play = someRay();
    ASSERT_GT(play.stepCount(), 2);
    const RayTree before = play.tree();
    play.seek(2);
    // The same pixel in a structure of another scheme: another walk of the same rays.
    cli::CommonOptions o;
    o.knobs.build.scheme = SchemeKind::Brute;
    Scene scene = loadScene("builtin:default");
    auto accel = buildAccelerator(scene, o.knobs.build);
    play.retrace(tracePixel(scene, *accel, o.knobs.shading, scene.camera, play.pixel().x,
                            play.pixel().y, play.pixel().width, play.pixel().height));
    EXPECT_EQ(play.state().ray, 0);
    EXPECT_EQ(play.state().step, 0);  // brute force walks one region: step 2 clamps to it
    ASSERT_TRUE(play.previousCounts(0));
    EXPECT_EQ(*play.previousCounts(0), countsOf(before.rays[0]));
    EXPECT_EQ(countsOf(play.ray()).regions, 1u);
    EXPECT_GT(play.previousCounts(0)->regions, 1u);
}

TEST(Playback, StepSpansAreTheStepsTestsAndTheRegionTree) {
    RayPlayback play = someRay();
    ASSERT_GT(play.stepCount(), 0);
    size_t tests = 0, rows = 0, combined = 0;
    for (int k = 0; k < play.stepCount(); ++k) {
        play.seek(k);
        const std::vector<SpanRow> r = stepSpans(play);
        rows += r.size();
        for (size_t i = play.state().eventBegin; i < play.state().eventEnd; ++i) {
            const WalkEvent& e = play.ray().events[i];
            tests += e.kind() == WalkEvent::PrimTest || e.kind() == WalkEvent::MailboxHit;
            combined += e.kind() == WalkEvent::Spans;
        }
        for (const SpanRow& row : r)
            if (row.prim != kNoPrim && !row.mailbox) {
                // A tested primitive's row holds the spans its test reported.
                bool seen = false;
                for (size_t i = play.state().eventBegin; i < play.state().eventEnd; ++i) {
                    const WalkEvent& e = play.ray().events[i];
                    const walk::PrimTest* t = e.get<walk::PrimTest>();
                    seen = seen || (t && t->prim == row.prim && t->spans == row.spans);
                }
                EXPECT_TRUE(seen);
            }
    }
    EXPECT_GT(tests, 0u);
    EXPECT_EQ(rows, tests + combined);
}

// The CSG strips read the steps' analysis (rayCsg): the region strip holds the primitives the
// step read then its tree's nodes, the root the walk's recorded spans, the hit's chain marked
// from the root down to the hit primitive's leaf in the step that found it; the whole ray's
// strip has one band per step and ends with the result row; the analysis is cached per ray.
TEST(Playback, CsgStripsHoldTheStepsNodesAndTheHitsChain) {
    for (SchemeKind scheme : {SchemeKind::Regular, SchemeKind::Irregular}) {
        Scene scene = loadScene("builtin:default");
        BuildParams b;
        b.scheme = scheme;
        auto accel = buildAccelerator(scene, b);
        const StructureView view(scene, *accel);
        ShadingOptions sh;
        size_t chains = 0;
        for (int y = 4; y < 64; y += 8)
            for (int x = 4; x < 64; x += 8) {
                RayPlayback play;
                play.setTree({x, y, 64, 64},
                             tracePixel(scene, *accel, sh, scene.camera, x, y, 64, 64));
                RayCsgCache cache;
                const std::vector<StepCsg>& steps = cache.steps(play, view);
                EXPECT_EQ(&cache.steps(play, view), &steps);
                ASSERT_EQ(int(steps.size()), play.stepCount());
                const TracedRay& ray = play.ray();
                for (int k = 0; k < play.stepCount(); ++k) {
                    const std::vector<StripRow> rows = regionStrip(steps, cache.waste(), ray, k);
                    const StepCsg& s = steps[size_t(k)];
                    ASSERT_EQ(rows.size(), s.inputs.size() + s.nodes.size());
                    if (s.nodes.empty()) continue;
                    const StripRow& root = rows[s.inputs.size()];
                    EXPECT_TRUE(root.node);
                    EXPECT_EQ(root.depth, 0);
                    EXPECT_EQ(root.spans, s.result);
                    const bool hitHere = k + 1 == play.stepCount() && ray.hit.valid();
                    EXPECT_EQ(root.onHit, hitHere);
                    if (hitHere) {
                        // The hit primitive's leaf is on the chain, and so is each marked
                        // node's parent.
                        bool leaf = false;
                        for (size_t i = 0; i < s.nodes.size(); ++i) {
                            const StripRow& r = rows[s.inputs.size() + i];
                            leaf = leaf ||
                                   (r.op == Op::Primitive && r.prim == ray.hit.prim && r.onHit);
                            if (r.onHit && s.nodes[i].parent >= 0) {
                                EXPECT_TRUE(
                                    rows[s.inputs.size() + size_t(s.nodes[i].parent)].onHit);
                            }
                        }
                        EXPECT_TRUE(leaf);
                        ++chains;
                    }
                }
                const RayStrip strip = rayStrip(steps, cache.waste(), ray);
                EXPECT_EQ(strip.bands.size(), steps.size());
                ASSERT_FALSE(strip.rows.empty());
                EXPECT_TRUE(strip.rows.back().node);
                EXPECT_EQ(strip.rows.back().onHit, ray.hit.valid());
            }
        EXPECT_GT(chains, 5u);
    }
}

TEST(Playback, TraceCommandNamesEveryParameter) {
    BuildParams b;
    b.scheme = SchemeKind::Irregular;
    b.mailboxes = false;
    ShadingOptions sh;
    sh.bounces = 1;
    const std::string cmd = traceCommand("my scene.csg", "/tmp/cam.json", {3, 4, 640, 480}, b, sh);
    EXPECT_EQ(cmd.rfind("lancer trace 'my scene.csg' --camera /tmp/cam.json --width 640 "
                        "--height 480 --pixel 3 4 --scheme irregular",
                        0),
              0u)
        << cmd;
    EXPECT_NE(cmd.find(" --bounces 1"), std::string::npos);
    EXPECT_NE(cmd.find(" --no-mailbox"), std::string::npos);
    // Each scheme's own knobs: the BVH's, not the regular scheme's.
    b.scheme = SchemeKind::Bvh;
    b.bvh.maxLevel = 10;
    b.bvh.maxObjects = 3;
    b.regular.maxLevel = 20;
    const std::string bvh = traceCommand("s.nff", "/tmp/cam.json", {3, 4, 640, 480}, b, sh);
    EXPECT_NE(bvh.find(" --scheme bvh --max-level 10 --max-objects 3"), std::string::npos) << bvh;
    EXPECT_EQ(bvh.find(" --max-level 20"), std::string::npos) << bvh;
}

}  // namespace
}  // namespace lancer::viewer::playback
