// Words with byte offsets for NFF, and the number syntax both text formats (NFF, OpenSCAD .csg)
// share.
#pragma once

#include <string>
#include <string_view>

#include "engine/geometry/geometry.h"
#include "engine/scene/source_text.h"

namespace lancer {

struct Token {
    std::string_view text;  ///< empty at end of input
    size_t pos = 0;
};

/// Whitespace-separated words; `#` starts a comment to the end of the line.
class WordReader {
  public:
    explicit WordReader(const SourceText& src) : src_(src) {}
    Token next();
    Token peek();
    /// A finite number; fails naming the position and `what` otherwise.
    double number(const char* what);
    int count(const char* what, int max);
    Vec3 vec3(const char* what);

  private:
    const SourceText& src_;
    size_t pos_ = 0;
};

/// Parse a whole token as a finite double (C locale). False for anything else.
bool parseFiniteDouble(std::string_view s, double& out);

}  // namespace lancer
