// The scheme table (build_params.h): every row names a scheme that builds, in the alternative of
// Accelerator::Impl at its index, traces the same hits as brute force, and is found by its name;
// the command line's --scheme offers exactly the table's names.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "engine/accel/accelerator.h"
#include "engine/scene/loader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

TEST(SchemeTable, EveryRowBuildsItsAlternativeAndTracesAsBruteForce) {
    const Scene scene = loadScene("builtin:drilled:3");
    const std::vector<Ray> rays = test::randomRays(scene, 11, 400);
    std::set<std::string> names;
    for (const SchemeInfo& info : kSchemeTable) {
        SCOPED_TRACE(info.name);
        EXPECT_TRUE(names.insert(info.name).second) << "two rows named " << info.name;
        EXPECT_EQ(schemeFromName(info.name), info.kind);
        EXPECT_STREQ(schemeName(info.kind), info.name);
        EXPECT_GT(std::string(info.help).size(), 10u);
        BuildParams p;
        p.scheme = info.kind;
        auto accel = buildAccelerator(scene, p);
        EXPECT_EQ(accel->impl().index(), size_t(info.kind));
        EXPECT_EQ(accel->params().scheme, info.kind);
        EXPECT_GE(accel->info().regions, 1u);
        test::expectSame(scene, *accel, rays, info.name);
    }
    EXPECT_EQ(schemeNames().size(), size_t(kSchemeCount));
    EXPECT_FALSE(schemeFromName("kd-tree").has_value());
    EXPECT_FALSE(schemeFromName("").has_value());
}

}  // namespace
}  // namespace lancer
