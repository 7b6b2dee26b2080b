#include "app/viewer/gl/batch.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <glm/gtc/type_ptr.hpp>
#include <map>
#include <tuple>

#include "app/viewer/gl.h"
#include "app/viewer/gl/program.h"

namespace lancer::viewer::gl {

Rgba8 rgba8(const glm::vec4& c) {
    auto byte = [](float v) { return Rgba8(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
    return byte(c.x) | byte(c.y) << 8 | byte(c.z) << 16 | byte(c.w) << 24;
}

namespace {

// The 12 edges of a hexahedron as corner pairs: corners differing in one bit.
constexpr int kEdges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                               {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
// The 6 faces as corner loops (axis a side s: the corners whose bit a is s).
constexpr int kFaces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                              {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};

std::array<glm::vec3, 8> cornersOf(const glm::vec3& lo, const glm::vec3& hi) {
    std::array<glm::vec3, 8> c;
    for (int i = 0; i < 8; ++i)
        c[size_t(i)] = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z};
    return c;
}

}  // namespace

void Batch::line(const glm::vec3& a, const glm::vec3& b, Rgba8 color) {
    lines.push_back({a, color});
    lines.push_back({b, color});
}

void Batch::box(const std::array<glm::vec3, 8>& c, Rgba8 color) {
    for (const auto& e : kEdges) line(c[size_t(e[0])], c[size_t(e[1])], color);
}

void Batch::box(const glm::vec3& lo, const glm::vec3& hi, Rgba8 color) {
    box(cornersOf(lo, hi), color);
}

void Batch::outline(std::span<const glm::vec3> p, Rgba8 color) {
    for (size_t i = 0; i < p.size() && p.size() > 1; ++i) line(p[i], p[(i + 1) % p.size()], color);
}

void Batch::outline(std::span<const glm::vec2> p, Rgba8 color) {
    for (size_t i = 0; i < p.size() && p.size() > 1; ++i) line(p[i], p[(i + 1) % p.size()], color);
}

void Batch::fill(std::span<const glm::vec3> p, Rgba8 color) {
    for (size_t i = 1; i + 1 < p.size(); ++i) {
        triangles.push_back({p[0], color});
        triangles.push_back({p[i], color});
        triangles.push_back({p[i + 1], color});
    }
}

void Batch::fill(std::span<const glm::vec2> p, Rgba8 color) {
    for (size_t i = 1; i + 1 < p.size(); ++i) {
        triangles.push_back({glm::vec3(p[0], 0.0f), color});
        triangles.push_back({glm::vec3(p[i], 0.0f), color});
        triangles.push_back({glm::vec3(p[i + 1], 0.0f), color});
    }
}

void Batch::fillBox(const std::array<glm::vec3, 8>& c, Rgba8 color) {
    for (const auto& f : kFaces) {
        const glm::vec3 quad[4] = {c[size_t(f[0])], c[size_t(f[1])], c[size_t(f[2])],
                                   c[size_t(f[3])]};
        fill(quad, color);
    }
}

void Batch::fillRect(const glm::vec2& lo, const glm::vec2& hi, Rgba8 color) {
    const glm::vec2 quad[4] = {lo, {hi.x, lo.y}, hi, {lo.x, hi.y}};
    fill(quad, color);
}

void Batch::append(const Batch& o) {
    lines.insert(lines.end(), o.lines.begin(), o.lines.end());
    triangles.insert(triangles.end(), o.triangles.begin(), o.triangles.end());
}

void Batch::clear() {
    lines.clear();
    triangles.clear();
}

namespace {

/// A segment along a coordinate axis: the axis, the two other coordinates (in axis order) and
/// its interval on the axis.
struct AxisSegment {
    int axis;
    float u, v;
    float lo, hi;
};

/// Segment (a, b) as an AxisSegment: false unless exactly one coordinate differs and every
/// coordinate is finite (NaN differs: such a segment is no axis segment).
bool alongAxis(const BatchVertex& a, const BatchVertex& b, AxisSegment& out) {
    int axis = -1, differing = 0;
    for (int c = 0; c < 3; ++c) {
        if (!std::isfinite(a.position[c]) || !std::isfinite(b.position[c])) return false;
        if (a.position[c] != b.position[c]) axis = c, ++differing;
    }
    if (differing != 1) return false;
    const int c1 = (axis + 1) % 3, c2 = (axis + 2) % 3;
    out = {axis, a.position[std::min(c1, c2)], a.position[std::max(c1, c2)],
           std::min(a.position[axis], b.position[axis]),
           std::max(a.position[axis], b.position[axis])};
    return true;
}

}  // namespace

Batch mergeCollinearLines(const Batch& in) {
    // One record per segment along an axis: its line (axis, the two other coordinates, the
    // colour) and its interval on it; sorted by line then start, runs that overlap or touch are
    // joined by one sweep.
    struct Piece {
        int axis;
        float u, v;  // the other two coordinates, in axis order
        Rgba8 color;
        float lo, hi;
        size_t at;  // the index of the segment, then of the last one a run replaces
    };
    std::vector<Piece> pieces;
    std::vector<size_t> kept;  // segments left as they are
    const size_t n = in.lineCount();
    pieces.reserve(n);
    for (size_t k = 0; k < n; ++k) {
        const BatchVertex& a = in.lines[2 * k];
        const BatchVertex& b = in.lines[2 * k + 1];
        AxisSegment g;
        if (!alongAxis(a, b, g) || a.color != b.color) {  // such a segment is kept
            kept.push_back(k);
            continue;
        }
        pieces.push_back({g.axis, g.u, g.v, a.color, g.lo, g.hi, k});
    }
    auto lineKey = [](const Piece& p) { return std::tuple(p.axis, p.u, p.v, p.color); };
    std::sort(pieces.begin(), pieces.end(), [&](const Piece& a, const Piece& b) {
        return std::tuple(lineKey(a), a.lo) < std::tuple(lineKey(b), b.lo);
    });
    std::vector<Piece> runs;
    for (const Piece& p : pieces) {
        Piece* last = runs.empty() ? nullptr : &runs.back();
        if (last && lineKey(*last) == lineKey(p) && p.lo <= last->hi) {
            last->hi = std::max(last->hi, p.hi);
            last->at = std::max(last->at, p.at);
        } else {
            runs.push_back(p);
        }
    }
    // In the order of the last segment each run replaces, with the kept ones.
    struct Out {
        size_t at;
        const Piece* run;  // null: segment `at` as it was
    };
    std::vector<Out> order;
    order.reserve(runs.size() + kept.size());
    for (const Piece& r : runs) order.push_back({r.at, &r});
    for (size_t k : kept) order.push_back({k, nullptr});
    std::sort(order.begin(), order.end(), [](const Out& a, const Out& b) { return a.at < b.at; });
    Batch out;
    out.triangles = in.triangles;
    out.lines.reserve(2 * order.size());
    for (const Out& o : order) {
        if (!o.run) {
            out.lines.push_back(in.lines[2 * o.at]);
            out.lines.push_back(in.lines[2 * o.at + 1]);
            continue;
        }
        const Piece& r = *o.run;
        const int c1 = (r.axis + 1) % 3, c2 = (r.axis + 2) % 3;
        glm::vec3 a, b;
        a[std::min(c1, c2)] = b[std::min(c1, c2)] = r.u;
        a[std::max(c1, c2)] = b[std::max(c1, c2)] = r.v;
        a[r.axis] = r.lo;
        b[r.axis] = r.hi;
        out.line(a, b, r.color);
    }
    return out;
}

Batch subtractCovered(const Batch& in, const Batch& cover) {
    // The cover's segments along each axis line (axis, the two other coordinates), as sorted,
    // joined intervals; each of `in`'s segments keeps the gaps between them.
    using Line = std::tuple<int, float, float>;
    std::map<Line, std::vector<std::pair<float, float>>> covered;
    for (size_t k = 0; k < cover.lineCount(); ++k)
        if (AxisSegment g; alongAxis(cover.lines[2 * k], cover.lines[2 * k + 1], g))
            covered[{g.axis, g.u, g.v}].push_back({g.lo, g.hi});
    for (auto& [line, ivs] : covered) {
        std::sort(ivs.begin(), ivs.end());
        std::vector<std::pair<float, float>> joined;
        for (const auto& iv : ivs)
            if (!joined.empty() && iv.first <= joined.back().second)
                joined.back().second = std::max(joined.back().second, iv.second);
            else
                joined.push_back(iv);
        ivs = std::move(joined);
    }
    Batch out;
    out.triangles = in.triangles;
    for (size_t k = 0; k < in.lineCount(); ++k) {
        const BatchVertex &a = in.lines[2 * k], &b = in.lines[2 * k + 1];
        AxisSegment g;
        const auto it = alongAxis(a, b, g) ? covered.find(Line{g.axis, g.u, g.v}) : covered.end();
        if (it == covered.end()) {
            out.lines.push_back(a);
            out.lines.push_back(b);
            continue;
        }
        const int axis = g.axis;
        const float lo = g.lo, hi = g.hi;
        auto piece = [&](float p, float q) {
            if (!(p < q)) return;
            const bool forward = a.position[axis] <= b.position[axis];
            BatchVertex u = forward ? a : b, v = forward ? b : a;  // u at the low end
            u.position[axis] = p;
            v.position[axis] = q;
            out.lines.push_back(u);
            out.lines.push_back(v);
        };
        // The gaps of [lo, hi] between the covering intervals.
        float from = lo;
        for (const auto& [c0, c1] : it->second) {
            if (c1 <= from) continue;
            if (c0 >= hi) break;
            piece(from, std::min(c0, hi));
            from = std::max(from, c1);
            if (from >= hi) break;
        }
        piece(from, hi);
    }
    return out;
}

GpuBatch::GpuBatch() = default;

GpuBatch::~GpuBatch() {
    for (auto& kind : chunks_)
        for (Chunk& c : kind) {
            glDeleteBuffers(1, &c.vbo);
            glDeleteVertexArrays(1, &c.vao);
        }
}

GpuBatch::Chunk& GpuBatch::chunk(int kind, size_t k, size_t vertices) {
    std::vector<Chunk>& list = chunks_[kind];
    while (list.size() <= k) {
        Chunk c;
        glGenVertexArrays(1, &c.vao);
        glGenBuffers(1, &c.vbo);
        glBindVertexArray(c.vao);
        glBindBuffer(GL_ARRAY_BUFFER, c.vbo);
        glEnableVertexAttribArray(0);
        glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(BatchVertex),
                              reinterpret_cast<void*>(offsetof(BatchVertex, position)));
        glEnableVertexAttribArray(1);
        glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(BatchVertex),
                              reinterpret_cast<void*>(offsetof(BatchVertex, color)));
        glBindVertexArray(0);
        list.push_back(c);
    }
    Chunk& c = list[k];
    if (vertices > c.capacity || vertices < c.capacity / 4) {  // grow, or give memory back
        glBindBuffer(GL_ARRAY_BUFFER, c.vbo);
        glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices * sizeof(BatchVertex)), nullptr,
                     GL_DYNAMIC_DRAW);
        c.capacity = vertices;
    }
    return c;
}

