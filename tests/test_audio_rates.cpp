// Runs at audio sample rates: the CLI accepts a low --fs on its own (the case's default
// output rate is capped at fs) and its outputs come at that rate.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "TestSupport.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;

TEST(AudioRates, Fs44100NeedsNoOtherFlag) {
    ScratchDir dir("fs44100");
    // The tanpura's 400 modes reach 147 kHz: at this rate contact aliases them, allowed here.
    const testing::CommandResult r =
        run_cli("run tanpura --fs 44100 --allow-aliasing --duration 0.05 -q --out " + dir.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream summary(dir.path() / "summary.json");
    const std::string text((std::istreambuf_iterator<char>(summary)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("\"output_rate\": 44100"), std::string::npos) << text;
    // An explicit rate above fs is still an error naming the option.
    const testing::CommandResult bad =
        run_cli("run tanpura --fs 44100 --allow-aliasing --output-rate 48000 --duration 0.05 -q --out " + dir.str() +
                "/bad");
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find("output_rate"), std::string::npos) << bad.output;
}

}  // namespace
}  // namespace fretbuzz
