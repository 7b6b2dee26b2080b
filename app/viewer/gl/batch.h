// Lines and translucent filled polygons, batched: built on the CPU (any thread, no GL), uploaded
// once, drawn each frame with one matrix. World-space geometry is drawn with a camera's
// world-to-clip matrix, image-space geometry (continuous image pixels, y down) with
// imagePixelsToClip (gl/transforms.h). Overlays, the inspector and ray playback all draw this way.
#pragma once

#include <array>
#include <cstdint>
#include <glm/glm.hpp>
#include <memory>
#include <span>
#include <vector>

namespace lancer::viewer::gl {

class Program;

/// An 8-bit RGBA colour packed as GL reads it (r in the lowest byte).
using Rgba8 = uint32_t;
/// Pack a colour with components in [0, 1] (clamped).
Rgba8 rgba8(const glm::vec4& c);
inline Rgba8 rgba8(const glm::vec3& c, float alpha = 1.0f) { return rgba8(glm::vec4(c, alpha)); }

/// One vertex of a batch: 16 bytes, so a million boxes' edges (24 vertices each) fit in 384 MB
/// at most; the overlays cap what they draw well below that.
struct BatchVertex {
    glm::vec3 position;
    Rgba8 color;
};

/// Geometry waiting to be drawn: line segments and triangles, each vertex coloured.
class Batch {
  public:
    /// A segment from a to b.
    void line(const glm::vec3& a, const glm::vec3& b, Rgba8 color);
    /// A segment in a plane (image pixels): z = 0.
    void line(const glm::vec2& a, const glm::vec2& b, Rgba8 color) {
        line(glm::vec3(a, 0.0f), glm::vec3(b, 0.0f), color);
    }
    /// The 12 edges of a hexahedron given by its 8 corners in the trace contract's order
    /// (corner c = i + 2j + 4k, i, j, k the low or high side along its three axes).
    void box(const std::array<glm::vec3, 8>& corners, Rgba8 color);
    /// The 12 edges of an axis-aligned box.
    void box(const glm::vec3& lo, const glm::vec3& hi, Rgba8 color);
    /// The closed outline of a polygon.
    void outline(std::span<const glm::vec3> points, Rgba8 color);
    void outline(std::span<const glm::vec2> points, Rgba8 color);
    /// A convex polygon, filled (a fan of triangles; its colour's alpha makes it translucent).
    void fill(std::span<const glm::vec3> points, Rgba8 color);
    void fill(std::span<const glm::vec2> points, Rgba8 color);
    /// The 6 faces of a hexahedron given as for box(), filled.
    void fillBox(const std::array<glm::vec3, 8>& corners, Rgba8 color);
    /// An axis-aligned rectangle in a plane (image pixels), filled.
    void fillRect(const glm::vec2& lo, const glm::vec2& hi, Rgba8 color);

    /// Everything in `other` after what this batch holds.
    void append(const Batch& other);
    void clear();
    bool empty() const { return lines.empty() && triangles.empty(); }
    /// Segments held (two line vertices each).
    size_t lineCount() const { return lines.size() / 2; }
    size_t triangleCount() const { return triangles.size() / 3; }