void GpuBatch::upload(const Batch& batch) {
    beginUpload(batch);
    uploadMore(SIZE_MAX);
}

void GpuBatch::beginUpload(const Batch& batch) {
    const size_t sizes[2] = {batch.lines.size(), batch.triangles.size()};
    for (int i = 0; i < 2; ++i) {
        // Chunks beyond the batch's give their memory back.
        const size_t keep = (sizes[i] + kChunkVertices - 1) / kChunkVertices;
        while (chunks_[i].size() > keep) {
            glDeleteBuffers(1, &chunks_[i].back().vbo);
            glDeleteVertexArrays(1, &chunks_[i].back().vao);
            chunks_[i].pop_back();
        }
    }
    lineVertices_ = triangleVertices_ = 0;
    pending_ = &batch;
}

bool GpuBatch::uploadMore(size_t bytes) {
    if (!pending_) return true;
    const std::vector<BatchVertex>* parts[2] = {&pending_->lines, &pending_->triangles};
    size_t* done[2] = {&lineVertices_, &triangleVertices_};
    for (int i = 0; i < 2 && bytes > 0; ++i) {
        const size_t per = i == 0 ? 2 : 3;
        while (*done[i] < parts[i]->size() && bytes > 0) {
            const size_t k = *done[i] / kChunkVertices, at = *done[i] % kChunkVertices;
            const size_t chunkEnd = std::min(parts[i]->size(), (k + 1) * kChunkVertices);
            const size_t want = std::max(bytes / sizeof(BatchVertex) / per, size_t(1)) * per;
            const size_t n = std::min(chunkEnd - *done[i], want);
            Chunk& c = chunk(i, k, chunkEnd - k * kChunkVertices);
            glBindBuffer(GL_ARRAY_BUFFER, c.vbo);
            glBufferSubData(GL_ARRAY_BUFFER, GLintptr(at * sizeof(BatchVertex)),
                            GLsizeiptr(n * sizeof(BatchVertex)), parts[i]->data() + *done[i]);
            *done[i] += n;
            bytes -= std::min(bytes, n * sizeof(BatchVertex));
        }
    }
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    if (lineVertices_ == parts[0]->size() && triangleVertices_ == parts[1]->size())
        pending_ = nullptr;
    return pending_ == nullptr;
}

