// The OpenSCAD .csg lexer: the text as identifiers, numbers, strings and punctuation, each with
// its byte offset for file:line:col messages.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "engine/scene/source_text.h"

namespace lancer::openscad {

enum class Tok : uint8_t { End, Ident, Number, String, Punct };

struct Token {
    Tok kind = Tok::End;    ///< End: the one token after the last, at the end of the text
    std::string_view text;  ///< as written (for strings: with the quotes)
    size_t pos = 0;         ///< byte offset in the source
    double number = 0.0;    ///< Number tokens
    std::string str;        ///< String tokens, escapes decoded
};

/// The whole text as tokens ending with one End token; `//` and `/* */` comments are skipped.
/// Throws SceneError at a malformed number, string or comment, or a character OpenSCAD's export
/// never writes.
std::vector<Token> tokenize(const SourceText& src);

/// `s` with every byte outside printable ASCII written as \xNN, for quoting input in messages.
std::string printable(std::string_view s);

}  // namespace lancer::openscad
