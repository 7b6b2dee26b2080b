// Source text with line/column lookup, shared by every scene reader's error messages.
#pragma once

#include <string>
#include <vector>

namespace lancer {

/// Why `path` cannot be read as a file: "no such file", "is a directory, not a file", or ""
/// (other problems show when it is opened).
std::string fileProblem(const std::string& path);

class SourceText {
  public:
    SourceText(std::string path, std::string text);
    /// Read a whole file; throws SceneError naming the path when it cannot be read.
    static SourceText fromFile(const std::string& path);
    /// fromFile for a file a scene imports: only a regular file (a device or a pipe could be
    /// read for ever) of at most 256 MiB; `what` names it in the message ("a DXF drawing").
    static SourceText fromImportedFile(const std::string& path, const std::string& what);
    const std::string& path() const { return path_; }
    const std::string& text() const { return text_; }
    /// 1-based line and column of byte offset `pos`.
    void lineColumn(size_t pos, int& line, int& col) const;
    /// "path:line:col" of byte offset `pos`.
    std::string where(size_t pos) const;
    /// Throw SceneError("path:line:col: message").
    [[noreturn]] void fail(size_t pos, const std::string& message) const;

  private:
    std::string path_, text_;
    std::vector<size_t> lineStarts_;
};

}  // namespace lancer
