#pragma once
// The root of an increasing scalar function h with slope >= 1 (the pad-point equations of
// fingers and pluckers): Newton's method from a guess, inside a bracket that starts within
// |h(guess)| of it and that bisection falls back on.
#include <algorithm>
#include <cmath>
#include <limits>

namespace fretbuzz::detail {

struct MonotoneValue {
    double h = 0.0;      // h(x)
    double scale = 0.0;  // size of the terms summed into h (for the round-off test)
    double slope = 1.0;  // h'(x) >= 1
};

// evaluate(x) -> MonotoneValue; the last call is at the root. Returns the iterations taken,
// or -1 when it did not converge within max_iterations.
template <class Evaluate>
int monotone_root(Evaluate&& evaluate, double guess, int max_iterations) {
    constexpr double eps = std::numeric_limits<double>::epsilon();
    MonotoneValue v = evaluate(guess);
    double x = guess, lo = guess, hi = guess;
    (v.h > 0.0 ? lo : hi) = guess - v.h;  // slope >= 1: the root lies within |h| of the guess
    for (int it = 0; it < max_iterations; ++it) {
        // Round-off in h: its terms', and the slope times the rounding of x (a steep h can
        // otherwise stay above the terms' round-off at every double next to the root).
        if (std::abs(v.h) <= 4.0 * eps * (v.scale + v.slope * std::abs(x)) ||
            hi - lo <= 2.0 * eps * std::max(std::abs(lo), std::abs(hi)))
            return it;
        double next = x - v.h / v.slope;
        const bool newton = next > lo && next < hi;
        if (!newton) next = 0.5 * (lo + hi);
        const double h_before = v.h;
        v = evaluate(next);
        (v.h > 0.0 ? hi : lo) = next;
        if (std::abs(next - x) <= eps * std::abs(next)) return it + 1;
        // A Newton step of a few ulps that does not even halve h: h is at the round-off of a
        // term the scale does not see (a contact law's difference quotient), and Newton would
        // creep on ulp by ulp without meeting the test above.
        if (newton && std::abs(v.h) > 0.5 * std::abs(h_before) && std::abs(next - x) <= 64.0 * eps * std::abs(next))
            return it + 1;
        x = next;
    }
    return -1;
}

}  // namespace fretbuzz::detail
