// A real plucked string: the low E (E2, 82.4 Hz) sample of the nylon-string guitar in
// Debian's freepats package (GUS patch; the recorded sample from the pluck on, its loop
// points ignored). Skipped when the package is not installed.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>

#include "fretbuzz/analysis/ModalEstimation.hpp"
#include "fretbuzz/analysis/ModelFit.hpp"

namespace fretbuzz {
namespace {

constexpr const char* kPatch = "/usr/share/midi/freepats/Tone_000/024_Nylon_Guitar.pat";

std::uint32_t le32(const std::vector<unsigned char>& b, std::size_t at) {
    return b[at] | (b[at + 1] << 8) | (b[at + 2] << 16) | (static_cast<std::uint32_t>(b[at + 3]) << 24);
}

// The first sample of a GF1 patch (16-bit signed, which this one is), scaled to full scale 1.
std::vector<double> first_sample(const std::vector<unsigned char>& b, double& rate, double& root_hz) {
    std::size_t header = 129 + 63 + 47;
    const std::uint32_t length = le32(b, header + 8);
    rate = b[header + 20] | (b[header + 21] << 8);
    root_hz = le32(b, header + 30) / 1000.0;
    std::vector<double> x;
    for (std::size_t i = header + 96; i + 1 < header + 96 + length; i += 2)
        x.push_back(static_cast<std::int16_t>(b[i] | (b[i + 1] << 8)) / 32768.0);
    return x;
}

TEST(RealRecording, FreepatsNylonGuitarLowE) {
    if (!std::filesystem::exists(kPatch)) GTEST_SKIP() << kPatch << " not found (Debian package freepats)";
    std::ifstream in(kPatch, std::ios::binary);
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    ASSERT_EQ(std::memcmp(bytes.data(), "GF1PATCH", 8), 0);
    double rate = 0.0, root = 0.0;
    const std::vector<double> x = first_sample(bytes, rate, root);
    ASSERT_NEAR(root, 82.399, 1e-3);

    EstimationOptions options;
    options.max_partials = 60;
    options.full_scale = 1.0;
    const ModalEstimate e = ModalEstimation(options).estimate(x, rate);
    ASSERT_FALSE(e.partials.empty());
    ASSERT_EQ(e.partials.front().mode, 1u);
    // f0 within 10 cents of the sample's note, from the first partial and from the fitted law.
    EXPECT_LT(std::abs(1200.0 * std::log2(e.partials.front().frequency_hz / root)), 10.0);
    EXPECT_LT(std::abs(1200.0 * std::log2(e.f0_hz / root)), 10.0);

    // Classical guitar low E: L = 0.65 m, mu = 6.0e-3 kg/m, d = 1.1 mm (typical, not measured).
    const StringFit fit = ModelFit({0.65, std::nullopt, 6.0e-3, 1.1e-3}).fit(e);
    EXPECT_GE(fit.frequency.inharmonicity, 1e-5);  // wound strings: 1e-5 .. 1e-4
    EXPECT_LE(fit.frequency.inharmonicity, 1e-4);
    std::vector<double> q;
    for (const EstimatedPartial& p : e.partials)
        if (p.reliable) q.push_back(std::numbers::pi * p.frequency_hz / p.sigma_per_s);
    ASSERT_GE(q.size(), 10u);
    std::nth_element(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(q.size() / 2), q.end());
    EXPECT_GE(q[q.size() / 2], 300.0);  // low partials of plucked strings: Q of 10^2.5 .. 10^4.5
    EXPECT_LE(q[q.size() / 2], 3e4);
}

}  // namespace
}  // namespace fretbuzz
