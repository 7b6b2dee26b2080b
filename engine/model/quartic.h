// Real roots of small polynomials on an interval, by isolation through the derivative's roots
// (the approach of Yuksel, "High-Performance Polynomial Root Finding for Graphics", HPG 2022):
// the roots of p' split [lo, hi] into pieces where p is monotone, so each piece holds at most
// one root, found by Newton's method kept inside the piece's bracket (bisection where a step
// would leave it). Unlike Ferrari's closed form, nothing cancels catastrophically near a double
// root: a grazing ray's two roots merge at a critical point, where the sign of p alone decides
// between two close roots and none. The torus (shapes.cpp) solves its quartic with it.
#pragma once

#include <cmath>
#include <limits>

namespace lancer::poly {

/// p(x) for the coefficients c[0..n] (c[i] multiplies x^i), by Horner's rule.
template <class T>
T eval(const T* c, int n, T x) {
    T v = c[n];
    for (int i = n - 1; i >= 0; --i) v = v * x + c[i];
    return v;
}

/// The root of c (degree n) in the bracket [a, b], where fa = p(a) and p(b) differ in sign
/// (negative against non-negative) and p is monotone; d holds p' (degree n - 1).
template <class T>
T bracketedRoot(const T* c, const T* d, int n, T a, T b, T fa) {
    const bool negA = fa < T(0);
    T x = T(0.5) * (a + b);
    // Newton converges in a few steps on a simple root; the bisection fallback bounds the work
    // near a double root by the number of bits (at most about 2100 halvings of a double range,
    // far fewer in practice since the bracket starts within [-1, 1] for the torus).
    for (int it = 0; it < 200; ++it) {
        const T fx = eval(c, n, x);
        if (fx == T(0)) return x;
        if ((fx < T(0)) == negA)
            a = x;
        else
            b = x;
        const T dfx = eval(d, n - 1, x);
        T next = x - fx / dfx;
        if (!(next > a && next < b)) next = T(0.5) * (a + b);  // also catches dfx = 0 (NaN/inf)
        if (next == x || next == a || next == b) return next;
        x = next;
    }
    return x;
}

/// The roots of c (degree n <= 4, c[n] != 0) in [lo, hi] where p changes sign, increasing, into
/// out (capacity n); returns their count. A root of even multiplicity (p touches zero without
/// crossing) is not a sign change and is left out; p = 0 counts as non-negative, so a touching
/// zero from below gives two equal roots. Exact for p(lo), p(hi) of either sign.
template <class T>
int signChangeRoots(const T* c, int n, T lo, T hi, T* out) {
    if (!(lo < hi)) return 0;
    if (n == 1) {
        if (c[1] == T(0)) return 0;
        const T x = -c[0] / c[1];
        if (!(x >= lo && x <= hi)) return 0;
        // Only where the sign changes between lo and hi, as for higher degrees.
        if ((eval(c, 1, lo) < T(0)) == (eval(c, 1, hi) < T(0))) return 0;
        out[0] = x;
        return 1;
    }
    T d[4];
    for (int i = 1; i <= n; ++i) d[i - 1] = T(i) * c[i];
    T crit[4];
    const int m = signChangeRoots(d, n - 1, lo, hi, crit);
    int k = 0;
    T a = lo, fa = eval(c, n, lo);
    for (int j = 0; j <= m; ++j) {
        const T b = j < m ? crit[j] : hi;
        const T fb = eval(c, n, b);
        if ((fa < T(0)) != (fb < T(0))) {
            // p(a) or p(b) may be exactly zero: the root is that end.
            if (fa == T(0))
                out[k++] = a;
            else if (fb == T(0))
                out[k++] = b;
            else
                out[k++] = bracketedRoot(c, d, n, a, b, fa);
        }
        a = b, fa = fb;
    }
    return k;
}

}  // namespace lancer::poly
