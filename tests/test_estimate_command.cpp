// `fretbuzz estimate`: bad input exits 2 and writes nothing; a simulated free decay goes
// through estimate -> case.toml -> the mode table the case resolves to.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <numbers>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;
namespace fs = std::filesystem;

TEST(EstimateCommand, NotAudioIsRejectedAndNothingIsWritten) {
    ScratchDir dir("estimate-bad");
    const fs::path text = dir.path() / "notes.wav";
    std::ofstream(text) << "this is not audio\n";
    const fs::path out = dir.path() / "out";
    const auto r = run_cli("estimate " + text.string() + " --L 0.863 --mu 6.69e-3 --d 1.14e-3 --out " + out.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("not an audio file"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
}

// A mono 16-bit PCM WAV file of the samples (full scale 1).
void write_wav(const fs::path& path, const std::vector<double>& x, int rate) {
    std::ofstream out(path, std::ios::binary);
    const auto u32 = [&out](std::uint32_t v) { out.write(reinterpret_cast<const char*>(&v), 4); };
    const auto u16 = [&out](std::uint16_t v) { out.write(reinterpret_cast<const char*>(&v), 2); };
    const auto bytes = static_cast<std::uint32_t>(2 * x.size());
    out.write("RIFF", 4);
    u32(36 + bytes);
    out.write("WAVEfmt ", 8);
    u32(16);
    u16(1);
    u16(1);
    u32(static_cast<std::uint32_t>(rate));
    u32(static_cast<std::uint32_t>(2 * rate));
    u16(2);
    u16(16);
    out.write("data", 4);
    u32(bytes);
    for (const double v : x) u16(static_cast<std::uint16_t>(static_cast<std::int16_t>(std::lround(32767.0 * v))));
}

// Twelve decaying partials of a stiff string at 110 Hz, `seconds` long, peak `peak`.
std::vector<double> decay(double seconds, int rate, double peak) {
    std::vector<double> x(static_cast<std::size_t>(seconds * rate));
    for (std::size_t n = 0; n < x.size(); ++n) {
        const double t = static_cast<double>(n) / rate;
        for (int j = 1; j <= 12; ++j)
            x[n] += 0.5 / j * std::exp(-(0.5 + 0.3 * j) * t) *
                    std::cos(2.0 * std::numbers::pi * 110.0 * j * std::sqrt(1 + 1e-4 * j * j) * t);
    }
    double top = 0.0;
    for (const double v : x) top = std::max(top, std::abs(v));
    for (double& v : x) v *= peak / top;
    return x;
}

TEST(EstimateCommand, BadRecordingsExitTwoAndWriteNothing) {
    ScratchDir dir("estimate-bad-recordings");
    const int rate = 16000;
    std::vector<double> clipped = decay(1.0, rate, 1.6);
    for (double& v : clipped) v = std::clamp(v, -1.0, 1.0);
    const std::vector<std::pair<std::string, std::vector<double>>> recordings = {
        {"silent", std::vector<double>(rate, 0.0)},
        {"at least 0.2 s", decay(0.1, rate, 0.5)},
        {"clipped", clipped},
    };
    for (const auto& [expected, samples] : recordings) {
        const fs::path wav = dir.path() / "in.wav", out = dir.path() / "out";
        write_wav(wav, samples, rate);
        const auto r = run_cli("estimate " + wav.string() + " --L 0.65 --mu 6e-3 --d 1.1e-3 --no-plots --out " + out.string());
        EXPECT_EQ(r.exit_code, 2) << expected << ": " << r.output;
        EXPECT_NE(r.output.find(expected), std::string::npos) << r.output;
        EXPECT_FALSE(fs::exists(out)) << expected;
    }
    // The same decay, neither clipped nor short, is accepted: the refusals are about the input.
    write_wav(dir.path() / "good.wav", decay(1.0, rate, 0.5), rate);
    const auto r = run_cli("estimate " + (dir.path() / "good.wav").string() +
                           " --L 0.65 --mu 6e-3 --d 1.1e-3 --no-plots -q --out " + (dir.path() / "good").string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
}

TEST(EstimateCommand, RunEstimateAndCaseRoundTrip) {
    ScratchDir dir("estimate-trip");
    const fs::path run = dir.path() / "run", est = dir.path() / "est";
    ASSERT_EQ(run_cli("run bass-pluck --fs 48000 --allow-aliasing --duration 1.5 -q --out " + run.string()).exit_code, 0);
    const std::string wav = (run / "audio.wav").string();

    // f0 outside the analysed band: exit 2, no output directory.
    auto r = run_cli("estimate " + wav + " --case bass-pluck --d 1.14e-3 --f0 98 --band 150 4000 --no-plots --out " +
                     est.string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("--f0 (Hz) = 98 is out of range"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(est));

    r = run_cli("estimate " + wav + " --case bass-pluck --d 1.14e-3 --modes 120 --band 20 4000 --no-plots -q --out " +
                est.string());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* name : {"partials.csv", "modes.csv", "fit.json", "case.toml", "case-snippet.toml", "model_curves.csv"})
        EXPECT_TRUE(fs::exists(est / name)) << name;
    // The written case reads its mode table back (source column included) and keeps the pluck.
    const Case original = load_case("bass-pluck");
    const Case estimated = load_case((est / "case.toml").string());
    ASSERT_EQ(estimated.mode_count(), 120u);
    for (std::size_t j = 0; j < 30; ++j) {
        EXPECT_NEAR(estimated.modes.frequency_hz[j] / original.modes.frequency_hz[j], 1.0, 1e-4) << "mode " << j + 1;
        EXPECT_NEAR(estimated.modes.sigma_per_s[j] / original.modes.sigma_per_s[j], 1.0, 0.05) << "mode " << j + 1;
    }
    EXPECT_NEAR(estimated.string.length_m, original.string.length_m, 1e-12);
    EXPECT_EQ(estimated.modes.source.front(), ModeSource::measured);
    EXPECT_EQ(estimated.modes.source.back(), ModeSource::model);  // mode 120 (11.8 kHz) lies above --band
}

}  // namespace
}  // namespace fretbuzz
