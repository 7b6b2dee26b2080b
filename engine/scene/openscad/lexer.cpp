#include "engine/scene/openscad/lexer.h"

#include <cctype>
#include <cstdio>

#include "engine/scene/tokenizer.h"

namespace lancer::openscad {

namespace {

bool identStart(char c) {
    return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == '$';
}
bool identPart(char c) { return identStart(c) || std::isdigit(static_cast<unsigned char>(c)); }
bool digit(char c) { return c >= '0' && c <= '9'; }

/// Skips white space and comments from `p`.
size_t skipBlank(const SourceText& src, size_t p) {
    const std::string& s = src.text();
    while (p < s.size()) {
        if (std::isspace(static_cast<unsigned char>(s[p]))) {
            ++p;
        } else if (s.compare(p, 2, "//") == 0) {
            while (p < s.size() && s[p] != '\n') ++p;
        } else if (s.compare(p, 2, "/*") == 0) {
            size_t end = s.find("*/", p + 2);
            if (end == std::string::npos) src.fail(p, "unterminated comment: '/*' without '*/'");
            p = end + 2;
        } else {
            break;
        }
    }
    return p;
}

/// The number starting at `start`: digits, an optional fraction and an optional exponent.
size_t scanNumber(const SourceText& src, size_t start, Token& t) {
    const std::string& s = src.text();
    size_t p = start;
    while (p < s.size() && digit(s[p])) ++p;
    if (p < s.size() && s[p] == '.') {
        ++p;
        while (p < s.size() && digit(s[p])) ++p;
    }
    if (p < s.size() && (s[p] == 'e' || s[p] == 'E')) {
        size_t q = p + 1;
        if (q < s.size() && (s[q] == '+' || s[q] == '-')) ++q;
        if (q >= s.size() || !digit(s[q]))
            src.fail(start, "malformed number: an exponent needs digits");
        while (q < s.size() && digit(s[q])) ++q;
        p = q;
    }
    t.kind = Tok::Number;
    if (!parseFiniteDouble(std::string_view(s).substr(start, p - start), t.number))
        src.fail(start, "number '" + s.substr(start, p - start) +
                            "' is out of range (not a finite double)");
    return p;
}

/// The string whose opening quote is at `start`, escapes decoded into `t.str`.
size_t scanString(const SourceText& src, size_t start, Token& t) {
    const std::string& s = src.text();
    size_t p = start + 1;
    while (true) {
        if (p >= s.size()) src.fail(start, "unterminated string: no closing '\"'");
        char d = s[p++];
        if (d == '"') break;
        if (d == '\\') {
            if (p >= s.size()) src.fail(start, "unterminated string: no closing '\"'");
            char e = s[p++];
            t.str += e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e;
        } else {
            t.str += d;
        }
    }
    t.kind = Tok::String;
    return p;
}

}  // namespace

std::string printable(std::string_view s) {
    std::string r;
    for (char c : s) {
        unsigned char u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u < 0x7f) {
            r += c;
        } else {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\x%02x", u);
            r += buf;
        }
    }
    return r;
}

std::vector<Token> tokenize(const SourceText& src) {
    const std::string& s = src.text();
    std::vector<Token> out;
    size_t p = 0;
    while (true) {
        p = skipBlank(src, p);
        Token t;
        t.pos = p;
        if (p >= s.size()) {
            out.push_back(std::move(t));
            return out;
        }
        char c = s[p];
        size_t start = p;
        if (identStart(c)) {
            while (p < s.size() && identPart(s[p])) ++p;
            t.kind = Tok::Ident;
        } else if (digit(c) || (c == '.' && p + 1 < s.size() && digit(s[p + 1]))) {
            p = scanNumber(src, start, t);
        } else if (c == '"') {
            p = scanString(src, start, t);
        } else if (std::string_view("()[]{},;=%*#!-+:").find(c) != std::string_view::npos) {
            ++p;
            t.kind = Tok::Punct;
        } else {
            src.fail(p, "unexpected character '" + printable(std::string_view(&s[p], 1)) + "'");
        }
        t.text = std::string_view(s).substr(start, p - start);
        out.push_back(std::move(t));
    }
}

}  // namespace lancer::openscad
