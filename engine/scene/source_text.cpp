#include "engine/scene/source_text.h"

#include <algorithm>
#include <fstream>
#include <sstream>

#include "engine/scene/scene.h"

namespace lancer {

SourceText::SourceText(std::string path, std::string text)
    : path_(std::move(path)), text_(std::move(text)) {
    lineStarts_.push_back(0);
    for (size_t i = 0; i < text_.size(); ++i)
        if (text_[i] == '\n') lineStarts_.push_back(i + 1);
}

SourceText SourceText::fromFile(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw SceneError(path + ": cannot open the file");
    std::ostringstream ss;
    ss << f.rdbuf();
    if (f.bad()) throw SceneError(path + ": read error");
    return SourceText(path, ss.str());
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
