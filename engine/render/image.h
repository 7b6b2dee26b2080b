// Images the tracer fills: colour, depth and per-pixel counters, and their files.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "engine/geometry/geometry.h"

namespace lancer {

struct Image {
    int width = 0, height = 0;
    std::vector<glm::vec3> color;     ///< linear RGB, row 0 on top
    std::vector<float> depth;         ///< primary hit distance along the unit direction; +inf: miss
    std::vector<uint32_t> hitPrim;    ///< primitive of the primary hit; kNoPrim on a miss
    std::vector<uint32_t> primTests;  ///< per pixel, every ray of the pixel
    std::vector<uint32_t> regionVisits;
    std::vector<float> timeUs;  ///< per pixel wall time in microseconds

    Image() = default;
    Image(int w, int h) { resize(w, h); }
    void resize(int w, int h);
    size_t index(int x, int y) const { return size_t(y) * size_t(width) + size_t(x); }
    /// 8-bit sRGB-ish bytes (clamped, gamma 1/2.2 not applied: NFF colours are display values)
    /// of rows [rowBegin, rowEnd) (-1: to the last).
    std::vector<uint8_t> rgba8(int rowBegin = 0, int rowEnd = -1) const;
    /// The same bytes written to `out` (4 x width bytes a row), the rows in the opposite order
    /// when `bottomUp` (as an OpenGL texture holds them).
    void rgba8Into(uint8_t* out, int rowBegin, int rowEnd, bool bottomUp) const;
    /// Rows [rowBegin, rowEnd) clamped to the image, as a pixel index range [first, last).
    void pixelRange(int rowBegin, int rowEnd, size_t& first, size_t& last) const;
};

/// Rows [begin, end) of an image written since someone last took them; empty when begin == end.
struct RowRange {
    int begin = 0, end = 0;
    bool empty() const { return begin >= end; }
    /// Grow to cover rows [b, e) too (nothing for an empty one).
    void add(int b, int e) {
        if (b >= e) return;
        begin = empty() ? b : std::min(begin, b);
        end = empty() ? e : std::max(end, e);
    }
    void clear() { begin = end = 0; }
};

/// Copy rows [rowBegin, rowEnd) (-1: to the last) of every channel of `src` into `dst`, which
/// is first made a whole copy of `src` if its size differs.
void copyRows(const Image& src, Image& dst, int rowBegin = 0, int rowEnd = -1);

/// Write a PNG atomically (a temporary file renamed into place). Throws std::runtime_error.
void writePng(const std::string& path, int w, int h, const std::vector<uint8_t>& rgba);
void writePng(const std::string& path, const Image& img);
/// Standard PFM ("Pf", little endian, rows bottom to top) of the depth channel.
void writeDepthPfm(const std::string& path, const Image& img);
/// Read a one-channel PFM. Throws std::runtime_error.
std::vector<float> readPfm(const std::string& path, int& w, int& h);
/// Read a PNG as RGBA8. Throws std::runtime_error.
std::vector<uint8_t> readPng(const std::string& path, int& w, int& h);
/// Write `data` to `path` atomically.
void writeFileAtomic(const std::string& path, const std::string& data);
/// Write what `write` puts in the stream to `path` atomically: into a temporary file renamed
/// into place once complete, so an exception or a failed write leaves no partial file.
void writeFileAtomic(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace lancer
