// `fretbuzz estimate`: bad input exits 2 and writes nothing; a simulated free decay goes
// through estimate -> case.toml -> the mode table the case resolves to.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "TestSupport.hpp"
#include "fretbuzz/io/CaseFile.hpp"

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
}

}  // namespace
}  // namespace fretbuzz
