// The native JSON scene format (docs/scenes.md) and the camera sidecar of .csg files.
// Every error names the file, line and column of the offending value.
#pragma once

#include <nlohmann/json.hpp>
#include <unordered_map>

#include "engine/scene/scene.h"
#include "engine/scene/source_text.h"

namespace lancer {

/// A parsed JSON document that remembers where each value starts (keyed by JSON pointer).
class LocatedJson {
  public:
    /// Parse; a syntax error throws SceneError with the file, line and column.
    explicit LocatedJson(const SourceText& src);
    const nlohmann::json& root() const { return root_; }
    const SourceText& source() const { return *src_; }
    /// Offset of the value at `pointer` (or of its closest located ancestor).
    size_t offset(const std::string& pointer) const;
    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const;

  private:
    const SourceText* src_;
    nlohmann::json root_;
    std::unordered_map<std::string, size_t> offsets_;
    friend struct LocatingSax;
};

/// A value and its JSON pointer, with typed getters that report errors at its location.
struct JsonAt {
    const LocatedJson& doc;
    const nlohmann::json& value;
    std::string pointer;

    JsonAt operator[](const std::string& key) const;
    JsonAt operator[](size_t index) const;
    bool has(const std::string& key) const { return value.is_object() && value.contains(key); }
    [[noreturn]] void fail(const std::string& message) const { doc.fail(pointer, message); }
    double number() const;    ///< finite number
    double positive() const;  ///< finite, > 0
    double nonNegative() const;
    int integer(int lo, int hi) const;
    bool boolean() const;
    std::string string() const;
    Vec3 vec3() const;  ///< [x, y, z], finite
    const nlohmann::json::array_t& array() const;
    const nlohmann::json::object_t& object() const;
    /// Reject keys not in `allowed` (catches typos such as "raduis").
    void onlyKeys(std::initializer_list<const char*> allowed) const;
};

/// Read a native scene (.json). Throws SceneError.
Scene readJsonScene(const SourceText& src);
/// Apply a camera description ({"from","at","up","fov","width","height","projection",
/// "ortho_height","lights","background"}; other keys ignored) to `scene`.
void applyCameraJson(const JsonAt& cam, Scene& scene, bool strictKeys);

}  // namespace lancer
