// The OpenSCAD .csg parser: tokens to a tree of nodes with their arguments and modifiers.
// OpenSCAD's export writes only literals, so a value is a number, boolean, string, undef or
// vector; expressions, assignments and ranges are refused naming their position.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "engine/scene/openscad/lexer.h"
#include "engine/scene/source_text.h"

namespace lancer::openscad {

/// Nesting deeper than this (nodes inside nodes, vectors inside vectors) is refused: the parser,
/// the builder and the CSG evaluation all recurse on it. OpenSCAD's own exports stay far below.
constexpr int kMaxDepth = 500;

struct Value {
    enum class Kind : uint8_t { Undef, Bool, Number, String, Vector } kind = Kind::Undef;
    double number = 0.0;
    bool boolean = false;
    std::string str;
    std::vector<Value> items;  ///< Vector
    size_t pos = 0;            ///< byte offset of its first token
};

struct Arg {
    std::string name;  ///< empty for a positional argument
    Value value;
    size_t pos = 0;
};

struct Node {
    std::string name;
    size_t pos = 0;           ///< of the name
    bool disable = false;     ///< `*`
    bool background = false;  ///< `%`
    bool highlight = false;   ///< `#`
    bool root = false;        ///< `!`
    std::vector<Arg> args;
    std::vector<Node> children;
};

/// The file's top-level statements. Throws SceneError naming file:line:col.
std::vector<Node> parse(const SourceText& src, const std::vector<Token>& tokens);

}  // namespace lancer::openscad
