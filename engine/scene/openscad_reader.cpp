#include "engine/scene/openscad_reader.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <optional>

#include "engine/scene/json_reader.h"
#include "engine/scene/tokenizer.h"

namespace lancer {

namespace {

// Nesting deeper than this (nodes inside nodes, vectors inside vectors) is refused: the parser,
// the builder and the CSG evaluation all recurse on it. OpenSCAD's own exports stay far below.
constexpr int kMaxDepth = 500;

// OpenSCAD's default face colour (the "Cornfield" scheme), for nodes without a color().
constexpr uint32_t kDefaultColor = 0xf9d72c;

// The SVG colour names OpenSCAD's color() accepts (case-insensitive).
const std::map<std::string, uint32_t, std::less<>> kColorNames = {
    {"aliceblue", 0xf0f8ff},
    {"antiquewhite", 0xfaebd7},
    {"aqua", 0x00ffff},
    {"aquamarine", 0x7fffd4},
    {"azure", 0xf0ffff},
    {"beige", 0xf5f5dc},
    {"bisque", 0xffe4c4},
    {"black", 0x000000},
    {"blanchedalmond", 0xffebcd},
    {"blue", 0x0000ff},
    {"blueviolet", 0x8a2be2},
    {"brown", 0xa52a2a},
    {"burlywood", 0xdeb887},
    {"cadetblue", 0x5f9ea0},
    {"chartreuse", 0x7fff00},
    {"chocolate", 0xd2691e},
    {"coral", 0xff7f50},
    {"cornflowerblue", 0x6495ed},
    {"cornsilk", 0xfff8dc},
    {"crimson", 0xdc143c},
    {"cyan", 0x00ffff},
    {"darkblue", 0x00008b},
    {"darkcyan", 0x008b8b},
    {"darkgoldenrod", 0xb8860b},
    {"darkgray", 0xa9a9a9},
    {"darkgreen", 0x006400},
    {"darkgrey", 0xa9a9a9},
    {"darkkhaki", 0xbdb76b},
    {"darkmagenta", 0x8b008b},
    {"darkolivegreen", 0x556b2f},
    {"darkorange", 0xff8c00},
    {"darkorchid", 0x9932cc},
    {"darkred", 0x8b0000},
    {"darksalmon", 0xe9967a},
    {"darkseagreen", 0x8fbc8f},
    {"darkslateblue", 0x483d8b},
    {"darkslategray", 0x2f4f4f},
    {"darkslategrey", 0x2f4f4f},
    {"darkturquoise", 0x00ced1},
    {"darkviolet", 0x9400d3},
    {"deeppink", 0xff1493},
    {"deepskyblue", 0x00bfff},
    {"dimgray", 0x696969},
    {"dimgrey", 0x696969},
    {"dodgerblue", 0x1e90ff},
    {"firebrick", 0xb22222},
    {"floralwhite", 0xfffaf0},
    {"forestgreen", 0x228b22},
    {"fuchsia", 0xff00ff},
    {"gainsboro", 0xdcdcdc},
    {"ghostwhite", 0xf8f8ff},
    {"gold", 0xffd700},
    {"goldenrod", 0xdaa520},
    {"gray", 0x808080},
    {"green", 0x008000},
    {"greenyellow", 0xadff2f},
    {"grey", 0x808080},
    {"honeydew", 0xf0fff0},
    {"hotpink", 0xff69b4},
    {"indianred", 0xcd5c5c},
    {"indigo", 0x4b0082},
    {"ivory", 0xfffff0},
    {"khaki", 0xf0e68c},
    {"lavender", 0xe6e6fa},
    {"lavenderblush", 0xfff0f5},
    {"lawngreen", 0x7cfc00},
    {"lemonchiffon", 0xfffacd},
    {"lightblue", 0xadd8e6},
    {"lightcoral", 0xf08080},
    {"lightcyan", 0xe0ffff},
    {"lightgoldenrodyellow", 0xfafad2},
    {"lightgray", 0xd3d3d3},
    {"lightgreen", 0x90ee90},
    {"lightgrey", 0xd3d3d3},
    {"lightpink", 0xffb6c1},
    {"lightsalmon", 0xffa07a},
    {"lightseagreen", 0x20b2aa},
    {"lightskyblue", 0x87cefa},
    {"lightslategray", 0x778899},
    {"lightslategrey", 0x778899},
    {"lightsteelblue", 0xb0c4de},
    {"lightyellow", 0xffffe0},
    {"lime", 0x00ff00},
    {"limegreen", 0x32cd32},
    {"linen", 0xfaf0e6},
    {"magenta", 0xff00ff},
    {"maroon", 0x800000},
    {"mediumaquamarine", 0x66cdaa},
    {"mediumblue", 0x0000cd},
    {"mediumorchid", 0xba55d3},
    {"mediumpurple", 0x9370db},
    {"mediumseagreen", 0x3cb371},
    {"mediumslateblue", 0x7b68ee},
    {"mediumspringgreen", 0x00fa9a},
    {"mediumturquoise", 0x48d1cc},
    {"mediumvioletred", 0xc71585},
    {"midnightblue", 0x191970},
    {"mintcream", 0xf5fffa},
    {"mistyrose", 0xffe4e1},
    {"moccasin", 0xffe4b5},
    {"navajowhite", 0xffdead},
    {"navy", 0x000080},
    {"oldlace", 0xfdf5e6},
    {"olive", 0x808000},
    {"olivedrab", 0x6b8e23},
    {"orange", 0xffa500},
    {"orangered", 0xff4500},
    {"orchid", 0xda70d6},
    {"palegoldenrod", 0xeee8aa},
    {"palegreen", 0x98fb98},
    {"paleturquoise", 0xafeeee},
    {"palevioletred", 0xdb7093},
    {"papayawhip", 0xffefd5},
    {"peachpuff", 0xffdab9},
    {"peru", 0xcd853f},
    {"pink", 0xffc0cb},
    {"plum", 0xdda0dd},
    {"powderblue", 0xb0e0e6},
    {"purple", 0x800080},
    {"rebeccapurple", 0x663399},
    {"red", 0xff0000},
    {"rosybrown", 0xbc8f8f},
    {"royalblue", 0x4169e1},
    {"saddlebrown", 0x8b4513},
    {"salmon", 0xfa8072},
    {"sandybrown", 0xf4a460},
    {"seagreen", 0x2e8b57},
    {"seashell", 0xfff5ee},
    {"sienna", 0xa0522d},
    {"silver", 0xc0c0c0},
    {"skyblue", 0x87ceeb},
    {"slateblue", 0x6a5acd},
    {"slategray", 0x708090},
    {"slategrey", 0x708090},
    {"snow", 0xfffafa},
    {"springgreen", 0x00ff7f},
    {"steelblue", 0x4682b4},
    {"tan", 0xd2b48c},
    {"teal", 0x008080},
    {"thistle", 0xd8bfd8},
    {"tomato", 0xff6347},
    {"turquoise", 0x40e0d0},
    {"violet", 0xee82ee},
    {"wheat", 0xf5deb3},
    {"white", 0xffffff},
    {"whitesmoke", 0xf5f5f5},
    {"yellow", 0xffff00},
    {"yellowgreen", 0x9acd32},
};

Vec3 hexColor(uint32_t hex) {
    return Vec3(double((hex >> 16) & 0xff), double((hex >> 8) & 0xff), double(hex & 0xff)) / 255.0;
}

// ---- Tokens ---------------------------------------------------------------------------------

enum class Tok : uint8_t { End, Ident, Number, String, Punct };

struct ScadToken {
    Tok kind = Tok::End;
    std::string_view text;  ///< as written (for strings: with the quotes)
    size_t pos = 0;
    double number = 0.0;  ///< Number tokens
    std::string str;      ///< String tokens, escapes decoded
};

bool identStart(char c) {
    return std::isalpha(static_cast<unsigned char>(c)) || c == '_' || c == '$';
}
bool identPart(char c) { return identStart(c) || std::isdigit(static_cast<unsigned char>(c)); }
bool digit(char c) { return c >= '0' && c <= '9'; }

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

/// Splits the whole text into tokens; `//` and `/* */` comments are skipped.
std::vector<ScadToken> tokenize(const SourceText& src) {
    const std::string& s = src.text();
    std::vector<ScadToken> out;
    size_t p = 0;
    while (true) {
        // Whitespace and comments.
        while (p < s.size()) {
            if (std::isspace(static_cast<unsigned char>(s[p]))) {
                ++p;
            } else if (s.compare(p, 2, "//") == 0) {
                while (p < s.size() && s[p] != '\n') ++p;
            } else if (s.compare(p, 2, "/*") == 0) {
                size_t end = s.find("*/", p + 2);
                if (end == std::string::npos)
                    src.fail(p, "unterminated comment: '/*' without '*/'");
                p = end + 2;
            } else {
                break;
            }
        }
        ScadToken t;
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
            auto r = std::from_chars(s.data() + start, s.data() + p, t.number);
            if (r.ec != std::errc() || r.ptr != s.data() + p || !std::isfinite(t.number))
                src.fail(start, "number '" + s.substr(start, p - start) +
                                    "' is out of range (not a finite double)");
        } else if (c == '"') {
            ++p;
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

// ---- Syntax tree ----------------------------------------------------------------------------

struct ScadValue {
    enum class Kind : uint8_t { Undef, Bool, Number, String, Vector } kind = Kind::Undef;
    double number = 0.0;
    bool boolean = false;
    std::string str;
    std::vector<ScadValue> items;
    size_t pos = 0;
};

struct ScadArg {
    std::string name;  ///< empty for a positional argument
    ScadValue value;
    size_t pos = 0;
};

struct ScadNode {
    std::string name;
    size_t pos = 0;           ///< of the name
    bool disable = false;     ///< `*`
    bool background = false;  ///< `%`
    bool highlight = false;   ///< `#`
    bool root = false;        ///< `!`
    std::vector<ScadArg> args;
    std::vector<ScadNode> children;
};

/// Recursive descent over the token list: statements, arguments and values.
class Parser {
  public:
    Parser(const SourceText& src, std::vector<ScadToken> toks)
        : src_(src), toks_(std::move(toks)) {}

    std::vector<ScadNode> file() {
        std::vector<ScadNode> nodes;
        while (peek().kind != Tok::End) {
            if (isPunct("}")) src_.fail(peek().pos, "unmatched '}'");
            statement(nodes, 0);
        }
        return nodes;
    }

  private:
    const ScadToken& peek() const { return toks_[i_]; }
    const ScadToken& take() {
        const ScadToken& t = toks_[i_];
        if (t.kind != Tok::End) ++i_;
        return t;
    }
    bool isPunct(std::string_view p) const { return peek().kind == Tok::Punct && peek().text == p; }
    std::string describe(const ScadToken& t) const {
        return t.kind == Tok::End ? "the end of the file" : "'" + printable(t.text) + "'";
    }
    void expect(std::string_view p, const char* context) {
        const ScadToken& t = peek();
        if (t.kind == Tok::End)
            src_.fail(t.pos, std::string("unexpected end of file: expected '") + std::string(p) +
                                 "' " + context);
        if (!isPunct(p))
            src_.fail(t.pos, std::string("expected '") + std::string(p) + "' " + context +
                                 ", got " + describe(t));
        take();
    }
    void checkDepth(int depth, size_t pos) {
        if (depth > kMaxDepth)
            src_.fail(pos,
                      "nesting deeper than " + std::to_string(kMaxDepth) + " levels is refused");
    }

    /// One statement: `;`, or [modifiers] name(args) followed by `;`, `{ ... }` or one child.
    void statement(std::vector<ScadNode>& out, int depth) {
        checkDepth(depth, peek().pos);
        if (isPunct(";")) {
            take();
            return;
        }
        ScadNode n;
        while (peek().kind == Tok::Punct && (peek().text == "*" || peek().text == "%" ||
                                             peek().text == "#" || peek().text == "!")) {
            char m = take().text[0];
            n.disable |= m == '*';
            n.background |= m == '%';
            n.highlight |= m == '#';
            n.root |= m == '!';
        }
        const ScadToken& name = peek();
        if (name.kind == Tok::End)
            src_.fail(name.pos, "unexpected end of file: expected a node name");
        if (name.kind != Tok::Ident)
            src_.fail(name.pos,
                      "expected a node name such as cube or multmatrix, got " + describe(name));
        n.name = std::string(name.text);
        n.pos = name.pos;
        take();
        if (peek().kind == Tok::Punct && peek().text == "=")
            src_.fail(peek().pos, "assignments ('" + n.name +
                                      " = ...') are not part of OpenSCAD's CSG export; export the "
                                      "model with 'openscad -o model.csg'");
        expect("(", ("after '" + n.name + "'").c_str());
        arguments(n, depth);
        if (isPunct(";")) {
            take();
        } else if (isPunct("{")) {
            size_t open = take().pos;
            while (!isPunct("}")) {
                if (peek().kind == Tok::End)
                    src_.fail(peek().pos, "unexpected end of file: missing '}' for the '{' at " +
                                              src_.where(open));
                statement(n.children, depth + 1);
            }
            take();
        } else if (peek().kind == Tok::End) {
            src_.fail(peek().pos,
                      "unexpected end of file: expected ';' or '{' after " + n.name + "(...)");
        } else {
            statement(n.children, depth + 1);  // a single child without braces
        }
        out.push_back(std::move(n));
    }

    void arguments(ScadNode& n, int depth) {
        if (isPunct(")")) {
            take();
            return;
        }
        while (true) {
            ScadArg a;
            a.pos = peek().pos;
            if (peek().kind == Tok::Ident && toks_[i_ + 1].kind == Tok::Punct &&
                toks_[i_ + 1].text == "=") {
                a.name = std::string(take().text);
                take();
            }
            a.value = value(depth + 1);
            n.args.push_back(std::move(a));
            if (isPunct(",")) {
                take();
                continue;
            }
            expect(")", ("to close the arguments of " + n.name).c_str());
            return;
        }
    }

    ScadValue value(int depth) {
        checkDepth(depth, peek().pos);
        const ScadToken& t = peek();
        ScadValue v;
        v.pos = t.pos;
        if (t.kind == Tok::End) src_.fail(t.pos, "unexpected end of file: expected a value");
        if (t.kind == Tok::Number) {
            v.kind = ScadValue::Kind::Number;
            v.number = take().number;
            return v;
        }
        if (t.kind == Tok::Punct && (t.text == "-" || t.text == "+")) {
            bool neg = take().text == "-";
            const ScadToken& num = peek();
            if (num.kind != Tok::Number) {
                if (num.kind == Tok::Ident && (num.text == "inf" || num.text == "nan"))
                    src_.fail(num.pos, "expected a finite number, got '" + std::string(t.text) +
                                           std::string(num.text) + "'");
                src_.fail(num.pos, "expected a number after '" + std::string(t.text) + "', got " +
                                       describe(num));
            }
            v.kind = ScadValue::Kind::Number;
            v.number = neg ? -take().number : take().number;
            return v;
        }
        if (t.kind == Tok::String) {
            v.kind = ScadValue::Kind::String;
            v.str = take().str;
            return v;
        }
        if (t.kind == Tok::Ident) {
            if (t.text == "true" || t.text == "false") {
                v.kind = ScadValue::Kind::Bool;
                v.boolean = take().text == "true";
                return v;
            }
            if (t.text == "undef") {
                take();
                return v;
            }
            if (t.text == "inf" || t.text == "nan")
                src_.fail(t.pos, "expected a finite number, got '" + std::string(t.text) + "'");
            src_.fail(t.pos,
                      "expected a value (number, true, false, undef, string or [vector]), got '" +
                          printable(t.text) +
                          "': expressions are not part of OpenSCAD's CSG export");
        }
        if (t.kind == Tok::Punct && t.text == "[") {
            size_t open = take().pos;
            v.kind = ScadValue::Kind::Vector;
            if (isPunct("]")) {
                take();
                return v;
            }
            while (true) {
                v.items.push_back(value(depth + 1));
                if (isPunct(",")) {
                    take();
                    continue;
                }
                if (isPunct(":"))
                    src_.fail(peek().pos, "ranges ('[a:b]') are not supported in a .csg file");
                if (peek().kind == Tok::End)
                    src_.fail(peek().pos, "unexpected end of file: missing ']' for the '[' at " +
                                              src_.where(open));
                expect("]", "to close the vector");
                return v;
            }
        }
        src_.fail(t.pos, "expected a value, got " + describe(t));
    }

    const SourceText& src_;
    std::vector<ScadToken> toks_;
    size_t i_ = 0;
};

// ---- Building the scene ---------------------------------------------------------------------

/// A subtree's contribution: left out of the model (`*`, `%`), present but empty (an empty
/// group, a zero-size primitive), or a CSG node.
struct Built {
    enum class Kind : uint8_t { Absent, Empty, Node } kind = Kind::Empty;
    int node = -1;
    static Built absent() { return {Kind::Absent, -1}; }
    static Built empty() { return {Kind::Empty, -1}; }
    static Built of(int n) { return {Kind::Node, n}; }
};

/// A node's arguments, matched to OpenSCAD's parameter names (positional ones in order).
class Args {
  public:
    Args(const SourceText& src, const ScadNode& n, std::initializer_list<const char*> positional,
         std::initializer_list<const char*> named)
        : src_(src), node_(n) {
        size_t next = 0;
        std::vector<const char*> pos(positional), all(positional);
        all.insert(all.end(), named.begin(), named.end());
        for (const ScadArg& a : n.args) {
            std::string name = a.name;
            if (name.empty()) {
                if (next >= pos.size())
                    src.fail(a.pos, n.name + "() takes at most " + std::to_string(pos.size()) +
                                        " positional argument" + (pos.size() == 1 ? "" : "s"));
                name = pos[next++];
            } else if (name[0] == '$') {
                continue;  // $fn, $fa, $fs: tessellation settings; Lancer traces the exact solid
            } else {
                bool known = false;
                for (const char* k : all) known = known || name == k;
                if (!known) {
                    std::string list;
                    for (const char* k : all) list += std::string(list.empty() ? "" : ", ") + k;
                    src.fail(a.pos, "unknown argument '" + name + "' of " + n.name +
                                        "() (expected " + (list.empty() ? "none" : list) + ")");
                }
            }
            if (values_.count(name))
                src.fail(a.pos, "argument '" + name + "' of " + n.name + "() is given twice");
            if (a.value.kind != ScadValue::Kind::Undef)
                values_[name] = &a.value;  // undef: as if absent
        }
    }
    const ScadValue* get(const std::string& name) const {
        auto it = values_.find(name);
        return it == values_.end() ? nullptr : it->second;
    }
    double number(const ScadValue& v, const std::string& what) const {
        if (v.kind != ScadValue::Kind::Number) src_.fail(v.pos, "expected a number for " + what);
        return v.number;
    }
    std::optional<double> number(const std::string& name) const {
        const ScadValue* v = get(name);
        if (!v) return std::nullopt;
        return number(*v, "'" + name + "' of " + node_.name + "()");
    }
    bool boolean(const std::string& name, bool fallback) const {
        const ScadValue* v = get(name);
        if (!v) return fallback;
        if (v->kind != ScadValue::Kind::Bool)
            src_.fail(v->pos, "expected true or false for '" + name + "' of " + node_.name + "()");
        return v->boolean;
    }
    /// [x, y, z] (or [x, y] with z = `z2d` when `allow2d`).
    Vec3 vec3(const ScadValue& v, const std::string& what, bool allow2d = false,
              double z2d = 0.0) const {
        if (v.kind != ScadValue::Kind::Vector ||
            !(v.items.size() == 3 || (allow2d && v.items.size() == 2)))
            src_.fail(v.pos, "expected " +
                                 std::string(allow2d ? "[x, y] or [x, y, z]" : "[x, y, z]") +
                                 " for " + what);
        Vec3 r(z2d);
        for (size_t k = 0; k < v.items.size(); ++k) r[int(k)] = number(v.items[k], what);
        return r;
    }

  private:
    const SourceText& src_;
    const ScadNode& node_;
    std::map<std::string, const ScadValue*> values_;
};

class Builder {
  public:
    Builder(const SourceText& src, Scene& scene, OpenScadCounts& counts)
        : src_(src), scene_(scene), counts_(counts) {}

    /// The whole model: the children of the file's top level, or the first `!` subtree.
    int model(const std::vector<ScadNode>& top) {
        const ScadNode* root = nullptr;
        for (const ScadNode& n : top)
            if ((root = findRoot(n))) break;
        Built b;
        if (root) {
            // As OpenSCAD does: the `!` node becomes the root of the design, so the transforms
            // and colours above it do not apply, and everything else is left out.
            countLeftOut(top, root);
            b = node(*root, Transform(), 0);
        } else {
            b = unionOf(top, Transform(), 0);
        }
        return b.kind == Built::Kind::Node ? b.node : -1;
    }

  private:
    const ScadNode* findRoot(const ScadNode& n) {
        if (n.disable) return nullptr;
        if (n.root) return &n;
        for (const ScadNode& c : n.children)
            if (const ScadNode* r = findRoot(c)) return r;
        return nullptr;
    }
    void countLeftOut(const std::vector<ScadNode>& nodes, const ScadNode* root) {
        for (const ScadNode& n : nodes) {
            if (&n == root) continue;
            if (findRoot(n) == root)
                countLeftOut(n.children, root);
            else
                ++counts_.leftOut;
        }
    }

    Built unionOf(const std::vector<ScadNode>& kids, const Transform& xf, int mat) {
        std::vector<int> items;
        for (const ScadNode& k : kids) {
            Built b = node(k, xf, mat);
            if (b.kind == Built::Kind::Node) items.push_back(b.node);
        }
        return items.empty() ? Built::empty() : Built::of(scene_.tree.balanced(Op::Union, items));
    }

    Built node(const ScadNode& n, const Transform& xf, int mat) {
        if (n.disable || n.background) {
            ++counts_.leftOut;
            return Built::absent();
        }
        const std::string& k = n.name;
        if (k == "group" || k == "union" || k == "render") {
            if (k == "render")
                Args(src_, n, {"convexity"}, {});  // checks the arguments
            else
                Args(src_, n, {}, {});
            ++counts_.operators;
            return unionOf(n.children, xf, mat);
        }
        if (k == "intersection" || k == "difference") {
            Args a(src_, n, {}, {});
            ++counts_.operators;
            return boolean(n, k == "intersection" ? Op::Intersection : Op::Difference, xf, mat);
        }
        if (k == "multmatrix" || k == "translate" || k == "rotate" || k == "scale" ||
            k == "mirror") {
            ++counts_.transforms;
            Transform t = xf * transform(n);
            // Each step is finite and invertible; their product may still overflow.
            for (int c = 0; c < 4; ++c)
                for (int r = 0; r < 4; ++r)
                    if (!std::isfinite(t.m[c][r]) || !std::isfinite(t.inv[c][r]))
                        src_.fail(n.pos, k + "() gives a transform with non-finite entries");
            return unionOf(n.children, t, mat);
        }
        if (k == "color") {
            ++counts_.colors;
            return unionOf(n.children, xf, color(n, mat));
        }
        if (k == "cube" || k == "sphere" || k == "cylinder") {
            if (!n.children.empty()) src_.fail(n.children.front().pos, k + "() takes no children");
            return primitive(n, xf, mat);
        }
        refuse(n);
    }

    [[noreturn]] void refuse(const ScadNode& n) {
        static const char* twoD[] = {"circle", "square",     "polygon",   "text",
                                     "offset", "projection", "import_dxf"};
        for (const char* t : twoD)
            if (n.name == t)
                src_.fail(n.pos,
                          "the 2D node '" + n.name + "' is not supported: Lancer traces 3D solids");
        std::string list;
        for (const std::string& s : openScadSupportedNodes())
            list += (list.empty() ? "" : ", ") + s;
        src_.fail(n.pos, "the node '" + n.name + "' is not supported (supported: " + list + ")");
    }

    Built boolean(const ScadNode& n, Op op, const Transform& xf, int mat) {
        // Children left out by `*` or `%` are not there at all, as in OpenSCAD; a present but
        // empty child empties an intersection, and an empty first child empties a difference.
        std::vector<Built> kids;
        for (const ScadNode& c : n.children) {
            Built b = node(c, xf, mat);
            if (b.kind != Built::Kind::Absent) kids.push_back(b);
        }
        if (kids.empty()) return Built::empty();
        if (op == Op::Intersection) {
            std::vector<int> items;
            for (const Built& b : kids) {
                if (b.kind == Built::Kind::Empty) return Built::empty();
                items.push_back(b.node);
            }
            return Built::of(scene_.tree.balanced(Op::Intersection, items));
        }
        if (kids[0].kind == Built::Kind::Empty) return Built::empty();
        std::vector<int> cut;
        for (size_t i = 1; i < kids.size(); ++i)
            if (kids[i].kind == Built::Kind::Node) cut.push_back(kids[i].node);
        if (cut.empty()) return kids[0];
        return Built::of(scene_.tree.combine(Op::Difference, kids[0].node,
                                             scene_.tree.balanced(Op::Union, cut)));
    }

    Transform transform(const ScadNode& n) {
        const std::string& k = n.name;
        Transform t;
        if (k == "multmatrix") {
            Args a(src_, n, {"m"}, {});
            const ScadValue* m = a.get("m");
            if (!m) return t;  // OpenSCAD's default: the identity
            auto bad = [&] {
                src_.fail(m->pos,
                          "multmatrix expects a 4x4 matrix (or its first 3 rows) of numbers, as "
                          "[[a, b, c, d], ...]");
            };
            if (m->kind != ScadValue::Kind::Vector ||
                (m->items.size() != 4 && m->items.size() != 3))
                bad();
            Mat4 mm(1.0);
            for (size_t r = 0; r < m->items.size(); ++r) {
                const ScadValue& row = m->items[r];
                if (row.kind != ScadValue::Kind::Vector || row.items.size() != 4) bad();
                for (size_t c = 0; c < 4; ++c)
                    mm[int(c)][int(r)] =
                        a.number(row.items[c], "a multmatrix entry");  // row-major in the file
            }
            if (mm[0][3] != 0.0 || mm[1][3] != 0.0 || mm[2][3] != 0.0 || mm[3][3] != 1.0)
                src_.fail(m->items.back().pos,
                          "the last row of a multmatrix must be [0, 0, 0, 1] (projective "
                          "transforms are not supported)");
            t = Transform(mm);
        } else if (k == "translate") {
            Args a(src_, n, {"v"}, {});
            if (const ScadValue* v = a.get("v"))
                t = Transform::translate(a.vec3(*v, "'v' of translate()", true));
        } else if (k == "scale") {
            Args a(src_, n, {"v"}, {});
            if (const ScadValue* v = a.get("v"))
                t = Transform::scale(v->kind == ScadValue::Kind::Number
                                         ? Vec3(v->number)
                                         : a.vec3(*v, "'v' of scale()", true, 1.0));
        } else if (k == "mirror") {
            Args a(src_, n, {"v"}, {});
            if (const ScadValue* v = a.get("v")) {
                Vec3 p = a.vec3(*v, "'v' of mirror()", true);
                double len2 = glm::dot(p, p);
                if (len2 > 0.0) {
                    Vec3 u = p / std::sqrt(len2);
                    Mat4 mm(1.0);
                    for (int c = 0; c < 3; ++c)
                        for (int r = 0; r < 3; ++r) mm[c][r] -= 2.0 * u[c] * u[r];
                    t = Transform(mm);
                }
            }
        } else {  // rotate(a, v): a number about v (default z), or [x, y, z] applied x, then y,
                  // then z
            Args a(src_, n, {"a", "v"}, {});
            const ScadValue* ang = a.get("a");
            if (!ang) return t;
            if (ang->kind == ScadValue::Kind::Number) {
                Vec3 axis(0, 0, 1);
                if (const ScadValue* v = a.get("v")) axis = a.vec3(*v, "'v' of rotate()");
                if (glm::dot(axis, axis) == 0.0 || !std::isfinite(glm::dot(axis, axis)))
                    src_.fail(n.pos, "rotate() needs a non-zero axis 'v'");
                t = Transform::rotate(ang->number, axis);
            } else {
                Vec3 e = a.vec3(*ang, "'a' of rotate()", true);
                t = Transform::rotate(e.z, {0, 0, 1}) * Transform::rotate(e.y, {0, 1, 0}) *
                    Transform::rotate(e.x, {1, 0, 0});
            }
        }
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(t.m[c][r]))
                    src_.fail(n.pos, k + "() gives a transform with non-finite entries");
        if (!t.isInvertible())
            src_.fail(n.pos, k + "() is singular (it flattens its children to nothing)");
        return t;
    }

    int color(const ScadNode& n, int mat) {
        Args a(src_, n, {"c", "alpha"}, {});
        const ScadValue* c = a.get("c");
        if (!c) return mat;
        if (a.get("alpha")) a.number("alpha");  // checked; opacity is not modelled
        Vec3 rgb;
        if (c->kind == ScadValue::Kind::Vector) {
            if (c->items.size() != 3 && c->items.size() != 4)
                src_.fail(c->pos, "expected [r, g, b] or [r, g, b, a] for the colour");
            for (int i = 0; i < 3; ++i)
                rgb[i] = std::clamp(a.number(c->items[size_t(i)], "a colour component"), 0.0, 1.0);
            if (c->items.size() == 4) a.number(c->items[3], "the alpha component");
        } else if (c->kind == ScadValue::Kind::String) {
            rgb = namedColor(*c);
        } else {
            src_.fail(c->pos,
                      "expected a colour: [r, g, b, a], a name such as \"red\", or \"#rrggbb\"");
        }
        return material(rgb);
    }

    Vec3 namedColor(const ScadValue& c) {
        std::string s;
        for (char ch : c.str) s += char(std::tolower(static_cast<unsigned char>(ch)));
        uint32_t hex = 0;
        if (!s.empty() && s[0] == '#') {
            // #rgb, #rgba, #rrggbb, #rrggbbaa (alpha ignored)
            std::string h = s.substr(1);
            bool ok = h.size() == 3 || h.size() == 4 || h.size() == 6 || h.size() == 8;
            for (char ch : h) ok = ok && std::isxdigit(static_cast<unsigned char>(ch));
            if (!ok)
                src_.fail(c.pos, "malformed colour '" + printable(c.str) +
                                     "' (expected #rgb, #rgba, #rrggbb or #rrggbbaa)");
            if (h.size() <= 4) h = std::string{h[0], h[0], h[1], h[1], h[2], h[2]};
            hex = uint32_t(std::stoul(h.substr(0, 6), nullptr, 16));
        } else if (s == "transparent") {
            hex = 0;
        } else {
            auto it = kColorNames.find(s);
            if (it == kColorNames.end())
                src_.fail(c.pos, "unknown colour name '" + printable(c.str) +
                                     "' (OpenSCAD accepts the SVG colour names)");
            hex = it->second;
        }
        return hexColor(hex);
    }

    int material(const Vec3& rgb) {
        auto key = std::make_tuple(rgb.x, rgb.y, rgb.z);
        auto it = materialOf_.find(key);
        if (it != materialOf_.end()) return it->second;
        Material m = scene_.materials[0];
        m.color = rgb;
        scene_.materials.push_back(m);
        int id = int(scene_.materials.size()) - 1;
        materialOf_[key] = id;
        return id;
    }

    /// A size or radius: finite (the lexer made sure) and not negative.
    double nonNegative(const Args& a, const std::string& name, double value) {
        if (value < 0.0) src_.fail(a.get(name)->pos, "'" + name + "' must not be negative");
        return value;
    }

    Built primitive(const ScadNode& n, const Transform& xf, int mat) {
        const std::string& k = n.name;
        Shape shape;
        Transform local;
        if (k == "cube") {
            Args a(src_, n, {"size", "center"}, {});
            Vec3 size(1.0);
            if (const ScadValue* s = a.get("size")) {
                size = s->kind == ScadValue::Kind::Number ? Vec3(s->number)
                                                          : a.vec3(*s, "'size' of cube()");
                for (int i = 0; i < 3; ++i)
                    if (size[i] < 0.0) src_.fail(s->pos, "cube sizes must not be negative");
            }
            bool center = a.boolean("center", false);
            if (size.x == 0.0 || size.y == 0.0 || size.z == 0.0) return emptyPrimitive();
            Block b;
            b.lo = center ? -0.5 * size : Vec3(0.0);
            b.hi = b.lo + size;
            shape = b;
            ++counts_.cubes;
        } else if (k == "sphere") {
            Args a(src_, n, {"r"}, {"d"});
            double r = 1.0;
            if (auto d = a.number("d"))
                r = 0.5 * nonNegative(a, "d", *d);  // d takes precedence, as in OpenSCAD
            else if (auto rr = a.number("r"))
                r = nonNegative(a, "r", *rr);
            if (r == 0.0) return emptyPrimitive();
            shape = Sphere{Vec3(0.0), r};
            ++counts_.spheres;
        } else {
            Args a(src_, n, {"h", "r1", "r2", "center"}, {"r", "d", "d1", "d2"});
            double h = 1.0, r1 = 1.0, r2 = 1.0;
            if (auto v = a.number("h")) h = nonNegative(a, "h", *v);
            // OpenSCAD: d over r, d1 over r1, d2 over r2; r1/r2 (or d1/d2) over r (or d).
            std::optional<double> r, rr1, rr2;
            if (auto d = a.number("d"))
                r = 0.5 * nonNegative(a, "d", *d);
            else if (auto v = a.number("r"))
                r = nonNegative(a, "r", *v);
            if (auto d = a.number("d1"))
                rr1 = 0.5 * nonNegative(a, "d1", *d);
            else if (auto v = a.number("r1"))
                rr1 = nonNegative(a, "r1", *v);
            if (auto d = a.number("d2"))
                rr2 = 0.5 * nonNegative(a, "d2", *d);
            else if (auto v = a.number("r2"))
                rr2 = nonNegative(a, "r2", *v);
            if (r) r1 = r2 = *r;
            if (rr1) r1 = *rr1;
            if (rr2) r2 = *rr2;
            bool center = a.boolean("center", false);
            if (h == 0.0 || (r1 == 0.0 && r2 == 0.0)) return emptyPrimitive();
            shape = Cone{r1, r2, h, false};
            if (center) local = Transform::translate({0.0, 0.0, -0.5 * h});
            ++(r1 == r2 ? counts_.cylinders : counts_.cones);
        }
        Primitive p = makePrimitive(std::move(shape), xf * local, mat);
        if (!p.worldBox.isBounded())
            src_.fail(n.pos, k + "() is too large: its bounds overflow a double");
        p.origin = src_.where(n.pos);
        scene_.prims.push_back(std::move(p));
        return Built::of(scene_.tree.leaf(uint32_t(scene_.prims.size() - 1)));
    }

    Built emptyPrimitive() {
        ++counts_.empty;
        return Built::empty();
    }

    const SourceText& src_;
    Scene& scene_;
    OpenScadCounts& counts_;
    std::map<std::tuple<double, double, double>, int> materialOf_;
};

}  // namespace

const std::vector<std::string>& openScadSupportedNodes() {
    static const std::vector<std::string> nodes = {
        "group",  "union", "difference", "intersection", "render", "multmatrix", "translate",
        "rotate", "scale", "mirror",     "color",        "cube",   "sphere",     "cylinder"};
    return nodes;
}

std::string openScadCameraPath(const std::string& csgPath) {
    std::string base = csgPath;
    size_t dot = base.rfind('.');
    size_t slash = base.rfind('/');
    if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) base.resize(dot);
    return base + ".camera.json";
}

Scene readOpenScad(const SourceText& src, const SourceText* camera, OpenScadCounts* countsOut) {
    Parser parser(src, tokenize(src));
    std::vector<ScadNode> top = parser.file();
    Scene scene;
    scene.name = src.path();
    scene.materials[0].color = hexColor(kDefaultColor);
    OpenScadCounts counts;
    Builder b(src, scene, counts);
    scene.tree.root = b.model(top);
    scene.prepare();
    // OpenSCAD's default view ($vpr = [55, 0, 25]): the eye at azimuth -65 degrees from +x,
    // 35 degrees above the ground plane, z up.
    const double el = glm::radians(35.0), az = glm::radians(25.0);
    Vec3 eye(std::sin(az) * std::cos(el), -std::cos(az) * std::cos(el), std::sin(el));
    scene.frameCamera(-eye, {0, 0, 1});
    bool sidecarLights = false;
    if (camera) {
        LocatedJson doc(*camera);
        JsonAt root{doc, doc.root(), ""};
        root.object();
        applyCameraJson(root, scene, false);
        sidecarLights = root.has("lights");
    }
    if (!sidecarLights) scene.defaultLights();
    if (countsOut) *countsOut = counts;
    return scene;
}

Scene readOpenScadFile(const std::string& path, OpenScadCounts* counts) {
    SourceText src = SourceText::fromFile(path);
    std::string cam = openScadCameraPath(path);
    std::error_code ec;
    if (std::filesystem::exists(cam, ec)) {
        SourceText camSrc = SourceText::fromFile(cam);
        return readOpenScad(src, &camSrc, counts);
    }
    return readOpenScad(src, nullptr, counts);
}

}  // namespace lancer
