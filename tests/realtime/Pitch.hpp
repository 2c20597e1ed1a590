#pragma once
// Pitch and level of rendered audio, for the real-time tests.
#include <cmath>
#include <cstddef>
#include <numbers>
#include <vector>

namespace fretbuzz::testing {

// The frequency of the strongest partial within +-50 cents of `guess` (Hann window over
// samples [from, to), searched in steps of 0.1 cent).
inline double partial_near(const std::vector<float>& x, std::size_t from, std::size_t to, double rate, double guess) {
    double best = guess, best_power = -1.0;
    for (int step = -500; step <= 500; ++step) {
        const double f = guess * std::exp2(step * 0.1 / 1200.0);
        double re = 0.0, im = 0.0;
        const double n = static_cast<double>(to - from);
        for (std::size_t i = from; i < to; ++i) {
            const double t = static_cast<double>(i - from);
            const double w = 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * t / n);
            re += w * x[i] * std::cos(2.0 * std::numbers::pi * f * t / rate);
            im += w * x[i] * std::sin(2.0 * std::numbers::pi * f * t / rate);
        }
        if (re * re + im * im > best_power) {
            best_power = re * re + im * im;
            best = f;
        }
    }
    return best;
}

inline double rms(const std::vector<float>& x, std::size_t from, std::size_t to) {
    double s = 0.0;
    for (std::size_t i = from; i < to; ++i) s += static_cast<double>(x[i]) * x[i];
    return std::sqrt(s / static_cast<double>(to - from));
}

inline double cents(double f, double reference) { return 1200.0 * std::log2(f / reference); }

}  // namespace fretbuzz::testing
