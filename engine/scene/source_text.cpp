#include "engine/scene/source_text.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/scene/scene.h"

namespace lancer {

std::string fileProblem(const std::string& path) {
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(path, ec);
    if (st.type() == std::filesystem::file_type::not_found) return "no such file";
    if (st.type() == std::filesystem::file_type::directory) return "is a directory, not a file";
    return "";
}

SourceText::SourceText(std::string path, std::string text)
    : path_(std::move(path)), text_(std::move(text)) {
    lineStarts_.push_back(0);
    for (size_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') lineStarts_.push_back(i + 1);
}

SourceText SourceText::fromFile(const std::string& path) {
    // A directory opens as an empty stream on Linux: refused by name, as a missing file is.
    if (std::string why = fileProblem(path); !why.empty()) throw SceneError(path + ": " + why);
    std::ifstream f(path, std::ios::binary);
    if (!f) throw SceneError(path + ": cannot open the file");
    std::ostringstream ss;
    ss << f.rdbuf();
    if (f.bad()) throw SceneError(path + ": read error");
    return SourceText(path, ss.str());
}

SourceText SourceText::fromImportedFile(const std::string& path, const std::string& what) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec))
        throw SceneError(path + ": not a regular file");
    constexpr uintmax_t kMaxBytes = uintmax_t(256) << 20;
    if (const uintmax_t size = std::filesystem::file_size(path, ec); !ec && size > kMaxBytes)
        throw SceneError(path + ": " + std::to_string(size >> 20) +
                         " MiB is over the 256 MiB Lancer reads of " + what);
    return fromFile(path);
}

void SourceText::lineColumn(size_t pos, int& line, int& col) const {
    pos = std::min(pos, text_.size());
    auto it = std::upper_bound(lineStarts_.begin(), lineStarts_.end(), pos);
    size_t l = size_t(it - lineStarts_.begin()) - 1;
    line = int(l) + 1;
    col = int(pos - lineStarts_[l]) + 1;
}

std::string SourceText::where(size_t pos) const {
    int line, col;
    lineColumn(pos, line, col);
    return path_ + ":" + std::to_string(line) + ":" + std::to_string(col);
}

void SourceText::fail(size_t pos, const std::string& message) const {
    throw SceneError(where(pos) + ": " + message);
}

}  // namespace lancer
