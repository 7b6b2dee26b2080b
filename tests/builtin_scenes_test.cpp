// Every built-in scene loads, renders, and gives the brute-force hit on every pixel with both
// subdivision schemes at their defaults.
#include "engine/scene/builtin_scenes.h"

#include <gtest/gtest.h>

#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

TEST(BuiltinScenes, EverySchemeAgreesWithBruteForceOnEveryPixel) {
    for (const BuiltinInfo& info : builtinScenes()) {
        int size = std::min(info.defaultSize, 3);
        Scene s = makeBuiltin(info.name, std::max(size, info.minSize));
        ASSERT_FALSE(s.tree.empty()) << info.name;
        std::vector<Ray> rays = test::pixelRays(s, 32, 24);
        for (SchemeKind k : {SchemeKind::Regular, SchemeKind::Irregular}) {
            BuildParams bp;
            bp.scheme = k;
            auto accel = buildAccelerator(s, bp);
            auto bad = test::compareWithBrute(s, *accel, rays);
            EXPECT_TRUE(bad.empty()) << info.name << " " << schemeName(k) << ": " << bad.size()
                                     << " mismatches, first:\n"
                                     << (bad.empty() ? "" : bad[0].toString(s));
        }
    }
}

TEST(BuiltinScenes, SizesFollowTheirDefinition) {
    EXPECT_EQ(makeBuiltin("tetra", 3).prims.size(), 64u);  // 4^SIZE triangles, as SPD tetra3
    EXPECT_EQ(makeBuiltin("tetra", 4).prims.size(), 256u);
    EXPECT_EQ(makeBuiltin("rings", 2).prims.size(), 2u * 2u * 20u + 1u);
    EXPECT_EQ(makeBuiltin("balls", 3).prims.size(), 821u);  // 820 spheres and the floor
    // The largest, the 598k spheres of the scale table (docs/scale.md).
    EXPECT_EQ(makeBuiltin("balls", 6).prims.size(), 597872u);
    EXPECT_EQ(makeBuiltin("drilled", 4).prims.size(), 65u);
    EXPECT_THROW(makeBuiltin("tetra", 99), SceneError);
}

TEST(BuiltinScenes, SpecsAreParsedAndWrittenByOneFunctionEach) {
    auto sized = parseBuiltinSpec("builtin:balls:2");
    ASSERT_TRUE(sized.has_value());
    EXPECT_EQ(sized->name, "balls");
    EXPECT_EQ(sized->size, 2);
    auto plain = parseBuiltinSpec("builtin:default");
    ASSERT_TRUE(plain.has_value());
    EXPECT_EQ(plain->name, "default");
    EXPECT_FALSE(plain->size.has_value());
    EXPECT_FALSE(parseBuiltinSpec("assets/spd/balls2.nff").has_value());
    EXPECT_FALSE(isBuiltinSpec("builtin.json"));
    try {
        parseBuiltinSpec("builtin:balls:2x");
        ADD_FAILURE() << "a size that is not an integer was accepted";
    } catch (const SceneError& e) {
        EXPECT_STREQ(e.what(),
                     "builtin:balls:2x: the size after the second ':' must be an integer");
    }
    EXPECT_EQ(builtinSpec("balls", 2), "builtin:balls:2");
    EXPECT_EQ(builtinSpec("default"), "builtin:default");
    ASSERT_NE(findBuiltin("tetra"), nullptr);
    EXPECT_EQ(findBuiltin("tetra")->maxSize, 7);
    EXPECT_EQ(findBuiltin("nosuch"), nullptr);
    // A scene is named by the spec that loads it; a negative size is outside every range.
    EXPECT_EQ(loadScene("builtin:tetra:2").name, "builtin:tetra:2");
    EXPECT_EQ(loadScene("builtin:default").name, "builtin:default");
    EXPECT_THROW(loadScene("builtin:balls:-1"), SceneError);
}

}  // namespace
}  // namespace lancer
