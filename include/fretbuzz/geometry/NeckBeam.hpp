#pragma once
// The neck as a beam under the strings' pull, for how its relief follows the load. The
// strings pull along the neck at a height e above its neutral axis: an eccentric axial load,
// whose bending moment M = P e is the same all along the neck. An Euler-Bernoulli beam of
// bending stiffness EI, pinned at the nut end and at the last fret (where relief is measured
// from), bends under a uniform moment into a parabola of depth
//     d = M l^2 / (8 EI)    at mid-span, over the span l.
// The truss rod is set against the pull the relief was measured under; strings that pull
// P + Delta P (another tuning, another set) bow the neck by Delta d = Delta P e l^2 / (8 EI)
// more. The string's own pull on the frets between and the rod's change of stiffness are
// left out.
//
// The default stiffness is a maple neck of rectangular section b x h = 50 x 21 mm:
// E = 12.6 GPa (sugar maple at 12 % moisture, USDA Forest Products Laboratory, Wood Handbook,
// FPL-GTR-190, table 5-3a), h the depth of a Fender "C" neck (0.82-0.87 in at frets 1 and
// 12, Fender's neck specifications), b between the nut's and the heel's width:
// EI = E b h^3 / 12 = 486 N m^2. The strings lie e = 13 mm above its neutral axis (half the
// depth, the fret and the action).
namespace fretbuzz {

struct NeckBeam {
    static constexpr double kMapleYoungModulus = 12.6e9;  // Pa
    static constexpr double kDefaultWidth = 0.050, kDefaultDepth = 0.021;  // m
    static constexpr double kDefaultPullHeight = 0.013;  // m

    double bending_stiffness_n_m2 = kMapleYoungModulus * kDefaultWidth * kDefaultDepth * kDefaultDepth * kDefaultDepth / 12.0;
    double pull_height_m = kDefaultPullHeight;

    // The bow's depth at mid-span (m) per newton of pull, over a span (m).
    double bow_per_newton(double span_m) const {
        return pull_height_m * span_m * span_m / (8.0 * bending_stiffness_n_m2);
    }
};

}  // namespace fretbuzz
