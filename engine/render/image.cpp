#include "engine/render/image.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "engine/model/span.h"

// Implementations come from Debian's libstb.
#include <stb_image.h>
#include <stb_image_write.h>

namespace lancer {

void Image::resize(int w, int h) {
    width = w;
    height = h;
    size_t n = size_t(w) * size_t(h);
    color.assign(n, glm::vec3(0.0f));
    depth.assign(n, std::numeric_limits<float>::infinity());
    hitPrim.assign(n, kNoPrim);
    primTests.assign(n, 0);
    regionVisits.assign(n, 0);
    timeUs.assign(n, 0.0f);
}

void Image::pixelRange(int rowBegin, int rowEnd, size_t& first, size_t& last) const {
    const int end = rowEnd < 0 ? height : std::min(rowEnd, height);
    const int begin = std::clamp(rowBegin, 0, std::max(end, 0));
    first = size_t(begin) * size_t(width);
    last = size_t(std::max(end, begin)) * size_t(width);
}

std::vector<uint8_t> Image::rgba8(int rowBegin, int rowEnd) const {
    size_t first, last;
    pixelRange(rowBegin, rowEnd, first, last);
    std::vector<uint8_t> out((last - first) * 4);
    rgba8Into(out.data(), rowBegin, rowEnd, false);
    return out;
}

static_assert(sizeof(glm::vec3) == 3 * sizeof(float), "rgba8Into reads a row as floats");

void Image::rgba8Into(uint8_t* out, int rowBegin, int rowEnd, bool bottomUp) const {
    size_t first, last;
    pixelRange(rowBegin, rowEnd, first, last);
    const size_t w = size_t(width), rows = w ? (last - first) / w : 0;
    for (size_t r = 0; r < rows; ++r) {
        // The row's floats in one run, so the loop vectorises (a viewer converts a 1280x720
        // image per pass).
        const float* src = &color[first + r * w].x;
        uint8_t* o = out + 4 * w * (bottomUp ? rows - 1 - r : r);
        for (size_t x = 0; x < w; ++x) {
            for (size_t c = 0; c < 3; ++c) {
                const float v = std::min(std::max(src[3 * x + c], 0.0f), 1.0f);
                o[4 * x + c] = uint8_t(v * 255.0f + 0.5f);
            }
            o[4 * x + 3] = 255;
        }
    }
}

void copyRows(const Image& src, Image& dst, int rowBegin, int rowEnd) {
    if (dst.width != src.width || dst.height != src.height) {
        dst = src;
        return;
    }
    size_t first, last;
    src.pixelRange(rowBegin, rowEnd, first, last);
    auto rows = [&](const auto& from, auto& to) {
        std::copy(from.begin() + std::ptrdiff_t(first), from.begin() + std::ptrdiff_t(last),
                  to.begin() + std::ptrdiff_t(first));
    };
    rows(src.color, dst.color);
    rows(src.depth, dst.depth);
    rows(src.hitPrim, dst.hitPrim);
    rows(src.primTests, dst.primTests);
    rows(src.regionVisits, dst.regionVisits);
    rows(src.timeUs, dst.timeUs);
}

void writeFileAtomic(const std::string& path, const std::string& data) {
    writeFileAtomic(path,
                    [&](std::ostream& f) { f.write(data.data(), std::streamsize(data.size())); });
}

void writeFileAtomic(const std::string& path, const std::function<void(std::ostream&)>& write) {
    std::string tmp = path + ".tmp";
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) throw std::runtime_error(path + ": cannot open for writing");
        try {
            write(f);
        } catch (...) {
            f.close();
            std::remove(tmp.c_str());
            throw;
        }
        f.close();
        if (!f) {
            std::remove(tmp.c_str());
            throw std::runtime_error(path + ": write failed");
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::remove(tmp.c_str());
        throw std::runtime_error(path + ": cannot rename the temporary file into place");
    }
}

void writePng(const std::string& path, int w, int h, const std::vector<uint8_t>& rgba) {
    std::string data;
    auto sink = [](void* ctx, void* bytes, int n) {
        static_cast<std::string*>(ctx)->append(static_cast<const char*>(bytes), size_t(n));
    };
    if (!stbi_write_png_to_func(sink, &data, w, h, 4, rgba.data(), w * 4))
        throw std::runtime_error(path + ": PNG encoding failed");
    writeFileAtomic(path, data);
}

void writePng(const std::string& path, const Image& img) {
    writePng(path, img.width, img.height, img.rgba8());
}

std::optional<ImageFormat> imageFormatOf(const std::string& path) {
    const size_t dot = path.find_last_of("./");
    if (dot == std::string::npos || path[dot] != '.') return std::nullopt;
    std::string ext = path.substr(dot + 1);
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    if (ext == "png") return ImageFormat::Png;
    if (ext == "jpg" || ext == "jpeg") return ImageFormat::Jpeg;
    return std::nullopt;
}

void writeImage(const std::string& path, int w, int h, const std::vector<uint8_t>& rgba) {
    const std::optional<ImageFormat> format = imageFormatOf(path);
    if (!format)
        throw std::runtime_error(path + ": unknown image format (use .png, .jpg or .jpeg)");
    if (*format == ImageFormat::Png) return writePng(path, w, h, rgba);
    std::string data;
    auto sink = [](void* ctx, void* bytes, int n) {
        static_cast<std::string*>(ctx)->append(static_cast<const char*>(bytes), size_t(n));
    };
    if (!stbi_write_jpg_to_func(sink, &data, w, h, 4, rgba.data(), 95))
        throw std::runtime_error(path + ": JPEG encoding failed");
    writeFileAtomic(path, data);
}

void writeImage(const std::string& path, const Image& img) {
    writeImage(path, img.width, img.height, img.rgba8());
}

void writeDepthPfm(const std::string& path, const Image& img) {
    std::ostringstream os;
    os << "Pf\n" << img.width << " " << img.height << "\n-1.0\n";
    std::string data = os.str();
    size_t header = data.size();
    data.resize(header + img.depth.size() * 4);
    char* p = data.data() + header;
    for (int y = img.height - 1; y >= 0; --y) {  // PFM rows go bottom to top
        std::memcpy(p, &img.depth[img.index(0, y)], size_t(img.width) * 4);  // x86: little endian
        p += size_t(img.width) * 4;
    }
    writeFileAtomic(path, data);
}

std::vector<float> readPfm(const std::string& path, int& w, int& h) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw std::runtime_error(path + ": cannot open");
    std::string magic;
    double scale;
    f >> magic >> w >> h >> scale;
    f.get();
    if (magic != "Pf" || w <= 0 || h <= 0 || scale >= 0)
        throw std::runtime_error(path + ": not a little-endian one-channel PFM");
    std::vector<float> rows(size_t(w) * size_t(h)), out(rows.size());
    f.read(reinterpret_cast<char*>(rows.data()), std::streamsize(rows.size() * 4));
    if (!f) throw std::runtime_error(path + ": truncated");
    for (int y = 0; y < h; ++y)
        std::memcpy(&out[size_t(y) * size_t(w)], &rows[size_t(h - 1 - y) * size_t(w)],
                    size_t(w) * 4);
    return out;
}

std::vector<uint8_t> readPng(const std::string& path, int& w, int& h) {
    int n;
    unsigned char* px = stbi_load(path.c_str(), &w, &h, &n, 4);
    if (!px) throw std::runtime_error(path + ": cannot read PNG: " + stbi_failure_reason());
    std::vector<uint8_t> out(px, px + size_t(w) * size_t(h) * 4);
    stbi_image_free(px);
    return out;
}

}  // namespace lancer
