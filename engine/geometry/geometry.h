// Rays, axis-aligned boxes and affine transforms, in double precision.
#pragma once

#include <algorithm>
#include <cmath>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>
#include <string>
#include <vector>

namespace lancer {

using Vec3 = glm::dvec3;
using Mat4 = glm::dmat4;
using Mat3 = glm::dmat3;

inline constexpr double kInf = std::numeric_limits<double>::infinity();

/// Coordinate `a` (0, 1 or 2) of `v`. glm's operator[] is a switch on the index, a branch or two
/// per access where the axis is known only at run time (the builders' loops over primitives).
inline double coord(const Vec3& v, int a) { return glm::value_ptr(v)[a]; }

std::string toString(const Vec3& v);

/// A ray o + t d. `d` need not be unit length; spans are measured in t.
struct Ray {
    Vec3 o{0.0};
    Vec3 d{0.0, 0.0, 1.0};

    Vec3 at(double t) const { return o + t * d; }
    std::string toString() const;
};

/// A closed axis-aligned box. Empty when lo > hi on some axis; a flat box (lo == hi) is not empty.
struct Box3 {
    Vec3 lo{kInf};
    Vec3 hi{-kInf};

    static Box3 empty() { return {}; }
    static Box3 everything() { return {Vec3(-kInf), Vec3(kInf)}; }

    bool isEmpty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
    bool isBounded() const;
    Vec3 extent() const { return hi - lo; }
    Vec3 center() const { return 0.5 * (lo + hi); }
    bool contains(const Vec3& p) const {
        return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z &&
               p.z <= hi.z;
    }
    /// Closed overlap: boxes that only touch do overlap.
    bool overlaps(const Box3& b) const {
        return lo.x <= b.hi.x && b.lo.x <= hi.x && lo.y <= b.hi.y && b.lo.y <= hi.y &&
               lo.z <= b.hi.z && b.lo.z <= hi.z;
    }
    void expand(const Vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void expand(const Box3& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }
    bool operator==(const Box3& b) const = default;
    std::string toString() const;
};

inline Box3 hull(const Box3& a, const Box3& b) {
    if (a.isEmpty()) return b;
    if (b.isEmpty()) return a;
    return {glm::min(a.lo, b.lo), glm::max(a.hi, b.hi)};
}

/// Intersection of two boxes; stays empty if either is empty.
inline Box3 overlap(const Box3& a, const Box3& b) {
    Box3 r{glm::max(a.lo, b.lo), glm::min(a.hi, b.hi)};
    return r.isEmpty() ? Box3::empty() : r;
}

/// Parametric interval [t0, t1] of the ray inside a closed box (over the whole line).
/// Returns false when the line misses. Axis-parallel rays are handled without 0 * inf.
bool clipLine(const Ray& r, const Box3& b, double& t0, double& t1);

/// The convex hull of `pts` in the plane, counterclockwise from the least (x, y), without
/// repeated or collinear points (Andrew's monotone chain); fewer than 3 points when they are
/// all on one line.
std::vector<glm::dvec2> convexHull2(std::vector<glm::dvec2> pts);

/// Whether the counterclockwise convex polygon `poly` (n >= 3 points, as convexHull2 makes it)
/// meets the closed rectangle [lo, hi]: no separating axis among the rectangle's and the edges'
/// outward normals. Only the edges' are tested; the caller has checked the bounds.
inline bool convexMeetsRect(const glm::dvec2* poly, size_t n, glm::dvec2 lo, glm::dvec2 hi) {
    for (size_t i = 0; i < n; ++i) {
        const glm::dvec2 a = poly[i], b = poly[i + 1 == n ? 0 : i + 1];
        const glm::dvec2 out{b.y - a.y, a.x - b.x};  // outward for a counterclockwise polygon
        // The rectangle's corner farthest inside along the normal.
        const glm::dvec2 c{out.x > 0.0 ? lo.x : hi.x, out.y > 0.0 ? lo.y : hi.y};
        if (glm::dot(out, c - a) > 0.0) return false;
    }
    return true;
}

/// An affine transform with its inverse and the normal matrix (inverse transpose).
struct Transform {
    Mat4 m{1.0};
    Mat4 inv{1.0};
    Mat3 normal{1.0};

    Transform() = default;
    explicit Transform(const Mat4& matrix);

    static Transform translate(const Vec3& t);
    static Transform scale(const Vec3& s);
    /// Rotation by `degrees` about `axis`.
    static Transform rotate(double degrees, const Vec3& axis);
    /// Rigid frame with origin `origin` whose local +z is the unit vector `w`.
    static Transform alongAxis(const Vec3& origin, const Vec3& w);

    /// this ∘ other: apply `other` first.
    Transform operator*(const Transform& o) const { return Transform(m * o.m); }

    Vec3 point(const Vec3& p) const { return Vec3(m * glm::dvec4(p, 1.0)); }
    Vec3 vector(const Vec3& v) const { return Mat3(m) * v; }
    Vec3 normalOf(const Vec3& n) const { return glm::normalize(normal * n); }
    Ray toLocal(const Ray& r) const { return {Vec3(inv * glm::dvec4(r.o, 1.0)), Mat3(inv) * r.d}; }
    /// World box of a local box (hull of its eight transformed corners).
    Box3 box(const Box3& local) const;
    bool isIdentity() const { return m == Mat4(1.0); }
    /// True when the linear part is invertible with a finite inverse.
    bool isInvertible() const;
};

/// An orthonormal frame whose third axis is `w` (unit).
void orthonormalBasis(const Vec3& w, Vec3& u, Vec3& v);

}  // namespace lancer
