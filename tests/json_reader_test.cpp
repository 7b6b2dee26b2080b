// The native JSON format: what it builds, and errors that name file, line and column.
#include "engine/scene/json_reader.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace lancer {
namespace {

using ::testing::HasSubstr;

Scene read(const std::string& text) { return readJsonScene(SourceText("scene.json", text)); }

// The message of the SceneError thrown by reading `text`.
std::string errorOf(const std::string& text) {
    try {
        read(text);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(JsonScene, BuildsTreeMaterialsAndTransforms) {
    Scene s = read(R"({
      "materials": {"m": {"color": [1, 0, 0], "reflect": 0.5}},
      "scene": {"difference": [
        {"box": {"size": 2, "center": true}, "material": "m"},
        {"sphere": {"radius": 1.2}},
        {"cylinder": {"radius": 0.3, "height": 4, "center": true}, "transform": [{"scale": [1, 2, 1]}]}
      ]}
    })");
    ASSERT_EQ(s.prims.size(), 3u);
    EXPECT_EQ(s.tree.toString(), "(p0 − (p1 ∪ p2))");
    EXPECT_EQ(s.materials[size_t(s.prims[0].material)].reflect, 0.5);
    EXPECT_EQ(s.prims[1].material, 0);
    EXPECT_EQ(s.prims[2].worldBox, (Box3{{-0.3, -0.6, -2}, {0.3, 0.6, 2}}));
    EXPECT_FALSE(s.lights.empty());  // default light rig
    EXPECT_EQ(s.prims[0].origin, "scene.json:4:9");
}

TEST(JsonScene, TorusIsATransformedPrimitive) {
    const Scene s = read(R"({"scene": {"difference": [
        {"torus": {"major": 2, "minor": 0.5}, "transform": [{"translate": [0, 0, 3]}]},
        {"torus": {"major": 1, "minor": 1}}]}})");
    ASSERT_EQ(s.prims.size(), 2u);
    const Torus* t = std::get_if<Torus>(&s.prims[0].shape);
    ASSERT_NE(t, nullptr);
    EXPECT_EQ(t->R, 2.0);
    EXPECT_EQ(t->r, 0.5);
    EXPECT_EQ(s.prims[0].worldBox.lo, Vec3(-2.5, -2.5, 2.5));
    EXPECT_EQ(s.prims[0].worldBox.hi, Vec3(2.5, 2.5, 3.5));
    EXPECT_EQ(s.prims[0].origin, "scene.json:2:9");
    // The horn torus (R = r) is accepted.
    EXPECT_TRUE(std::holds_alternative<Torus>(s.prims[1].shape));
}

TEST(JsonScene, MaterialOnAnInnerNodeIsInherited) {
    Scene s = read(
        R"({"scene": {"union": [{"sphere": {"radius": 1}}, {"sphere": {"center": [3, 0, 0], "radius": 1}}],
                         "material": {"color": [0, 1, 0]}}})");
    EXPECT_EQ(s.prims[0].material, s.prims[1].material);
    EXPECT_EQ(s.materials[size_t(s.prims[0].material)].color, Vec3(0, 1, 0));
}

TEST(JsonScene, EmptyOperatorContributesNothing) {
    Scene s = read(R"({"scene": {"union": [{"intersection": []}, {"sphere": {"radius": 1}}]}})");
    EXPECT_EQ(s.tree.toString(), "p0");
    Scene e = read(R"({"scene": {"union": []}})");
    EXPECT_TRUE(e.tree.empty());
}

TEST(JsonSceneErrors, SyntaxErrorNamesLineAndColumn) {
    EXPECT_THAT(errorOf("{\n  \"scene\": {\"sphere\": {\"radius\": 1,}}\n}"),
                HasSubstr("scene.json:2:"));
    EXPECT_THAT(errorOf("{\n  \"scene\": {\"sphere\": {\"radius\": 1,}}\n}"),
                HasSubstr("JSON syntax error"));
    EXPECT_THAT(errorOf("{\"scene\": "), HasSubstr("scene.json:1:"));  // truncated
}

