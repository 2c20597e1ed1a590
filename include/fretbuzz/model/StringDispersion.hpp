#pragma once
// The frequency and damping of a string's transverse waves as functions of their wavenumber
// k, read off the mode table of the string pinned at both ends: its mode j has k_j = j pi / L,
// so the table samples nu(k) and sigma(k). A piece of the same string (same T, mu, E I) pinned
// over a length L' has its modes at k = n pi / L'. For the stiff string,
//   nu(k) = (k c / 2 pi) sqrt(1 + E I k^2 / T),
// so the shorter piece gets nu_n = n c / (2 L') sqrt(1 + B' n^2) with B' = B (L / L')^2
// (Fletcher's B = pi^2 E I / (T L^2)) without E I being known: every frequency scaled by
// L / L' would keep B and come out flat.
//
// Between samples, (nu / k)^2 and sigma are linear in k^2 (exact for the stiff string and for
// the damping law sigma = eta0 + eta2 k^2); beyond the last sample, the least-squares straight
// line (in k^2) through the top eighth of the table, its slope at least 0 (a string's waves do
// not slow down, nor lose less, as they get shorter).
#include <cstddef>
#include <vector>

#include "fretbuzz/model/ModeTable.hpp"

namespace fretbuzz {

class StringDispersion {
public:
    // modes: the table of the string pinned over length_m (mode j at index j - 1).
    // Throws InputError if the table is empty or the length not positive.
    StringDispersion(const ModeTable& modes, double length_m);

    // nu in Hz and sigma in 1/s at the wavenumber k >= pi / L (rad/m).
    double frequency_hz(double wavenumber) const;
    double sigma_per_s(double wavenumber) const;
    // The first `count` modes of the same string pinned over length_m (n pi / length_m);
    // each mode's source is that of the table's mode nearest to it in wavenumber.
    ModeTable pinned_modes(double length_m, std::size_t count) const;

private:
    struct Line {
        double at_zero = 0.0;  // value at k^2 = 0
        double slope = 0.0;    // per unit k^2
    };
    // Linear in k^2 through the samples, then the fitted line beyond the last.
    double interpolate(const std::vector<double>& values, const Line& beyond, double wavenumber) const;

    double length_m_;
    std::vector<double> wavenumber_;          // k_j
    std::vector<double> squared_speed_;       // (2 pi nu_j / k_j)^2 = phase velocity squared
    std::vector<double> sigma_;               // sigma_j
    std::vector<ModeSource> source_;
    Line speed_beyond_, sigma_beyond_;
};

}  // namespace fretbuzz
