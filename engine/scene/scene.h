// A scene: primitives, their CSG tree, materials, lights and a camera; and its prepared form
// (minimized boxes, dropped primitives) that every acceleration scheme is built from.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "engine/model/csg.h"
#include "engine/scene/camera.h"

namespace lancer {

/// Whitted material. `reflect` and `transmit` weight the secondary rays.
struct Material {
    Vec3 color{0.8};
    double ambient = 0.1;
    double diffuse = 0.8;
    double specular = 0.0;
    double shininess = 20.0;
    double reflect = 0.0;
    double transmit = 0.0;
    double ior = 1.0;
    std::string name;
};

struct Light {
    Vec3 position{0.0};
    Vec3 color{1.0};
};

/// An input error with its location: "file:line:col: message".
struct SceneError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

struct Scene {
    std::string name;
    std::vector<Primitive> prims;
    CsgTree tree;
    std::vector<Material> materials{Material{}};
    std::vector<Light> lights;
    Camera camera;
    Vec3 background{0.0};
    int width = 512, height = 512;  ///< default image size

    // Filled by prepare():
    std::vector<Box3> minBox;       ///< CSG-minimized box per primitive (empty: dropped)
    int droppedPrims = 0;           ///< primitives removed by bound minimization
    int minimizeIterations = 0;
    Box3 bounds;                    ///< hull of the minimized boxes of live primitives
    bool prepared = false;

    /// Validate (surfaces under unions only), minimize boxes, drop primitives that cannot
    /// contribute (restricting the tree to the rest). Throws SceneError.
    void prepare();
    /// Primitives present in the prepared tree.
    std::vector<uint32_t> livePrimitives() const { return tree.primitives(); }
    /// A camera framed on the bounds, looking along `dir` (from the camera toward the scene).
    void frameCamera(const Vec3& dir, const Vec3& up);
    /// Three white-ish lights placed around the bounds.
    void defaultLights();
    /// Scale used for the secondary-ray offset: largest |coordinate| of the bounds, at least 1.
    double scale() const;
};

}  // namespace lancer