BatchRenderer::BatchRenderer()
    : program_(std::make_unique<Program>("batch.vert", "batch.frag")),
      scratch_(std::make_unique<GpuBatch>()) {
    locToClip_ = program_->uniform("toClip");
    locOpacity_ = program_->uniform("opacity");
}

BatchRenderer::~BatchRenderer() = default;

void BatchRenderer::draw(const GpuBatch& b, const glm::mat4& toClip, const DrawOptions& o) {
    auto range = [](size_t count, size_t first, size_t limit) {
        first = std::min(first, count);
        return std::pair<size_t, size_t>(first, std::min(limit, count - first));
    };
    const auto [t0, tn] = range(b.triangleCount(), o.firstTriangle, o.triangleLimit);
    const auto [l0, ln] = range(b.lineCount(), o.firstLine, o.lineLimit);
    if ((!o.triangles || tn == 0) && (!o.lines || ln == 0)) return;
    glUseProgram(program_->id());
    glUniformMatrix4fv(locToClip_, 1, GL_FALSE, glm::value_ptr(toClip));
    glUniform1f(locOpacity_, o.opacity);
    glEnable(GL_BLEND);
    glBlendEquation(GL_FUNC_ADD);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glDisable(GL_CULL_FACE);
    glDisable(GL_SCISSOR_TEST);
    if (o.depthTest) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LEQUAL);
    } else {
        glDisable(GL_DEPTH_TEST);
    }
    // Vertices [first, first + count) of a kind, chunk by chunk (no primitive spans two).
    auto drawRange = [&](int kind, GLenum mode, size_t first, size_t count) {
        const size_t end = first + count;
        for (size_t v = first; v < end;) {
            const size_t k = v / GpuBatch::kChunkVertices;
            const size_t chunkEnd = std::min(end, (k + 1) * GpuBatch::kChunkVertices);
            glBindVertexArray(b.chunks_[kind][k].vao);
            glDrawArrays(mode, GLint(v - k * GpuBatch::kChunkVertices), GLsizei(chunkEnd - v));
            v = chunkEnd;
        }
    };
    if (o.triangles && tn > 0) drawRange(1, GL_TRIANGLES, 3 * t0, 3 * tn);
    if (o.lines && ln > 0) drawRange(0, GL_LINES, 2 * l0, 2 * ln);
    glBindVertexArray(0);
    glUseProgram(0);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_BLEND);
}

void BatchRenderer::drawNow(const Batch& batch, const glm::mat4& toClip,
                            const DrawOptions& options) {
    if (batch.empty()) return;
    scratch_->upload(batch);
    draw(*scratch_, toClip, options);
}

}  // namespace lancer::viewer::gl
