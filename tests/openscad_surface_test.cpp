// surface(): OpenSCAD heightmaps (.dat text and PNG images) as closed mesh solids, their depth
// against the heights OpenSCAD's mesh has, their errors, and every scheme against brute force.
#include <gtest/gtest.h>
#include <stb_image_write.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "engine/accel/accelerator.h"
#include "engine/scene/openscad/surface.h"
#include "engine/scene/openscad_reader.h"
#include "tests/support/differential.h"

namespace lancer {
namespace {

/// A fresh folder of the test's own; files written there are found beside its .csg.
std::filesystem::path folder() {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("lancer_surface_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return dir;
}

std::string write(const std::string& name, const std::string& text) {
    const std::filesystem::path p = folder() / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
}

Scene csgFile(const std::string& text, OpenScadCounts* counts = nullptr) {
    return readOpenScadFile(write("model.csg", text), counts);
}

/// The nearest hit of brute force along the ray, or NaN.
double depth(const Scene& s, const Ray& r) {
    Hit hit;
    return test::bruteHit(s, r, hit) ? hit.t : std::nan("");
}

/// The top's height at (x, y) as OpenSCAD's mesh has it (grid at integers, not centred): the
/// triangle of the cell around (x, y) between two of its corners and its centre, at the centre
/// the mean of the four corners.
double meshHeight(const std::vector<std::vector<double>>& z, double x, double y) {
    const int j = std::min(int(std::floor(x)), int(z[0].size()) - 2);
    const int i = std::min(int(std::floor(y)), int(z.size()) - 2);
    const double u = x - j, v = y - i;  // in the cell, [0, 1]^2
    const double c00 = z[i][j], c10 = z[i][j + 1], c01 = z[i + 1][j], c11 = z[i + 1][j + 1];
    const double mid = (c00 + c10 + c01 + c11) / 4.0;
    // The four triangles meet at (0.5, 0.5): pick the one by the diagonals, then interpolate.
    const glm::dvec2 p(u - 0.5, v - 0.5);
    glm::dvec2 a, b;
    double za, zb;
    if (std::abs(p.y) >= std::abs(p.x)) {
        a = {-0.5, p.y < 0 ? -0.5 : 0.5};
        b = {0.5, a.y};
        za = p.y < 0 ? c00 : c01;
        zb = p.y < 0 ? c10 : c11;
    } else {
        a = {p.x < 0 ? -0.5 : 0.5, -0.5};
        b = {a.x, 0.5};
        za = p.x < 0 ? c00 : c10;
        zb = p.x < 0 ? c01 : c11;
    }
    // Barycentric in the triangle (a, b, 0).
    const double det = a.x * b.y - a.y * b.x;
    const double la = (p.x * b.y - p.y * b.x) / det, lb = (a.x * p.y - a.y * p.x) / det;
    return la * za + lb * zb + (1.0 - la - lb) * mid;
}

TEST(OpenScadSurface, DatHeightmapDepthIsOpenScadsMeshHeight) {
    // Three rows of four (the third short: OpenSCAD fills it with 0), a comment and a blank line.
    const std::vector<std::vector<double>> z = {
        {1.0, 2.0, 0.5, 3.0}, {2.5, -1.0, 4.0, 1.0}, {0.0, 1.5, 2.0, 0.0}};
    write("h.dat", "# heights\n1 2 0.5 3\n\n 2.5\t-1 4 1\r\n0 1.5 2\n");
    OpenScadCounts n;
    const Scene s = csgFile("surface(file = \"h.dat\", center = false, invert = false);", &n);
    EXPECT_EQ(n.surfaces, 1);
    EXPECT_EQ(n.meshes, 1);
    // Straight down onto the top from z = 10, at points in every triangle and on grid points.
    int checked = 0;
    for (double x = 0.05; x < 3.0; x += 0.3)
        for (double y = 0.05; y < 2.0; y += 0.23) {
            const double t = depth(s, Ray{Vec3(x, y, 10.0), Vec3(0, 0, -1)});
            ASSERT_FALSE(std::isnan(t)) << x << " " << y;
            EXPECT_NEAR(10.0 - t, meshHeight(z, x, y), 1e-9) << x << " " << y;
            ++checked;
        }
    EXPECT_GT(checked, 50);
    // The floor: min(0, lowest - 1) = -2, seen from below; the walls at x = 0 and y = 2.
    EXPECT_NEAR(depth(s, Ray{Vec3(1.3, 0.7, -10.0), Vec3(0, 0, 1)}), 8.0, 1e-9);
    EXPECT_NEAR(depth(s, Ray{Vec3(-5.0, 1.0, -1.5), Vec3(1, 0, 0)}), 5.0, 1e-9);
    EXPECT_NEAR(depth(s, Ray{Vec3(1.0, 9.0, -1.5), Vec3(0, -1, 0)}), 7.0, 1e-9);
    // Beside it: nothing.
    EXPECT_TRUE(std::isnan(depth(s, Ray{Vec3(3.2, 1.0, 10.0), Vec3(0, 0, -1)})));
    // center = true shifts the grid by -(columns - 1) / 2, -(rows - 1) / 2.
    const Scene c = csgFile("surface(file = \"h.dat\", center = true);");
    EXPECT_NEAR(10.0 - depth(c, Ray{Vec3(1.3 - 1.5, 0.7 - 1.0, 10.0), Vec3(0, 0, -1)}),
                meshHeight(z, 1.3, 0.7), 1e-9);
}

TEST(OpenScadSurface, PngHeightmapIsLuminanceAndInverts) {
    // 3 x 2 pixels: the image's top row is the grid's last (largest y), as OpenSCAD reads it.
    const unsigned char rgb[2][3][3] = {{{255, 0, 0}, {0, 255, 0}, {0, 0, 255}},
                                        {{255, 255, 255}, {0, 0, 0}, {10, 200, 30}}};
    const std::string png = (folder() / "h.png").string();
    ASSERT_NE(stbi_write_png(png.c_str(), 3, 2, 3, rgb, 9), 0);
    auto lum = [&](int row, int col) {
        const unsigned char* p = rgb[row][col];
        return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    };
    for (bool invert : {false, true}) {
        const Scene s = csgFile(std::string("surface(file = \"h.png\", invert = ") +
                                (invert ? "true" : "false") + ");");
        for (int row = 0; row < 2; ++row)
            for (int col = 0; col < 3; ++col) {
                const double want = 100.0 / 255.0 * (invert ? 1.0 - lum(row, col) : lum(row, col));
                // Pixel (row, col) is grid point (x = col, y = 1 - row); at the grid's border the
                // ray comes down a hair inside it.
                const double x = col == 2 ? 2.0 - 1e-7 : col + 1e-7;
                const double y = row == 0 ? 1.0 - 1e-7 : 1e-7;
                const double t = depth(s, Ray{Vec3(x, y, 200.0), Vec3(0, 0, -1)});
                EXPECT_NEAR(200.0 - t, want, 2e-4)
                    << "invert " << invert << " pixel " << row << "," << col;
            }
    }
}

TEST(OpenScadSurface, BadHeightmapsAreRefusedNamingFileLineAndColumn) {
    write("bad.dat", "1 2 3\n4 x5 6\n");
    const std::string dir = folder().string();
    auto error = [&](const std::string& csg) {
        try {
            csgFile(csg);
        } catch (const SceneError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_EQ(error("group() {\n  surface(file = \"bad.dat\");\n}"),
              dir + "/model.csg:2:18: surface(): " + dir +
                  "/bad.dat:2:3: expected a finite number in a heightmap, found 'x5'");
    EXPECT_EQ(error("surface(file = \"none.dat\");"),
              dir + "/model.csg:1:16: surface(): " + dir + "/none.dat: no such file");
    write("nan.dat", "1 2\nnan 3\n");
    EXPECT_NE(error("surface(file = \"nan.dat\");").find("nan.dat:2:1: expected a finite number"),
              std::string::npos);
    // Too many values: refused before the mesh is made.
    std::string row, big;
    for (int j = 0; j < 200; ++j) row += "1 ";
    for (int i = 0; i < 300; ++i) big += row + "\n";
    write("big.dat", big);
    EXPECT_NE(error("surface(file = \"big.dat\");").find("more than 49000 values"),
              std::string::npos);
    // A PNG signature with a broken body.
    write("broken.png", std::string("\x89PNG\r\n\x1a\n", 8) + "garbage");
    EXPECT_NE(error("surface(file = \"broken.png\");").find("not a PNG image that can be read"),
              std::string::npos);
    EXPECT_NE(error("surface(file = \"bad.dat\", nonsense = 1);").find("nonsense"),
              std::string::npos);
}

TEST(OpenScadSurface, SchemesAgreeWithBruteForceOnTwoTurnedSurfaces) {
    // example010's shape, small: the intersection of a heightmap and its copy turned 45 degrees.
    std::string dat;
    for (int i = 0; i < 8; ++i) {
        for (int j = 0; j < 9; ++j)
            dat += std::to_string(3.0 * std::sin(0.7 * i) * std::cos(0.5 * j) + 0.1 * i) + " ";
        dat += "\n";
    }
    write("wave.dat", dat);
    const Scene s = csgFile(
        "intersection() {\n surface(file = \"wave.dat\", center = true, convexity = 5);\n"
        " multmatrix([[0.707107, -0.707107, 0, 0], [0.707107, 0.707107, 0, 0], [0, 0, 1, 0], "
        "[0, 0, 0, 1]]) surface(file = \"wave.dat\", center = true);\n}");
    test::expectEverySchemeSame(s, test::randomRays(s, 5, 2000));
    test::expectEverySchemeSame(s, test::pixelRays(s, 32, 32));
}

}  // namespace
}  // namespace lancer