TEST(JsonSceneErrors, ValidationErrorsPointAtTheValue) {
    // Negative radius: line 3, at the "radius" key.
    EXPECT_THAT(errorOf("{\n \"scene\":\n  {\"sphere\": {\"radius\": -1}}\n}"),
                HasSubstr("scene.json:3:15: expected a positive number, got -1"));
    EXPECT_THAT(errorOf(R"({"scene": {"sphere": {"raduis": 1}}})"),
                HasSubstr("unknown key \"raduis\""));
    EXPECT_THAT(errorOf(R"({"scene": {"sphere": {}}})"), HasSubstr("missing \"radius\""));
    EXPECT_THAT(errorOf(R"({"scene": {"sphere": {"radius": "big"}}})"),
                HasSubstr("expected a number"));
    EXPECT_THAT(errorOf(R"({"scene": {"sphere": {"radius": 1, "center": [1, 2]}}})"),
                HasSubstr("expected [x, y, z]"));
    EXPECT_THAT(errorOf(R"({"scene": {"sphere": {"radius": 1}, "material": "nope"}})"),
                HasSubstr("unknown material \"nope\""));
    EXPECT_THAT(errorOf(R"({"scene": {"box": {"min": [1, 0, 0], "max": [0, 1, 1]}}})"),
                HasSubstr("box \"min\" must be below \"max\""));
    EXPECT_THAT(errorOf(R"({"scene": {"torus": {}}})"), HasSubstr("missing \"major\""));
    EXPECT_THAT(errorOf(R"({"scene": {"donut": {}}})"), HasSubstr("expected a node"));
    // A spindle torus (its tube crossing the axis) is refused at its "minor" value.
    EXPECT_THAT(errorOf("{\"scene\":\n {\"torus\": {\"major\": 1, \"minor\": 2}}}"),
                HasSubstr("scene.json:2:25: a torus's \"minor\" radius must not exceed its "
                          "\"major\" one"));
    EXPECT_THAT(errorOf(R"({"scene": {"torus": {"major": 2, "minor": 0}}})"),
                HasSubstr("expected a positive number, got 0"));
    EXPECT_THAT(errorOf(R"({"scene": {"torus": {"major": 2, "minor": 1, "center": [0, 0, 0]}}})"),
                HasSubstr("unknown key \"center\""));
    EXPECT_THAT(errorOf(R"({"scene": {"sphere": {"radius": 1}, "box": {"size": 1}}})"),
                HasSubstr("exactly one of"));
    EXPECT_THAT(
        errorOf(R"({"scene": {"sphere": {"radius": 1}, "transform": [{"scale": [1, 0, 1]}]}})"),
        HasSubstr("non-zero"));
    EXPECT_THAT(
        errorOf(
            R"({"camera": {"from": [0, 0, 0], "at": [0, 0, 0]}, "scene": {"sphere": {"radius": 1}}})"),
        HasSubstr("'from' and 'at' are the same point"));
    EXPECT_THAT(errorOf(R"({"scene": {"sphere": {"radius": 1e999}}})"), HasSubstr("scene.json:1:"));
}

TEST(JsonSceneErrors, SurfaceUnderDifferenceIsRefusedNamingTheNode) {
    std::string e = errorOf(R"({"scene": {"difference": [
        {"box": {"size": 2}},
        {"triangle": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}]}})");
    EXPECT_THAT(e, HasSubstr("triangle"));
    EXPECT_THAT(e, HasSubstr("scene.json:3:9"));
    EXPECT_THAT(e, HasSubstr("difference"));
    // Under a union it is fine.
    EXPECT_NO_THROW(read(
        R"({"scene": {"union": [{"box": {"size": 2}}, {"triangle": [[0, 0, 0], [1, 0, 0], [0, 1, 0]]}]}})"));
}

TEST(JsonSceneErrors, MissingFileIsNamed) {
    try {
        SourceText::fromFile("/nonexistent/dir/x.json");
        ADD_FAILURE() << "a missing file was read";
    } catch (const SceneError& e) {
        EXPECT_THAT(e.what(), HasSubstr("/nonexistent/dir/x.json"));
    }
}

}  // namespace
}  // namespace lancer

namespace lancer {
namespace {
TEST(JsonSceneErrors, DeepNestingIsRefusedNotOverflowed) {
    std::string text = "{\"scene\": ";
    for (int i = 0; i < 5000; ++i) text += "{\"union\": [";
    text += "{\"sphere\": {\"radius\": 1}}";
    for (int i = 0; i < 5000; ++i) text += "]}";
    text += "}";
    try {
        readJsonScene(SourceText("deep.json", text));
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("nesting deeper than"), std::string::npos) << e.what();
    }
}
}  // namespace
}  // namespace lancer
