#pragma once
// Synthetic free decays of a stiff string for the estimation tests: mode j rings at
// j f0 sqrt(1 + B j^2) with sigma_j = 0.5 + 0.3 j and amplitude 0.5 / j from t = 0 (the
// attack peak). A doublet adds the other polarisation's partial, `separation` higher in
// relative frequency, `ratio` of the amplitude and `damping_ratio` of the damping, so that
// the two beat. White noise at `snr_db` below the signal's mean power.
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace fretbuzz::testing {

struct DecaySpec {
    double f0_hz = 110.0;
    double inharmonicity = 1e-4;
    int modes = 12;
    double separation = 0.0;  // relative; 0 with ratio 0: one partial per mode
    double ratio = 0.0;
    double damping_ratio = 0.8;
    double rate_hz = 16000.0;
    double seconds = 1.0;
    double snr_db = std::numeric_limits<double>::infinity();
    unsigned seed = 1;
};

struct TruePartial {
    int mode;
    int polarisation;  // 1: the stronger (z), 2: the weaker (y)
    double frequency_hz, sigma_per_s, amplitude, phase_rad;
};

inline std::vector<TruePartial> decay_partials(const DecaySpec& s) {
    std::vector<TruePartial> p;
    for (int j = 1; j <= s.modes; ++j) {
        const double f = s.f0_hz * j * std::sqrt(1.0 + s.inharmonicity * j * j), sigma = 0.5 + 0.3 * j;
        p.push_back({j, 1, f, sigma, 0.5 / j, 0.0});
        if (s.ratio > 0.0)
            p.push_back({j, 2, f * (1.0 + s.separation), s.damping_ratio * sigma, s.ratio * 0.5 / j, 1.0 * j});
    }
    return p;
}

inline std::vector<double> decay_signal(const DecaySpec& s) {
    std::vector<double> x(static_cast<std::size_t>(s.rate_hz * s.seconds), 0.0);
    for (const TruePartial& p : decay_partials(s))
        for (std::size_t n = 0; n < x.size(); ++n) {
            const double t = static_cast<double>(n) / s.rate_hz;
            x[n] += p.amplitude * std::exp(-p.sigma_per_s * t) *
                    std::cos(2.0 * std::numbers::pi * p.frequency_hz * t + p.phase_rad);
        }
    if (std::isfinite(s.snr_db)) {
        double power = 0.0;
        for (const double v : x) power += v * v / static_cast<double>(x.size());
        std::mt19937 random(s.seed);
        std::normal_distribution<double> noise(0.0, std::sqrt(power * std::pow(10.0, -s.snr_db / 10.0)));
        for (double& v : x) v += noise(random);
    }
    return x;
}

}  // namespace fretbuzz::testing
