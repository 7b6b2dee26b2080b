#include "engine/scene/openscad/parser.h"

namespace lancer::openscad {

namespace {

/// Recursive descent over the token list: statements, arguments and values.
class Parser {
  public:
    Parser(const SourceText& src, const std::vector<Token>& toks) : src_(src), toks_(toks) {}

    std::vector<Node> file() {
        std::vector<Node> nodes;
        while (peek().kind != Tok::End) {
            if (isPunct("}")) src_.fail(peek().pos, "unmatched '}'");
            statement(nodes, 0);
        }
        return nodes;
    }

  private:
    const Token& peek() const { return toks_[i_]; }
    const Token& take() {
        const Token& t = toks_[i_];
        if (t.kind != Tok::End) ++i_;
        return t;
    }
    bool isPunct(std::string_view p) const { return peek().kind == Tok::Punct && peek().text == p; }
    std::string describe(const Token& t) const {
        if (t.kind == Tok::End) return "the end of the file";
        // Appended rather than "'" + ...: GCC 12 warns (-Wrestrict) on the inlined operator+.
        std::string quoted = "'";
        quoted += printable(t.text);
        return quoted += "'";
    }
    void expect(std::string_view p, const char* context) {
        const Token& t = peek();
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
    void statement(std::vector<Node>& out, int depth) {
        checkDepth(depth, peek().pos);
        if (isPunct(";")) {
            take();
            return;
        }
        Node n;
        while (peek().kind == Tok::Punct && (peek().text == "*" || peek().text == "%" ||
                                             peek().text == "#" || peek().text == "!")) {
            char m = take().text[0];
            n.disable |= m == '*';
            n.background |= m == '%';
            n.highlight |= m == '#';
            n.root |= m == '!';
        }
        const Token& name = peek();
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

    void arguments(Node& n, int depth) {
        if (isPunct(")")) {
            take();
            return;
        }
        while (true) {
            Arg a;
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

    Value value(int depth) {
        checkDepth(depth, peek().pos);
        const Token& t = peek();
        Value v;
        v.pos = t.pos;
        if (t.kind == Tok::End) src_.fail(t.pos, "unexpected end of file: expected a value");
        if (t.kind == Tok::Number) {
            v.kind = Value::Kind::Number;
            v.number = take().number;
            return v;
        }
        if (t.kind == Tok::Punct && (t.text == "-" || t.text == "+")) return signedNumber(v);
        if (t.kind == Tok::String) {
            v.kind = Value::Kind::String;
            v.str = take().str;
            return v;
        }
        if (t.kind == Tok::Ident) return word(v);
        if (t.kind == Tok::Punct && t.text == "[") return vector(v, depth);
        src_.fail(t.pos, "expected a value, got " + describe(t));
    }

    /// `-` or `+` and the number after it.
    Value signedNumber(Value& v) {
        const Token& sign = take();
        const bool neg = sign.text == "-";
        const Token& num = peek();
        if (num.kind != Tok::Number) {
            if (num.kind == Tok::Ident && (num.text == "inf" || num.text == "nan"))
                src_.fail(num.pos, "expected a finite number, got '" + std::string(sign.text) +
                                       std::string(num.text) + "'");
            src_.fail(num.pos, "expected a number after '" + std::string(sign.text) + "', got " +
                                   describe(num));
        }
        v.kind = Value::Kind::Number;
        v.number = neg ? -take().number : take().number;
        return v;
    }

    /// true, false or undef; any other identifier would start an expression.
    Value word(Value& v) {
        const Token& t = peek();
        if (t.text == "true" || t.text == "false") {
            v.kind = Value::Kind::Bool;
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
                      printable(t.text) + "': expressions are not part of OpenSCAD's CSG export");
    }

    /// `[` value, ... `]`.
    Value vector(Value& v, int depth) {
        size_t open = take().pos;
        v.kind = Value::Kind::Vector;
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
                src_.fail(peek().pos,
                          "unexpected end of file: missing ']' for the '[' at " + src_.where(open));
            expect("]", "to close the vector");
            return v;
        }
    }

    const SourceText& src_;
    const std::vector<Token>& toks_;
    size_t i_ = 0;
};

}  // namespace

std::vector<Node> parse(const SourceText& src, const std::vector<Token>& tokens) {
    return Parser(src, tokens).file();
}

}  // namespace lancer::openscad
