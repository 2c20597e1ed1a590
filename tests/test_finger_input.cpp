// Bad finger input (fret = k, --fret, [[finger]] keys) is refused before anything runs:
// exit status 2, a message that names the key and its allowed range, no output left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "TestSupport.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;

void expect_refused(const std::string& arguments, const std::string& must_mention) {
    ScratchDir scratch("bad-finger");
    const std::filesystem::path out = scratch.path() / "out";
    const auto result = run_cli("run " + arguments + " --out " + out.string() + " -q");
    EXPECT_EQ(result.exit_code, 2) << arguments << "\n" << result.output;
    EXPECT_NE(result.output.find(must_mention), std::string::npos)
        << "`" << arguments << "` should name '" << must_mention << "', said: " << result.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << arguments << ": an output directory was left behind";
}

TEST(FingerInput, CommandLineFretIsChecked) {
    expect_refused("bass-fretless --fret 5", "--fret = 5");
    expect_refused("bass-fretless --fret 5", "no frets");
    expect_refused("flat-obstacle --fret 1", "--fret");
    expect_refused("bass-pop --fret 21", "--fret");
    expect_refused("bass-pop --fret 0", "--fret");
    expect_refused("bass-pop --fret -3", "--fret");
}

TEST(FingerInput, CaseFileFingersAreCheckedAndNamed) {
    ScratchDir scratch("bad-finger-case");
    std::string base = builtin_case_text("bass-pluck");
    base.replace(base.find("modes = 862"), 11, "modes = 255");
    base.replace(base.find("fs = 1e6"), 8, "fs = 100000");
    base.replace(base.find("duration = 0.5"), 14, "duration = 0.01");
    const auto write = [&](const std::string& name, const std::string& extra) {
        const std::filesystem::path path = scratch.path() / name;
        std::ofstream(path) << base << extra;
        return path.string();
    };
    const std::string finger = "\n[[finger]]\nposition = 0.2\n";
    // A top-level key must come before the tables: `fret` goes first.
    const auto with_fret = [&](const std::string& name, const std::string& line) {
        const std::filesystem::path path = scratch.path() / name;
        std::ofstream(path) << line << "\n" << base;
        return path.string();
    };
    {  // the good files run
        ScratchDir out("good-finger");
        for (const std::string& file : {with_fret("good1.toml", "fret = 5"),
                                        write("good2.toml", finger + "force = [[0, 0], [0.005, 3]]\n")}) {
            const auto ok = run_cli("run " + file + " --out " + out.str() + "/o -q");
            ASSERT_EQ(ok.exit_code, 0) << file << ok.output;
        }
    }
    expect_refused(with_fret("fret21.toml", "fret = 21"), "fret");
    expect_refused(with_fret("fret0.toml", "fret = 0"), "fret");
    std::string fretless = builtin_case_text("bass-fretless");
    {
        const std::filesystem::path path = scratch.path() / "fretless.toml";
        std::ofstream(path) << "fret = 3\n" << fretless;
        expect_refused(path.string(), "no frets");
    }
    const std::pair<std::string, std::string> cases[] = {
        {"\n[[finger]]\nposition = 0.0\n", "finger[0].position"},
        {"\n[[finger]]\nposition = 0.9\n", "finger[0].position"},
        {"\n[[finger]]\nposition = -0.1\n", "finger[0].position"},
        {finger + "width = -0.01\n", "finger[0].width"},
        {finger + "width = 0\n", "finger[0].width"},
        {"\n[[finger]]\nposition = 0.02\nwidth = 0.05\n", "overlaps an end"},
        {"\n[[finger]]\nposition = 0.858\nwidth = 0.02\n", "finger[0].width"},
        {finger + "mass = -0.005\n", "finger[0].mass"},
        {finger + "mass = 0\n", "finger[0].mass"},
        {finger + "stiffness = -1e5\n", "finger[0].stiffness"},
        {finger + "exponent = 0.5\n", "finger[0].exponent"},
        {finger + "loss = -1\n", "finger[0].loss"},
        {finger + "gap = -0.001\n", "finger[0].gap"},
        {finger + "force = -5\n", "finger[0].force[0][1]"},
        {finger + "force = [[0, 1], [0.5, 5]]\n", "finger[0].force[1][0]"},
        {finger + "force = [[-0.1, 1]]\n", "finger[0].force[0][0]"},
        {finger + "force = [[0.005, 1], [0.001, 5]]\n", "finger[0].force[1][0]"},
        {finger + "force = nan\n", "finger[0].force"},
        {finger + "mas = 0.005\n", "finger[0].mas"},
        {finger + "fret = 5\n", "finger[0].position"},
        {"\n[[finger]]\nfret = 30\n", "finger[0].fret"},
        {finger + "\n[[finger]]\nposition = 0.205\n", "finger[1].position"},
    };
    int k = 0;
    for (const auto& [extra, key] : cases) expect_refused(write("bad" + std::to_string(k++) + ".toml", extra), key);
}

}  // namespace
}  // namespace fretbuzz
