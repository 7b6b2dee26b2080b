#include "engine/scene/mesh_file.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "engine/scene/scene.h"
#include "engine/scene/source_text.h"

namespace lancer {

namespace {

std::string lowerExtension(const std::string& path) {
    std::string e = std::filesystem::path(path).extension().string();
    for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

/// Whitespace-separated words with their offsets; `#` starts a comment to the end of the line
/// (OFF's comments; STL has none).
class Words {
  public:
    Words(const SourceText& src, bool comments) : src_(src), comments_(comments) {}
    bool next(std::string_view& w) {
        const std::string& t = src_.text();
        while (pos_ < t.size()) {
            const char c = t[pos_];
            if (comments_ && c == '#') {
                while (pos_ < t.size() && t[pos_] != '\n') ++pos_;
            } else if (std::isspace(static_cast<unsigned char>(c))) {
                ++pos_;
            } else {
                break;
            }
        }
        if (pos_ >= t.size()) return false;
        start_ = pos_;
        while (pos_ < t.size() && !std::isspace(static_cast<unsigned char>(t[pos_])) &&
               !(comments_ && t[pos_] == '#'))
            ++pos_;
        w = std::string_view(t).substr(start_, pos_ - start_);
        return true;
    }
    /// The next word, which must be there (`what` names it in the message).
    std::string_view word(const char* what) {
        std::string_view w;
        if (!next(w)) src_.fail(src_.text().size(), std::string("the file ends before ") + what);
        return w;
    }
    double number(const char* what) {
        const std::string_view w = word(what);
        double v = 0.0;
        const auto r = std::from_chars(w.data(), w.data() + w.size(), v);
        if (r.ec != std::errc() || r.ptr != w.data() + w.size() || !std::isfinite(v))
            fail(std::string("expected a finite number for ") + what + ", got '" + std::string(w) +
                 "'");
        return v;
    }
    uint64_t count(const char* what, uint64_t max) {
        const double v = number(what);
        if (v < 0.0 || v != std::floor(v) || v > double(max))
            fail(std::string("expected a whole number from 0 to ") + std::to_string(max) + " for " +
                 what);
        return uint64_t(v);
    }
    /// Skip the rest of the current line.
    void skipLine() {
        const std::string& t = src_.text();
        while (pos_ < t.size() && t[pos_] != '\n') ++pos_;
    }
    [[noreturn]] void fail(const std::string& m) const { src_.fail(start_, m); }

  private:
    const SourceText& src_;
    bool comments_;
    size_t pos_ = 0, start_ = 0;
};

/// Binary STL: an 80-byte header, a triangle count, then 50 bytes a triangle. Told from ASCII
/// by its size, which matches the count exactly (an ASCII file may begin with "solid" too).
bool isBinaryStl(const std::string& bytes) {
    if (bytes.size() < 84) return false;
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 80, 4);
    return bytes.size() == 84 + 50 * uint64_t(n);
}

void tooMany(const std::string& path, size_t max) {
    throw SceneError(path + ": more than " + std::to_string(max) +
                     " triangles, over what Lancer reads of a mesh");
}

TriangleMesh readStl(const SourceText& src, size_t maxTriangles) {
    const std::string& bytes = src.text();
    TriangleMesh m;
    if (isBinaryStl(bytes)) {
        uint32_t n = 0;
        std::memcpy(&n, bytes.data() + 80, 4);
        if (n > maxTriangles) tooMany(src.path(), maxTriangles);
        for (uint32_t i = 0; i < n; ++i) {
            float v[9];
            std::memcpy(v, bytes.data() + 84 + 50 * size_t(i) + 12, sizeof v);
            for (int k = 0; k < 3; ++k) {
                const Vec3 p(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
                    throw SceneError(src.path() + ": facet " + std::to_string(i) +
                                     " has a vertex that is not a finite number");
                m.points.push_back(p);
            }
            m.triangles.push_back({3 * i, 3 * i + 1, 3 * i + 2});
        }
        return m;
    }
    Words w(src, false);
    std::string_view word;
    if (!w.next(word) || word != "solid") w.fail("an ASCII STL file begins with 'solid'");
    int corner = 0;
    while (w.next(word)) {
        if (word == "vertex") {
            Vec3 p;
            p.x = w.number("a vertex's x");
            p.y = w.number("a vertex's y");
            p.z = w.number("a vertex's z");
            m.points.push_back(p);
            if (++corner == 3) {
                corner = 0;
                const uint32_t k = uint32_t(m.points.size());
                m.triangles.push_back({k - 3, k - 2, k - 1});
                if (m.triangles.size() > maxTriangles) tooMany(src.path(), maxTriangles);
            }
        } else if (word == "endloop" && corner != 0) {
            w.fail("a facet's loop needs three vertices");
        }
    }
    if (corner != 0) w.fail("the last facet has fewer than three vertices");
    return m;
}

TriangleMesh readOff(const SourceText& src, size_t maxTriangles) {
    Words w(src, true);
    std::string_view head = w.word("the 'OFF' header");
    if (head != "OFF") w.fail("an OFF file begins with 'OFF' (COFF, NOFF and 4OFF are not read)");
    TriangleMesh m;
    const uint64_t nv = w.count("the number of vertices", 3 * uint64_t(maxTriangles));
    const uint64_t nf = w.count("the number of faces", maxTriangles);
    w.count("the number of edges", ~uint32_t(0));
    for (uint64_t i = 0; i < nv; ++i) {
        Vec3 p;
        p.x = w.number("a vertex's x");
        p.y = w.number("a vertex's y");
        p.z = w.number("a vertex's z");
        m.points.push_back(p);
    }
    std::vector<uint32_t> loop;
    for (uint64_t f = 0; f < nf; ++f) {
        const uint64_t k = w.count("a face's number of corners", 1000000);
        loop.clear();
        for (uint64_t i = 0; i < k; ++i) {
            const uint64_t v = w.count("a face's point index", nv == 0 ? 0 : nv - 1);
            if (loop.empty() || loop.back() != v) loop.push_back(uint32_t(v));
        }
        while (loop.size() > 1 && loop.front() == loop.back()) loop.pop_back();
        if (loop.size() < 3) w.fail("a face needs at least three distinct points");
        m.addPolygon(loop);
        if (m.triangles.size() > maxTriangles) tooMany(src.path(), maxTriangles);
        w.skipLine();  // a face's colour, when given, follows its indices on its line
    }
    return m;
}

}  // namespace

bool isMeshFile(const std::string& path) {
    const std::string e = lowerExtension(path);
    return e == ".stl" || e == ".off";
}

TriangleMesh readMeshFile(const std::string& path, size_t maxTriangles) {
    return readMeshText(SourceText::fromImportedFile(path, "a mesh"),
                        lowerExtension(path) == ".off", maxTriangles);
}

TriangleMesh readMeshText(const SourceText& src, bool off, size_t maxTriangles) {
    return off ? readOff(src, maxTriangles) : readStl(src, maxTriangles);
}

}  // namespace lancer
