// What a pickup passes: no DC, and the strings' notes as they are. Every audio file is
// written through it (run outputs, `fretbuzz play`, buzz-map notes); the data files keep the
// displacement itself.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/output/PickupHighPass.hpp"

namespace fretbuzz {
namespace {

constexpr double kRate = 48000.0;

// The amplitude of the f Hz component of x[from, to) (a least-squares fit of sin and cos).
double amplitude_at(const std::vector<double>& x, double f, std::size_t from, std::size_t to) {
    double ss = 0.0, cc = 0.0, sc = 0.0, xs = 0.0, xc = 0.0;
    for (std::size_t k = from; k < to; ++k) {
        const double w = 2.0 * std::numbers::pi * f * static_cast<double>(k) / kRate;
        const double s = std::sin(w), c = std::cos(w);
        ss += s * s;
        cc += c * c;
        sc += s * c;
        xs += x[k] * s;
        xc += x[k] * c;
    }
    const double det = ss * cc - sc * sc;
    const double a = (xs * cc - xc * sc) / det, b = (xc * ss - xs * sc) / det;
    return std::hypot(a, b);
}

double mean_of(const std::vector<double>& x, std::size_t from, std::size_t to) {
    double sum = 0.0;
    for (std::size_t k = from; k < to; ++k) sum += x[k];
    return sum / static_cast<double>(to - from);
}

// A fretted note's pickup signal: its static deflection (a step when the finger presses) and
// a 41 Hz partial (whole periods in every second: its mean over one is 0).
std::vector<double> fretted_note(std::size_t samples) {
    std::vector<double> x(samples);
    for (std::size_t k = 0; k < samples; ++k) {
        const double t = static_cast<double>(k) / kRate;
        x[k] = (t > 0.005 ? -0.09 : 0.0) + 0.05 * std::sin(2.0 * std::numbers::pi * 41.0 * t);
    }
    return x;
}

TEST(PickupHighPass, RemovesTheStaticDeflection) {
    const std::vector<double> x = fretted_note(static_cast<std::size_t>(3 * kRate));
    PickupHighPass pickup(kRate);
    std::vector<double> y(x.size());
    for (std::size_t k = 0; k < x.size(); ++k) y[k] = pickup(x[k]);
    const auto one_s = static_cast<std::size_t>(kRate);
    EXPECT_NEAR(mean_of(x, 2 * one_s, 3 * one_s), -0.09, 1e-12);
    // Settled within a second (the corner at 5 Hz: a time constant of about 45 ms).
    EXPECT_LT(std::abs(mean_of(y, 2 * one_s, 3 * one_s)), 1e-6);
    EXPECT_LT(std::abs(mean_of(y, one_s, 2 * one_s)), 1e-5);
}

TEST(PickupHighPass, PassesTheLowestNotesWithinATenthOfADecibel) {
    const auto n = static_cast<std::size_t>(4 * kRate);
    for (const double f : {30.87, 41.2, 55.0, 98.0, 1000.0}) {  // B0, E1, A1, G2, and higher
        std::vector<double> x(n), y(n);
        PickupHighPass pickup(kRate);
        for (std::size_t k = 0; k < n; ++k) {
            x[k] = std::sin(2.0 * std::numbers::pi * f * static_cast<double>(k) / kRate);
            y[k] = pickup(x[k]);
        }
        const double gain_db = 20.0 * std::log10(amplitude_at(y, f, n / 2, n) / amplitude_at(x, f, n / 2, n));
        EXPECT_LT(std::abs(gain_db), 0.1) << f << " Hz";
        EXPECT_LT(std::abs(gain_db), 0.01) << f << " Hz";  // a second-order corner at 5 Hz: -0.003 dB at B0
    }
    // And what it is there for: 1 Hz (a drift) is cut by more than 25 dB.
    std::vector<double> x(n), y(n);
    PickupHighPass pickup(kRate);
    for (std::size_t k = 0; k < n; ++k) {
        x[k] = std::sin(2.0 * std::numbers::pi * static_cast<double>(k) / kRate);
        y[k] = pickup(x[k]);
    }
    EXPECT_LT(amplitude_at(y, 1.0, n / 2, n), 0.06 * amplitude_at(x, 1.0, n / 2, n));
}

TEST(PickupHighPass, PassesAReleasedStringWithoutAThump) {
    // A string released from its initial shape swings about its line from its first sample:
    // it has no DC to remove, and the filter, starting from rest, adds no slow offset to it
    // (one that started settled on the first sample would swing about it: peaks 1.5 times
    // as high, a mean of 0.04 of the amplitude over the first 0.2 s).
    const auto n = static_cast<std::size_t>(kRate);
    const double amplitude = 0.002;
    std::vector<double> y(n);
    PickupHighPass pickup(kRate);
    double peak = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        y[k] = pickup(amplitude * std::cos(2.0 * std::numbers::pi * 40.0 * static_cast<double>(k) / kRate));
        peak = std::max(peak, std::abs(y[k]));
    }
    EXPECT_NEAR(peak, amplitude, 0.02 * amplitude);
    const auto tenth = static_cast<std::size_t>(0.1 * kRate);  // 4 periods
    for (std::size_t from = 0; from < n / 2; from += tenth)
        EXPECT_LT(std::abs(mean_of(y, from, from + tenth)), 0.01 * amplitude) << "from sample " << from;
}

TEST(PickupHighPass, IsAPairOfNumbersOfState) {
    // Nothing on the heap: copying it copies the filter, processing allocates nothing (the
    // real-time tests count it).
    static_assert(std::is_trivially_copyable_v<PickupHighPass>);
    static_assert(sizeof(PickupHighPass) == 7 * sizeof(double));  // five coefficients, two of state
}

TEST(PickupHighPass, AudioFilesCarryNoDc) {
    testing::ScratchDir scratch("pickup");
    const std::vector<double> x = fretted_note(static_cast<std::size_t>(2 * kRate));
    for (const char* name : {"note.wav", "note.ogg"}) {
        const auto path = scratch.path() / name;
        const double full_scale = write_normalised_audio(path, x, kRate);
        const std::vector<double> y = testing::read_audio(path);
        ASSERT_EQ(y.size(), x.size()) << name;
        const auto half = y.size() / 2;
        // Before, the file's second half sat at -0.09 / 0.14 of full scale.
        EXPECT_LT(std::abs(mean_of(y, half, y.size())), 1e-3) << name;
        // The partial at its level: full scale is what a sample of 1.0 stands for.
        EXPECT_NEAR(amplitude_at(y, 41.0, half, y.size()) * full_scale, amplitude_at(x, 41.0, half, x.size()),
                    0.01 * amplitude_at(x, 41.0, half, x.size()))
            << name;
    }
}

}  // namespace
}  // namespace fretbuzz
