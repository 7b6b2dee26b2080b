// The panels' layout without a window: at the sizes users run the viewer at, with the
// inspector shown or not, no panel overlaps another, the image area or the inspector's view,
// and every panel stays inside the window.
#include "app/viewer/panels/layout.h"

#include <gtest/gtest.h>

#include <random>

#include "app/viewer/inspector/inspector.h"

namespace lancer::viewer {
namespace {

/// Every panel open but the structure tree (opened on demand), asking for the heights their
/// contents take (the first four as measured at 900 x 720 on builtin:default, and typical ones
/// for the others; the Ray panel asks for all it can get).
LayoutInput everyPanel(float w, float h, bool inspector) {
    LayoutInput in;
    in.width = w;
    in.height = h;
    in.inspector = inspector;
    const float wants[kPanelCount] = {639, 121, 272, 189, 240, 330, 450, 420, 1.0e6f};
    for (int i = 0; i < kPanelCount; ++i) in.panels[size_t(i)] = {true, false, wants[i]};
    in[PanelId::Tree].open = false;
    return in;
}

void expectApart(const LayoutInput& in, const PanelLayout& l) {
    const Rect window{0.0f, kMenuBarHeight, in.width, in.height};
    EXPECT_FALSE(l.image.empty());
    EXPECT_FALSE(l.image.overlaps(l.inspector));
    EXPECT_EQ(l.inspector.empty(), !in.inspector);
    EXPECT_TRUE(Rect({0.0f, 0.0f, in.width, in.height}).contains(l.image)) << l.image.toString();
    if (in.inspector) {
        EXPECT_TRUE(window.contains(l.inspector)) << l.inspector.toString();
    }
    for (int i = 0; i < kPanelCount; ++i) {
        const Rect& r = l.panels[size_t(i)];
        const char* name = panelTitle(PanelId(i));
        if (!in.panels[size_t(i)].open) {
            EXPECT_TRUE(r.empty()) << name;
            continue;
        }
        // On screen, under the menu bar, at least a title bar high (never clipped away).
        EXPECT_TRUE(window.contains(r)) << name << " " << r.toString();
        EXPECT_GE(r.height(), in.titleHeight) << name;
        EXPECT_FALSE(r.overlaps(l.image))
            << name << " " << r.toString() << " over the image " << l.image.toString();
        EXPECT_FALSE(r.overlaps(l.inspector))
            << name << " " << r.toString() << " over the inspector " << l.inspector.toString();
        for (int j = i + 1; j < kPanelCount; ++j)
            EXPECT_FALSE(r.overlaps(l.panels[size_t(j)]))
                << name << " overlaps " << panelTitle(PanelId(j));
    }
}

TEST(PanelLayout, NoPanelOverlapsTheImageOrTheInspectorAt1280x720And900x600) {
    for (const auto& [w, h] : {std::pair{1280.0f, 720.0f}, std::pair{900.0f, 600.0f}})
        for (bool inspector : {false, true}) {
            SCOPED_TRACE(testing::Message() << w << " x " << h << (inspector ? ", inspector" : ""));
            const LayoutInput in = everyPanel(w, h, inspector);
            const PanelLayout l = layoutPanels(in);
            expectApart(in, l);
            // The image keeps a useful part of the window, and so does the inspector.
            EXPECT_GE(l.image.width(), 0.25f * w);
            if (inspector) {
                EXPECT_GE(l.inspector.width(), 0.3f * w);
            }
            // Two columns at these sizes without the inspector, one with it.
            EXPECT_EQ(l.twoColumns, !inspector);
        }
}

TEST(PanelLayout, PanelsThatFitGetTheirHeightAndTheRayPanelTakesWhatIsLeft) {
    LayoutInput in = everyPanel(1280.0f, 720.0f, false);
    for (PanelId id : {PanelId::Camera, PanelId::Overlays, PanelId::Inspector, PanelId::Selection})
        in[id].open = false;
    const PanelLayout l = layoutPanels(in);
    expectApart(in, l);
    // Parameters has the left column, View fits beside the Ray panel; the Ray panel gets its
    // usable height first, Statistics what it leaves.
    for (PanelId id : {PanelId::Parameters, PanelId::View})
        EXPECT_EQ(l[id].height(), in[id].want) << panelTitle(id);
    EXPECT_GE(l[PanelId::Statistics].height(), 3.0f * in.titleHeight);
    // The Ray panel goes down to the bottom margin of its column.
    EXPECT_FLOAT_EQ(l[PanelId::Ray].y1, 720.0f - 8.0f);
    EXPECT_GE(l[PanelId::Ray].height(), kUsablePanelHeight);

    // Folding the panels gives the Ray panel their room.
    LayoutInput folded = in;
    for (PanelId id : {PanelId::Parameters, PanelId::View, PanelId::Statistics})
        folded[id].collapsed = true;
    const PanelLayout f = layoutPanels(folded);
    expectApart(folded, f);
    EXPECT_GT(f[PanelId::Ray].height(), 600.0f);
    for (PanelId id : {PanelId::Parameters, PanelId::View, PanelId::Statistics})
        EXPECT_EQ(f[id].height(), folded.titleHeight) << panelTitle(id);
}

TEST(PanelLayout, TheStructureTreeOpenKeepsEveryPanelApart) {
    for (const auto& [w, h] : {std::pair{1280.0f, 720.0f}, std::pair{1920.0f, 1080.0f}})
        for (bool inspector : {false, true}) {
            SCOPED_TRACE(testing::Message() << w << " x " << h << (inspector ? ", inspector" : ""));
            LayoutInput in = everyPanel(w, h, inspector);
            in[PanelId::Tree].open = true;
            const PanelLayout l = layoutPanels(in);
            expectApart(in, l);
            EXPECT_GE(l[PanelId::Tree].height(), in.titleHeight);
            EXPECT_GE(l[PanelId::Ray].height(), kUsablePanelHeight);
        }
}

TEST(PanelLayout, HiddenPanelsLeaveTheWindowToTheImageAndTheInspectorItsRightHalf) {
    LayoutInput in = everyPanel(1280.0f, 720.0f, false);
    in.panelsHidden = true;
    PanelLayout l = layoutPanels(in);
    EXPECT_EQ(l.image.toString(), Rect({0, 0, 1280, 720}).toString());
    for (const Rect& r : l.panels) EXPECT_TRUE(r.empty());
    in.inspector = true;
    l = layoutPanels(in);
    // The image, the split's handle and the inspector tile the window, split in half.
    EXPECT_EQ(l.image.toString(), Rect({0, 0, 636, 720}).toString());
    EXPECT_EQ(l.splitHandle.toString(), Rect({636, 0, 644, 720}).toString());
    EXPECT_EQ(l.inspector.toString(), Rect({644, 0, 1280, 720}).toString());
    // The split dragged: the image's share of the width, the inspector the rest.
    in.imageShare = 0.25f;
    l = layoutPanels(in);
    EXPECT_EQ(l.image.width(), 318.0f);
    EXPECT_EQ(l.inspector.x1, 1280.0f);
    EXPECT_FALSE(l.image.overlaps(l.inspector));
}

/// The panels a first run shows (Overlays folded), with the inspector and a ray picked.
LayoutInput inspectingARay(float w, float h) {
    LayoutInput in = everyPanel(w, h, true);
    in[PanelId::Overlays].collapsed = true;
    in[PanelId::Selection].open = false;
    return in;
}

/// The height of the tallest open, expanded panel other than those of `skip`.
float tallestOther(const LayoutInput& in, const PanelLayout& l,
                   std::initializer_list<PanelId> skip) {
    float most = 0.0f;
    for (int i = 0; i < kPanelCount; ++i) {
        if (!in.panels[size_t(i)].open ||
            std::find(skip.begin(), skip.end(), PanelId(i)) != skip.end())
            continue;
        most = std::max(most, l.panels[size_t(i)].height());
    }
    return most;
}

TEST(PanelLayout, WithTheInspectorTheRayPanelKeepsAUsableHeight) {
    // One column holds every panel beside the image and the inspector: the Ray panel gets a
    // usable height before the others, which keep at least their title bar.
    for (const auto& [w, h, least] :
         {std::tuple{1280.0f, 720.0f, kUsablePanelHeight}, std::tuple{900.0f, 600.0f, 200.0f}}) {
        SCOPED_TRACE(testing::Message() << w << " x " << h);
        const LayoutInput in = inspectingARay(w, h);
        const PanelLayout l = layoutPanels(in);
        expectApart(in, l);
        EXPECT_FALSE(l.twoColumns);
        EXPECT_GE(l[PanelId::Ray].height(), least);
        EXPECT_FLOAT_EQ(l[PanelId::Ray].y1, h - 8.0f) << "down to the bottom margin";
        for (PanelId id : {PanelId::Parameters, PanelId::View, PanelId::Statistics, PanelId::Camera,
                           PanelId::Inspector})
            EXPECT_GE(l[id].height(), in.titleHeight) << panelTitle(id);
        EXPECT_EQ(l[PanelId::Overlays].height(), in.titleHeight) << "folded: its title bar";
    }
    // A ray played selects its region, which opens the Selection panel: the Ray panel still
    // gets a usable height first.
    LayoutInput playing = inspectingARay(1280.0f, 720.0f);
    playing[PanelId::Selection].open = true;
    PanelLayout l = layoutPanels(playing);
    expectApart(playing, l);
    EXPECT_GE(l[PanelId::Ray].height(), kUsablePanelHeight);
    EXPECT_GE(l[PanelId::Selection].height(), playing.titleHeight);
    // Every panel open and expanded at 1280 x 720: the Ray panel is cut last, gets its usable
    // height, and more than twice the height of any other.
    LayoutInput all = everyPanel(1280.0f, 720.0f, true);
    l = layoutPanels(all);
    expectApart(all, l);
    EXPECT_GE(l[PanelId::Ray].height(), kUsablePanelHeight);
    EXPECT_GT(l[PanelId::Ray].height(), 2.0f * tallestOther(all, l, {PanelId::Ray}));
    EXPECT_GE(l[PanelId::Selection].height(), all.titleHeight);
    // Folding the other panels gives the Ray panel the column.
    for (PanelId id : {PanelId::Parameters, PanelId::View, PanelId::Statistics, PanelId::Camera,
                       PanelId::Overlays, PanelId::Inspector, PanelId::Selection})
        all[id].collapsed = true;
    l = layoutPanels(all);
    expectApart(all, l);
    EXPECT_GT(l[PanelId::Ray].height(),
              720.0f - kMenuBarHeight - 8.0f - 7.0f * (19.0f + 8.0f) - 1.0f);
}

TEST(PanelLayout, AWideWindowPutsTheRayPanelBesideTheInspectorWhenOneColumnCannotHoldThePanels) {
    for (const auto& [w, h] : {std::pair{1600.0f, 900.0f}, std::pair{1920.0f, 1080.0f}}) {
        SCOPED_TRACE(testing::Message() << w << " x " << h);
        LayoutInput in = inspectingARay(w, h);
        in[PanelId::Selection].open = true;
        const PanelLayout l = layoutPanels(in);
        expectApart(in, l);
        EXPECT_TRUE(l.twoColumns);
        for (PanelId id : {PanelId::Inspector, PanelId::Selection, PanelId::Ray})
            EXPECT_GE(l[id].x0, l.inspector.x1) << panelTitle(id) << " right of the inspector";
        for (PanelId id : {PanelId::Parameters, PanelId::View, PanelId::Statistics})
            EXPECT_LE(l[id].x1, l.image.x0) << panelTitle(id) << " left of the image";
        EXPECT_GE(l.image.width(), 400.0f);
        EXPECT_GE(l.inspector.width(), 400.0f);
        EXPECT_GE(l[PanelId::Ray].height(), kUsablePanelHeight);
        EXPECT_GE(l[PanelId::Selection].height(), kUsablePanelHeight);
        // No panel has less room than one column of the same height gives it, and together
        // they have more.
        LayoutInput narrow = in;
        narrow.width = 1280.0f;
        const PanelLayout one = layoutPanels(narrow);
        ASSERT_FALSE(one.twoColumns);
        float two = 0.0f, single = 0.0f;
        for (int i = 0; i < kPanelCount; ++i)
            if (in.panels[size_t(i)].open && !in.panels[size_t(i)].collapsed) {
                EXPECT_GE(l.panels[size_t(i)].height(), one.panels[size_t(i)].height())
                    << panelTitle(PanelId(i));
                two += l.panels[size_t(i)].height();
                single += one.panels[size_t(i)].height();
            }
        EXPECT_GT(two, single + 200.0f);

        // The other panels folded: one column holds them, and the image and the inspector
        // keep the width.
        LayoutInput folded = in;
        for (PanelId id : {PanelId::Parameters, PanelId::View, PanelId::Statistics, PanelId::Camera,
                           PanelId::Inspector, PanelId::Selection})
            folded[id].collapsed = true;
        const PanelLayout f = layoutPanels(folded);
        expectApart(folded, f);
        EXPECT_FALSE(f.twoColumns);
        EXPECT_GT(f.inspector.width(), l.inspector.width());
        EXPECT_GE(f[PanelId::Ray].height(), 0.6f * h);
    }
}

TEST(PanelLayout, NoPanelOverlapsOrLeavesTheWindowAtAnySizeAndChoiceOfPanels) {
    std::mt19937 rng(16);
    std::uniform_real_distribution<float> wantOf(40.0f, 900.0f);
    for (float w : {640.0f, 800.0f, 900.0f, 1024.0f, 1280.0f, 1440.0f, 1600.0f, 1920.0f, 2560.0f})
        for (float h : {480.0f, 600.0f, 720.0f, 900.0f, 1080.0f, 1440.0f})
            for (int k = 0; k < 40; ++k) {
                LayoutInput in;
                in.width = w;
                in.height = h;
                in.inspector = rng() % 2;
                for (int i = 0; i < kPanelCount; ++i) {
                    const bool open = rng() % 3 != 0, folded = rng() % 3 == 0;
                    const float want = PanelId(i) == PanelId::Ray ? 1.0e6f : wantOf(rng);
                    in.panels[size_t(i)] = {open, folded, want};
                }
                SCOPED_TRACE(testing::Message() << w << " x " << h << " case " << k
                                                << (in.inspector ? ", inspector" : ""));
                const PanelLayout l = layoutPanels(in);
                expectApart(in, l);
                EXPECT_GE(l.image.width(), std::min(260.0f, 0.2f * w));
                const PanelRequest& ray = in[PanelId::Ray];
                if (ray.open && !ray.collapsed && h >= 600.0f) {
                    EXPECT_GE(l[PanelId::Ray].height(), 2.0f * in.titleHeight);
                }
                if (::testing::Test::HasFailure()) return;
            }
}

TEST(PanelLayout, ASmallWindowKeepsEveryPanelInside) {
    for (const auto& [w, h] : {std::pair{640.0f, 400.0f}, std::pair{320.0f, 240.0f}}) {
        SCOPED_TRACE(testing::Message() << w << " x " << h);
        const LayoutInput in = everyPanel(w, h, false);
        const PanelLayout l = layoutPanels(in);
        EXPECT_FALSE(l.twoColumns);
        for (int i = 0; i < kPanelCount; ++i) {
            if (!in.panels[size_t(i)].open) continue;
            const Rect& r = l.panels[size_t(i)];
            EXPECT_GE(r.x0, 0.0f);
            EXPECT_LE(r.x1, w);
            EXPECT_GE(r.y0, kMenuBarHeight);
            EXPECT_LE(r.y1, h);
        }
    }
}

TEST(PanelLayout, DraggedColumnsKeepTheirWidthAndTheirHandlesSeparateThemFromTheImage) {
    for (const auto& [w, h] : {std::pair{1280.0f, 720.0f}, std::pair{1920.0f, 1080.0f}}) {
        SCOPED_TRACE(testing::Message() << w << " x " << h);
        LayoutInput in = everyPanel(w, h, false);
        in.leftWidth = 300.0f;
        in.rightWidth = 420.0f;
        const PanelLayout l = layoutPanels(in);
        expectApart(in, l);
        ASSERT_TRUE(l.twoColumns);
        EXPECT_EQ(l.leftWidth, 300.0f);
        EXPECT_EQ(l.rightWidth, 420.0f);
        EXPECT_EQ(l[PanelId::Parameters].width(), 300.0f);
        // Each handle lies between its column and the image, and the image fills the rest.
        EXPECT_EQ(l.leftHandle.x0, l[PanelId::Parameters].x1);
        EXPECT_EQ(l.leftHandle.x1, l.image.x0);
        EXPECT_EQ(l.rightHandle.x0, l.image.x1);
        EXPECT_EQ(l.rightHandle.x1, l[PanelId::View].x0);
        EXPECT_FALSE(l.leftHandle.overlaps(l.image));
    }
}

TEST(PanelLayout, AColumnDraggedTooWideOrTooNarrowIsClampedAndTheImageKeepsItsMinimum) {
    LayoutInput in = everyPanel(1280.0f, 720.0f, false);
    in.leftWidth = 5000.0f;
    in.rightWidth = 10.0f;
    const PanelLayout l = layoutPanels(in);
    expectApart(in, l);
    EXPECT_EQ(l.rightWidth, kColumnMinWidth);
    EXPECT_GE(l.image.width(), kMinViewportSide - 1.0f);
}

TEST(PanelLayout, TheWindowForAnImageSizeGivesExactlyThatImageViewport) {
    for (bool inspector : {false, true})
        for (const auto& [iw, ih] :
             {std::pair{640.0f, 480.0f}, std::pair{1280.0f, 720.0f}, std::pair{640.0f, 360.0f}}) {
            SCOPED_TRACE(testing::Message()
                         << iw << " x " << ih << (inspector ? ", inspector" : ""));
            LayoutInput in = everyPanel(0.0f, 0.0f, inspector);
            const auto [w, h] = windowForImage(in, iw, ih);
            in.width = w;
            in.height = h;
            const PanelLayout l = layoutPanels(in);
            EXPECT_EQ(l.image.width(), iw) << "window " << w << " x " << h;
            EXPECT_EQ(l.image.height(), ih);
            expectApart(in, l);
        }
}

}  // namespace
}  // namespace lancer::viewer
