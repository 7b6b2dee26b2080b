// GLSL programs from the shaders embedded out of shaders/ (app/CMakeLists.txt embeds every file
// there): compiled and linked with errors that name the file and quote the driver's log.
#pragma once

#include <string>
#include <string_view>

namespace lancer::viewer::gl {

/// The text of shaders/NAME as embedded at configure time. Throws std::runtime_error naming
/// NAME when no such file was embedded.
const char* shaderSource(std::string_view name);

/// A linked vertex + fragment program. Needs a current OpenGL 3.3 core context from
/// construction to destruction.
class Program {
  public:
    /// Compile shaders/VERTEX and shaders/FRAGMENT and link them. Throws std::runtime_error
    /// with the file's name and the compiler's or linker's log.
    Program(std::string_view vertex, std::string_view fragment);
    /// The same from source text; the names only label errors.
    Program(const char* vertexSource, const char* fragmentSource, const std::string& label);
    ~Program();
    Program(const Program&) = delete;
    Program& operator=(const Program&) = delete;

    /// The GL program object.
    unsigned id() const { return id_; }
    /// A uniform's location (-1 when the program has none of that name, as GL says).
    int uniform(const char* name) const;

  private:
    unsigned id_ = 0;
};

}  // namespace lancer::viewer::gl
