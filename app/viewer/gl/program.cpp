#include "app/viewer/gl/program.h"

#include <stdexcept>

#include "app/viewer/gl.h"
#include "lancer_shaders.h"  // generated from every file in shaders/ at configure time

namespace lancer::viewer::gl {

namespace {

GLuint compile(GLenum type, const char* source, const std::string& label) {
    GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        glDeleteShader(s);
        throw std::runtime_error("shader " + label + " does not compile: " + log);
    }
    return s;
}

}  // namespace

const char* shaderSource(std::string_view name) {
    for (const shaders::Embedded& e : shaders::kAll)
        if (name == e.name) return e.source;
    throw std::runtime_error("no shader shaders/" + std::string(name) +
                             " was embedded (re-run cmake after adding it)");
}

Program::Program(std::string_view vertex, std::string_view fragment)
    : Program(shaderSource(vertex), shaderSource(fragment),
              std::string(vertex) + " + " + std::string(fragment)) {}

Program::Program(const char* vertexSource, const char* fragmentSource, const std::string& label) {
    // Both stages are named in errors by the pair's label and the stage.
    GLuint vs = compile(GL_VERTEX_SHADER, vertexSource, label + " (vertex)");
    GLuint fs = 0;
    try {
        fs = compile(GL_FRAGMENT_SHADER, fragmentSource, label + " (fragment)");
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    id_ = glCreateProgram();
    glAttachShader(id_, vs);
    glAttachShader(id_, fs);
    glLinkProgram(id_);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(id_, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetProgramInfoLog(id_, sizeof log, nullptr, log);
        glDeleteProgram(id_);
        throw std::runtime_error("shaders " + label + " do not link: " + log);
    }
}

Program::~Program() { glDeleteProgram(id_); }

int Program::uniform(const char* name) const { return glGetUniformLocation(id_, name); }

}  // namespace lancer::viewer::gl
