// Runs at audio sample rates: the CLI accepts a low --fs on its own (the case's default
// output rate is capped at fs) and its outputs come at that rate.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;

std::string summary_text(const std::filesystem::path& dir) {
    std::ifstream summary(dir / "summary.json");
    return std::string((std::istreambuf_iterator<char>(summary)), std::istreambuf_iterator<char>());
}

TEST(AudioRates, Fs44100NeedsNoOtherFlag) {
    ScratchDir dir("fs44100");
    // The tanpura's 400 modes reach 147 kHz: at 44.1 kHz only the modes below fs/2 are kept,
    // with a warning and the choice in summary.json; --allow-aliasing keeps them all.
    const testing::CommandResult r = run_cli("run tanpura --fs 44100 --duration 0.05 -q --out " + dir.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::string text = summary_text(dir.path());
    EXPECT_NE(text.find("\"output_rate\": 44100"), std::string::npos) << text;
    const Case tanpura = load_case("tanpura");
    const std::size_t kept = modes_below_nyquist(tanpura.modes, 44100.0);
    ASSERT_LT(kept, tanpura.mode_count());
    EXPECT_GT(tanpura.modes.frequency_hz[kept], 22050.0);
    EXPECT_NE(text.find("\"modes\": " + std::to_string(kept) + ","), std::string::npos) << text;
    EXPECT_NE(text.find("\"modes_choice\": \"automatic"), std::string::npos) << text;
    EXPECT_NE(text.find("modes below fs/2"), std::string::npos) << text;  // the warning
    EXPECT_EQ(text.find("lie above fs/2"), std::string::npos) << text;    // nothing aliased
    const testing::CommandResult all =
        run_cli("run tanpura --fs 44100 --allow-aliasing --duration 0.05 -q --out " + dir.str() + "/all");
    ASSERT_EQ(all.exit_code, 0) << all.output;
    text = summary_text(dir.path() / "all");
    EXPECT_NE(text.find("\"modes\": 400,"), std::string::npos) << text;
    // An explicit rate above fs is still an error naming the option.
    const testing::CommandResult bad =
        run_cli("run tanpura --fs 44100 --allow-aliasing --output-rate 48000 --duration 0.05 -q --out " + dir.str() +
                "/bad");
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find("output_rate"), std::string::npos) << bad.output;
}

TEST(AudioRates, EveryBuiltInCaseRunsAt48kHzWithNoOtherFlag) {
    // A modal excitation table tied to the mode count (the bass cases) is truncated instead
    // of read again.
    for (const auto& info : builtin_cases()) {
        const Case c = load_case(info.name);
        ScratchDir dir("fs48000-" + info.name);
        const testing::CommandResult r = run_cli("run " + info.name + " --fs 48000 --duration " +
                                                 std::to_string(c.run.duration_s) + " -q --out " + dir.str());
        ASSERT_EQ(r.exit_code, 0) << info.name << ": " << r.output;
        const std::string text = summary_text(dir.path());
        // Modes kept below fs/2 where one would alias onto a very low frequency; else all
        // kept (those above fs/2 with a warning where contact can happen, as before).
        const bool refused = contact_possible(c) && !check_sampling(c.modes, 48000.0).hazardous.empty();
        const std::size_t kept = refused ? modes_below_nyquist(c.modes, 48000.0) : c.mode_count();
        EXPECT_NE(text.find("\"modes\": " + std::to_string(kept) + ","), std::string::npos) << info.name << text;
        EXPECT_EQ(text.find("contact results are wrong"), std::string::npos) << info.name << text;
    }
}

}  // namespace
}  // namespace fretbuzz
