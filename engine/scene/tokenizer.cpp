#include "engine/scene/tokenizer.h"

#include <charconv>
#include <cmath>

namespace lancer {

bool parseFiniteDouble(std::string_view s, double& out) {
    if (s.empty()) return false;
    const char* b = s.data();
    const char* e = s.data() + s.size();
    if (*b == '+') ++b;  // from_chars rejects a leading '+', NFF writers emit it
    auto r = std::from_chars(b, e, out);
    return r.ec == std::errc() && r.ptr == e && std::isfinite(out);
}

Token WordReader::peek() {
    size_t save = pos_;
    Token t = next();
    pos_ = save;
    return t;
}

Token WordReader::next() {
    const std::string& s = src_.text();
    while (pos_ < s.size()) {
        char c = s[pos_];
        if (c == '#') {
            while (pos_ < s.size() && s[pos_] != '\n') ++pos_;
        } else if (std::isspace(static_cast<unsigned char>(c))) {
            ++pos_;
        } else {
            break;
        }
    }
    size_t start = pos_;
    while (pos_ < s.size() && !std::isspace(static_cast<unsigned char>(s[pos_]))) ++pos_;
    return {std::string_view(s).substr(start, pos_ - start), start};
}

double WordReader::number(const char* what) {
    Token t = next();
    if (t.text.empty()) src_.fail(t.pos, std::string("unexpected end of file: expected ") + what);
    double v;
    if (!parseFiniteDouble(t.text, v))
        src_.fail(t.pos, std::string("expected ") + what + " (a finite number), got '" +
                             std::string(t.text) + "'");
    return v;
}

int WordReader::count(const char* what, int max) {
    Token t = next();
    if (t.text.empty()) src_.fail(t.pos, std::string("unexpected end of file: expected ") + what);
    double v;
    if (!parseFiniteDouble(t.text, v) || v != std::floor(v) || v < 0)
        src_.fail(t.pos, std::string("expected ") + what + " (a non-negative integer), got '" +
                             std::string(t.text) + "'");
    if (v > max)
        src_.fail(t.pos, std::string(what) + " " + std::string(t.text) +
                             " is larger than the limit of " + std::to_string(max));
    return int(v);
}

Vec3 WordReader::vec3(const char* what) {
    double x = number(what), y = number(what), z = number(what);
    return {x, y, z};
}

}  // namespace lancer
