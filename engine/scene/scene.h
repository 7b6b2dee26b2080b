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

/// How a reader models OpenSCAD's round primitives.
enum class Facets : uint8_t {
    Exact,     ///< the true circle, sphere, cylinder and cone (the default)
    OpenScad,  ///< OpenSCAD's polygons and polyhedra of them, by $fn, $fa, $fs
};

/// Options of the scene readers (`--facets`).
struct ReadOptions {
    Facets facets = Facets::Exact;  ///< circles, spheres, cylinders and cones of .csg files
    /// The parts each of OpenSCAD's slices of a twisted extrusion is cut into (1 to 16; the
    /// bench's speed-against-error knob); 0: as many as the reader's error target asks.
    int twistParts = 0;
};

struct PackedSphere {
    Vec3 c{0.0};
    double r = -1.0;
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
    /// The largest distance (model units) by which the solids read stray from the surfaces the
    /// file describes: a twisted extrusion's slices (OpenScadCounts::twistError); 0: exact.
    double modelError = 0.0;
    /// How far OpenSCAD's own mesh of a .csg strays from the surfaces it describes beyond its
    /// circles' facets (OpenScadCounts::openScadTwistMeshError); 0 for other formats.
    double openScadMeshError = 0.0;

    // Filled by prepare():
    std::vector<Box3> minBox;  ///< CSG-minimized box per primitive (empty: dropped)
    int droppedPrims = 0;      ///< primitives removed by bound minimization
    int minimizeIterations = 0;
    Box3 bounds;  ///< hull of the minimized boxes of live primitives
    /// Per primitive, a sphere in world coordinates packed in 32 bytes (r < 0: another shape or
    /// a transformed one): the walks' inner loop tests it without the variant, the transform or
    /// a call, and reads 7,000 of them from a quarter of a megabyte, not from the primitives.
    std::vector<PackedSphere> packedSpheres;
    bool prepared = false;
    /// Set by prepare(), a different value at each preparation: copies share it, so a structure
    /// built over one copy may lend its camera-independent parts to a build over another with
    /// only its camera changed (BuildControl::previous). 0: not prepared.
    uint64_t preparedId = 0;

    /// Validate (surfaces under unions only), minimize boxes, drop primitives that cannot
    /// contribute (restricting the tree to the rest). Throws SceneError.
    void prepare();
    /// Spans of primitive `p` along `ray`: Primitive::spans, from the packed table for spheres.
    /// With Precision::Float, the shape's test in single precision (TraceContext::precision).
    int primSpans(uint32_t p, const Ray& ray, Span* out, Precision precision) const {
        if (precision == Precision::Float) [[unlikely]]
            return primSpansFloat(p, ray, out);
        if (p < packedSpheres.size() && packedSpheres[p].r >= 0.0)
            return sphereSpans(packedSpheres[p].c, packedSpheres[p].r, ray, p, out);
        return prims[p].spans(ray, p, out);
    }
    /// primSpans in single precision.
    int primSpansFloat(uint32_t p, const Ray& ray, Span* out) const;
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