    std::vector<BatchVertex> lines;      ///< pairs of vertices, one segment each
    std::vector<BatchVertex> triangles;  ///< triples of vertices, one triangle each
};

/// The same segments drawn with fewer lines: segments along a coordinate axis (both ends equal
/// in the other two coordinates, both ends of one colour) that lie on one line and have one
/// colour are replaced by the union of their intervals, overlapping or touching intervals made
/// one segment; every other segment is kept as it is. The boxes of a subdivision share faces,
/// so most of their edges lie on their neighbours': fewer and shorter lines to rasterize, over
/// the same pixels. The triangles are kept; a segment takes the place of the last one it
/// replaces, so where lines of two colours overlap, which one lands on top may change.
Batch mergeCollinearLines(const Batch& batch);
/// The lines of `lines` without the parts that a segment of `cover` lies on (of any colour):
/// where two layers draw the same edge, the one whose colour says more is drawn alone. Only
/// segments along a world axis are cut (as mergeCollinearLines joins them); the others, and
/// the triangles, are kept as they are. Order is kept, a cut segment's pieces in its place.
Batch subtractCovered(const Batch& lines, const Batch& cover);

/// How a batch is drawn.
struct DrawOptions {
    float opacity = 1.0f;    ///< multiplies every vertex's alpha
    bool depthTest = false;  ///< test and write depth (a 3D view with a depth buffer)
    bool lines = true;       ///< draw the segments
    bool triangles = true;   ///< draw the triangles
    /// Draw only the segments [firstLine, firstLine + lineLimit) (a replay, a level range stored
    /// in order); SIZE_MAX: to the last.
    size_t firstLine = 0, lineLimit = SIZE_MAX;
    size_t firstTriangle = 0, triangleLimit = SIZE_MAX;
};

/// A batch uploaded to GL buffers, to be drawn every frame without copying it again.
class GpuBatch {
  public:
    GpuBatch();  ///< needs a current OpenGL 3.3 core context (as do all members)
    ~GpuBatch();
    GpuBatch(const GpuBatch&) = delete;
    GpuBatch& operator=(const GpuBatch&) = delete;

    /// Replace the buffers' contents with `batch`.
    void upload(const Batch& batch);
    /// Begin replacing them with `batch` in parts (uploadMore()): `batch` must stay alive and
    /// unchanged until uploaded(). Meanwhile only what was copied is drawn (lineCount(),
    /// triangleCount(): the first lines and triangles, in order).
    void beginUpload(const Batch& batch);
    /// Copy about `bytes` more (whole lines or triangles, at least one) of the batch begun;
    /// true once all of it is.
    bool uploadMore(size_t bytes);
    /// Nothing is left to copy.
    bool uploaded() const { return pending_ == nullptr; }
    /// Segments and triangles drawn (copied so far).
    size_t lineCount() const { return lineVertices_ / 2; }
    size_t triangleCount() const { return triangleVertices_ / 3; }

    /// Vertices a GL buffer holds at most (2 MB; whole lines and triangles): a batch lives in
    /// several, each allocated when the copy reaches it, because llvmpipe zeroes a buffer when
    /// it allocates it (balls4's slab batches, 77 MB in one buffer each, took 52 ms).
    static constexpr size_t kChunkVertices = 6 * 21845;

  private:
    friend class BatchRenderer;
    /// One GL buffer of a batch's vertices [k * kChunkVertices, (k + 1) * kChunkVertices).
    struct Chunk {
        unsigned vao = 0, vbo = 0;
        size_t capacity = 0;  ///< vertices allocated
    };
    /// Make chunk `k` of kind `kind` (0 the segments, 1 the triangles) hold `vertices`.
    Chunk& chunk(int kind, size_t k, size_t vertices);
    std::vector<Chunk> chunks_[2];  ///< [0] the segments, [1] the triangles
    size_t lineVertices_ = 0, triangleVertices_ = 0;
    const Batch* pending_ = nullptr;  ///< the batch being copied (beginUpload())
};

/// Draws batches: owns the program (shaders/batch.vert, batch.frag) and a scratch buffer for
/// batches drawn once. Blending is on (translucent fills); triangles are drawn before segments,
/// so lines stay visible over fills.
class BatchRenderer {
  public:
    /// Needs a current OpenGL 3.3 core context. Throws std::runtime_error if a shader fails.
    BatchRenderer();
    ~BatchRenderer();
    BatchRenderer(const BatchRenderer&) = delete;
    BatchRenderer& operator=(const BatchRenderer&) = delete;

    /// Draw an uploaded batch into the current framebuffer and viewport; `toClip` takes its
    /// positions to clip space.
    void draw(const GpuBatch& batch, const glm::mat4& toClip, const DrawOptions& options = {});
    /// Upload `batch` to the scratch buffer and draw it (small batches that change every frame:
    /// a hover highlight, a ray being played).
    void drawNow(const Batch& batch, const glm::mat4& toClip, const DrawOptions& options = {});

  private:
    std::unique_ptr<Program> program_;
    int locToClip_ = -1, locOpacity_ = -1;
    std::unique_ptr<GpuBatch> scratch_;
};

}  // namespace lancer::viewer::gl
