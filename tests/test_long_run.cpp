// The paper's settings end to end: 3 s of bass-pop at 4 MHz through the CLI, in bounded
// memory; and the free flight between contacts leaves the audio as it would be if every
// step of every mode had been computed.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <numeric>

#include "TestSupport.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

// AddressSanitizer's shadow memory and quarantine roughly double a program's footprint
// (385 MB measured for this run) and slow it down; the bounds are on the program, not the tool.
#if defined(__SANITIZE_ADDRESS__)
constexpr double kSanitizerFactor = 3.0;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr double kSanitizerFactor = 3.0;
#else
constexpr double kSanitizerFactor = 1.0;
#endif
#else
constexpr double kSanitizerFactor = 1.0;
#endif

TEST(LongRun, ThreeSecondsOfBassPopAtFourMegahertzInBoundedMemory) {
    testing::ScratchDir scratch("long-run");
    const auto start = std::chrono::steady_clock::now();
    const auto result = testing::run_cli("run bass-pop --duration 3 --fs 4e6 --out " + scratch.str() + "/out -q");
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(result.exit_code, 0) << result.output;
    rusage usage{};
    ::getrusage(RUSAGE_CHILDREN, &usage);
    const double peak_mb = static_cast<double>(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
    RecordProperty("wall_seconds", std::to_string(wall));
    RecordProperty("peak_memory_MB", std::to_string(peak_mb));
    std::printf("3 s of bass-pop at 4 MHz: %.2f s wall, peak memory %.1f MB\n", wall, peak_mb);
    EXPECT_LT(peak_mb, 200.0 * kSanitizerFactor);
    // Not a speed benchmark (bench/ is): a guard against losing the fast path altogether.
    EXPECT_LT(wall, 120.0 * kSanitizerFactor);
}

std::vector<double> audio_of(const Case& c, bool free_flight, RunSummary& summary) {
    AudioWriter audio({"/dev/null"}, c.run.audio_rate_hz);
    RunObserver* observers[] = {&audio};
    RunOptions options;
    options.free_flight = free_flight;
    summary = simulate(c, observers, options);
    return audio.samples();
}

TEST(LongRun, FreeFlightLeavesTheAudioUnchanged) {
    // At 4 MHz every mode (up to 1.18 MHz) is below the simulation's Nyquist frequency; at
    // lower rates the stepped path would fold the top modes into the audio band as aliases
    // that free flight, leaving them out, does not have.
    Case c = load_case("bass-pop");
    c.run.sample_rate_hz = 4e6;
    c.run.duration_s = 0.15;
    RunSummary flying, stepping;
    const std::vector<double> a = audio_of(c, true, flying), b = audio_of(c, false, stepping);
    ASSERT_GT(flying.free_flight_fraction, 0.5);
    ASSERT_EQ(stepping.free_flight_fraction, 0.0);
    ASSERT_EQ(a.size(), b.size());
    double diff = 0.0, norm = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) {
        diff += (a[k] - b[k]) * (a[k] - b[k]);
        norm += b[k] * b[k];
    }
    // Only modes above 0.6 x 48 kHz are left out while flying, and the resampler removes
    // them (it attenuates a 30 kHz tone by 200 dB); what remains is the trace of switching
    // them off and on at the edges of each flight: measured 4e-6 (-108 dB), inaudible.
    EXPECT_LT(std::sqrt(diff / norm), 1e-5);
}

}  // namespace
}  // namespace fretbuzz
