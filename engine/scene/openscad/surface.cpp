#include "engine/scene/openscad/surface.h"

#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "engine/scene/scene.h"

namespace lancer::openscad {

namespace {

HeightMap readPng(const SourceText& file, bool invert) {
    const auto* bytes = reinterpret_cast<const stbi_uc*>(file.text().data());
    const int len = int(std::min<size_t>(file.text().size(), size_t(1) << 30));
    int w = 0, h = 0, n = 0;
    // The size first: an image of millions of pixels is refused before it is decoded.
    if (!stbi_info_from_memory(bytes, len, &w, &h, &n))
        throw SceneError(file.path() + ": not a PNG image that can be read (" +
                         stbi_failure_reason() + ")");
    if (size_t(w) * size_t(h) > kMaxHeightValues)
        throw SceneError(file.path() + ": a heightmap of " + std::to_string(w) + " x " +
                         std::to_string(h) + " pixels is over the " +
                         std::to_string(kMaxHeightValues) + " values Lancer meshes");
    stbi_uc* px = stbi_load_from_memory(bytes, len, &w, &h, &n, 4);
    if (!px)
        throw SceneError(file.path() + ": not a PNG image that can be read (" +
                         stbi_failure_reason() + ")");
    HeightMap m;
    m.rows = h;
    m.columns = w;
    m.z.resize(size_t(w) * size_t(h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const stbi_uc* p = px + 4 * (size_t(y) * size_t(w) + size_t(x));
            const double lum = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            // OpenSCAD 2021.01's convert_image: 1 - luminance (not 255 - it) when inverted.
            m.z[size_t(h - 1 - y) * size_t(w) + size_t(x)] =
                100.0 / 255.0 * (invert ? 1.0 - lum : lum);
        }
    stbi_image_free(px);
    return m;
}

HeightMap readDat(const SourceText& file) {
    const std::string& t = file.text();
    std::vector<std::vector<double>> rows;
    size_t values = 0, i = 0;
    while (i < t.size()) {
        size_t end = t.find('\n', i);
        if (end == std::string::npos) end = t.size();
        size_t a = i;
        while (a < end && std::isspace(static_cast<unsigned char>(t[a]))) ++a;
        if (a < end && t[a] != '#') {
            std::vector<double> row;
            while (a < end) {
                while (a < end && std::isspace(static_cast<unsigned char>(t[a]))) ++a;
                if (a == end) break;
                size_t b = a;
                while (b < end && !std::isspace(static_cast<unsigned char>(t[b]))) ++b;
                const std::string tok = t.substr(a, b - a);
                char* stop = nullptr;
                const double v = std::strtod(tok.c_str(), &stop);
                if (stop != tok.c_str() + tok.size() || !std::isfinite(v))
                    file.fail(a, "expected a finite number in a heightmap, found '" +
                                     tok.substr(0, 40) + "'");
                if (++values > kMaxHeightValues)
                    file.fail(a, "a heightmap of more than " + std::to_string(kMaxHeightValues) +
                                     " values, which Lancer does not mesh");
                row.push_back(v);
                a = b;
            }
            rows.push_back(std::move(row));
        }
        i = end + 1;
    }
    HeightMap m;
    m.rows = int(rows.size());
    for (const auto& r : rows) m.columns = std::max(m.columns, int(r.size()));
    if (size_t(m.rows) * size_t(m.columns) > kMaxHeightValues)
        throw SceneError(file.path() + ": a heightmap of " + std::to_string(m.rows) + " rows of " +
                         std::to_string(m.columns) +
                         " values (short rows filled with 0) is over the " +
                         std::to_string(kMaxHeightValues) + " values Lancer meshes");
    m.z.assign(size_t(m.rows) * size_t(m.columns), 0.0);
    for (size_t r = 0; r < rows.size(); ++r)
        std::copy(rows[r].begin(), rows[r].end(), m.z.begin() + long(r * size_t(m.columns)));
    return m;
}

}  // namespace

HeightMap readHeightMap(const SourceText& file, bool invert) {
    static const char kPng[] = "\x89PNG\r\n\x1a\n";
    if (file.text().compare(0, 8, kPng, 8) == 0) return readPng(file, invert);
    return readDat(file);  // as OpenSCAD: what does not decode as a PNG is read as .dat
}

TriangleMesh heightMapMesh(const HeightMap& map, bool center) {
    TriangleMesh m;
    const int rows = map.rows, cols = map.columns;
    if (rows < 2 || cols < 2) return m;
    double floor = 0.0;
    for (double v : map.z) floor = std::min(floor, v - 1.0);
    const double ox = center ? -(cols - 1) / 2.0 : 0.0, oy = center ? -(rows - 1) / 2.0 : 0.0;
    auto point = [&](double x, double y, double z) {
        m.points.push_back(Vec3(ox + x, oy + y, z));
        return uint32_t(m.points.size() - 1);
    };
    // Grid points first (index i * cols + j), then their feet on the floor along the border.
    for (int i = 0; i < rows; ++i)
        for (int j = 0; j < cols; ++j) point(j, i, map.at(i, j));
    auto top = [&](int i, int j) { return uint32_t(i * cols + j); };
    for (int i = 1; i < rows; ++i)
        for (int j = 1; j < cols; ++j) {
            const double mid =
                (map.at(i - 1, j - 1) + map.at(i - 1, j) + map.at(i, j - 1) + map.at(i, j)) / 4.0;
            const uint32_t c = point(j - 0.5, i - 0.5, mid);
            const uint32_t a = top(i - 1, j - 1), b = top(i - 1, j), d = top(i, j),
                           e = top(i, j - 1);
            m.triangles.push_back({a, b, c});
            m.triangles.push_back({b, d, c});
            m.triangles.push_back({d, e, c});
            m.triangles.push_back({e, a, c});
        }
    // The border, counter-clockwise seen from +z, and a wall under each of its edges.
    std::vector<std::pair<int, int>> ring;
    for (int j = 0; j < cols - 1; ++j) ring.push_back({0, j});
    for (int i = 0; i < rows - 1; ++i) ring.push_back({i, cols - 1});
    for (int j = cols - 1; j > 0; --j) ring.push_back({rows - 1, j});
    for (int i = rows - 1; i > 0; --i) ring.push_back({i, 0});
    std::vector<uint32_t> feet;
    for (const auto& [i, j] : ring) feet.push_back(point(j, i, floor));
    const uint32_t centre = point((cols - 1) / 2.0, (rows - 1) / 2.0, floor);
    for (size_t k = 0; k < ring.size(); ++k) {
        const size_t n = (k + 1) % ring.size();
        const uint32_t p = top(ring[k].first, ring[k].second),
                       q = top(ring[n].first, ring[n].second);
        m.triangles.push_back({p, feet[k], feet[n]});
        m.triangles.push_back({p, feet[n], q});
        m.triangles.push_back({centre, feet[n], feet[k]});
    }
    return m;
}

}  // namespace lancer::openscad
