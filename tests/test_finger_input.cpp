// Bad finger input (fret = k, --fret, [[finger]] keys) is refused before anything runs:
// exit status 2, a message that names the key and its allowed range, no output left behind.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/RunLength.hpp"
#include "fretbuzz/run/Simulation.hpp"

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

// The bass of bass-pluck on 255 modes at run.fs, with `extra` appended (fingers, gestures).
std::string small_bass(double fs, const std::string& extra) {
    std::string base = builtin_case_text("bass-pluck");
    base.replace(base.find("modes = 862"), 11, "modes = 255");
    base.replace(base.find("fs = 1e6"), 8, "fs = " + std::to_string(fs));
    base.replace(base.find("duration = 0.5"), 14, "duration = 0.005");
    return base + extra;
}

// The documented ranges of the fingers' and pluckers' parameters are what runs: values past
// them (1e300, 1e-300) are refused before the run, naming the key and its range (exit 2;
// they used to end in a solver failure, exit 3, that advised a lower stiffness for a mass),
// and the ranges' corners run with the energy balanced, at a low and a high rate.
TEST(FingerInput, TheRangesAreWhatRuns) {
    ScratchDir scratch("finger-ranges");
    const std::string finger = "\n[[finger]]\nfret = 5\n";
    const std::string pop = "\n[[gesture]]\ntype = \"pop\"\nposition = 0.637\nrelease_displacement = 2e-3\n";
    const std::pair<std::string, std::string> refused[] = {
        {finger + "mass = 1e300\n", "finger[0].mass (kg) = 1.0000000000000001e+300 is out of range: must be in [1e-05, 10] kg"},
        {finger + "mass = 1e-300\n", "finger[0].mass (kg) = 1e-300 is out of range: must be in [1e-05, 10] kg"},
        {finger + "stiffness = 1e300\n", "finger[0].stiffness (N/m^exponent) = 1.0000000000000001e+300 is out of range"},
        {finger + "stiffness = 1e10\n", "k <= M fs^2"},
        {finger + "loss = 1e300\n", "finger[0].loss (s/m) = 1.0000000000000001e+300 is out of range: must be in [0, 1000] s/m"},
        {pop + "stiffness = 1e300\n", "gesture[0].stiffness (N/m^exponent) = 1.0000000000000001e+300 is out of range: must be in [0, 1e+15]"},
        {pop + "loss = 1e300\n", "gesture[0].loss (s/m) = 1.0000000000000001e+300 is out of range: must be in [0, 1000]"},
    };
    int k = 0;
    for (const auto& [extra, message] : refused) {
        const std::filesystem::path file = scratch.path() / ("r" + std::to_string(k++) + ".toml");
        std::ofstream(file) << small_bass(48000, extra);
        const auto r = run_cli("run " + file.string() + " --out " + (scratch.path() / "o").string() + " -q");
        EXPECT_EQ(r.exit_code, 2) << extra << r.output;
        EXPECT_NE(r.output.find(message), std::string::npos) << extra << " should say " << message << ": " << r.output;
    }
    for (const double fs : {48000.0, 1e6}) {
        for (const double mass : {1e-5, 10.0}) {
            for (const double exponent : {1.0, 3.0}) {
                // The stiffest pad the range allows: alpha K^(1/alpha) F^(1-1/alpha) = M fs^2 at F = 5 N.
                const double k_pad = mass * fs * fs * (1.0 - 1e-9);
                const double stiffness = std::pow(k_pad / (exponent * std::pow(5.0, 1.0 - 1.0 / exponent)), exponent);
                std::ostringstream extra;
                extra.precision(17);
                extra << finger << "force = [[0, 0], [0.002, 5.0]]\nmass = " << mass << "\nstiffness = " << stiffness
                      << "\nexponent = " << exponent << "\nloss = 1000\n";
                Case c = parse_case(small_bass(fs, extra.str()), "corner.toml", DataSource::builtin());
                c.run.allow_aliasing = true;
                RunSummary s;
                ASSERT_NO_THROW(s = simulate(c, {})) << extra.str() << " at fs = " << fs;
                EXPECT_LT(s.max_relative_balance_error, 1e-9) << extra.str() << " at fs = " << fs;
            }
        }
        for (const double stiffness : {1e-3, 1e15}) {
            std::ostringstream extra;
            extra << pop << "stiffness = " << stiffness << "\nloss = 1000\nspeed = 1e-4\n";
            Case c = parse_case(small_bass(fs, extra.str()), "corner.toml", DataSource::builtin());
            c.run.allow_aliasing = true;
            RunSummary s;
            ASSERT_NO_THROW(s = simulate(c, {})) << extra.str() << " at fs = " << fs;
            // The stiffest pad's balance rests at its slope times the rounding of its position
            // (5e-7 at 48 kHz, on its grid pad as at its exact position beside the frets).
            EXPECT_LT(s.max_relative_balance_error, stiffness > 1.0 ? 1e-5 : 1e-12) << extra.str() << " at fs = " << fs;
        }
    }
}

// Input that used to be accepted and then did nothing is refused, naming the key: a finger
// that never presses, a second polarisation's table on a string with one, a gesture that
// never moves.
TEST(FingerInput, InputThatWouldDoNothingIsRefused) {
    ScratchDir scratch("finger-nothing");
    const auto write = [&](const std::string& name, const std::string& text) {
        const std::filesystem::path path = scratch.path() / name;
        std::ofstream(path) << text;
        return path.string();
    };
    const std::string pluck = "\n[[gesture]]\ntype = \"pluck\"\ndirection = \"up\"\nposition = 0.637\n"
                              "release_displacement = 2e-3\n";
    expect_refused(write("f.toml", small_bass(100000, "\n[[finger]]\nposition = 0.2\nforce = []\n")),
                   "finger[0].force = []: an empty profile never presses");
    expect_refused(write("y.toml", small_bass(100000, "\n[polarisation_y]\nfrequency_scale = 1.01\n")),
                   "[polarisation_y] describes the second polarisation, but string.polarisations = 1");
    expect_refused(write("s.toml", small_bass(100000, pluck + "speed = 1e-300\n")),
                   "gesture[0].speed (m/s) = 1e-300 is out of range: must be in [0.0001, 100]");
    expect_refused(write("w.toml", small_bass(100000, pluck + "withdraw_speed = 1e-300\n")),
                   "gesture[0].withdraw_speed (m/s) = 1e-300 is out of range");
}

// A built-in case with a finger and a gesture shortened with --duration runs: its profiles
// are cut to the run (a point past the end kept for the part within), a gesture that would
// start after the end is left out with a warning, and the run is the same as with the
// whole profiles.
TEST(FingerInput, AShortenedRunCutsItsProfiles) {
    ScratchDir scratch("finger-short");
    const auto r = run_cli("run bass-fret5-lift --duration 0.002 --out " + (scratch.path() / "o").string() + " -q");
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("gesture[0] (a pop at 0.02 s) is left out: it starts after the run's end at 0.002 s"),
              std::string::npos)
        << r.output;

    Case c = load_case("bass-fret5-lift");
    Case whole = c;
    set_duration(c, 0.0201);
    using Profile = std::vector<std::array<double, 2>>;
    EXPECT_EQ(c.fingers[0].force_profile, (Profile{{0.0, 0.0}, {0.005, 5.0}, {0.5, 5.0}}));
    ASSERT_EQ(c.plucks.size(), 1u);
    EXPECT_NO_THROW(c.validate());
    whole.run.duration_s = 0.0201;  // the profiles as written, past the end
    const RunSummary cut_run = simulate(c, {});
    const RunSummary whole_run = simulate(whole, {});
    EXPECT_EQ(cut_run.energy_final_j, whole_run.energy_final_j);
    EXPECT_EQ(cut_run.work_j, whole_run.work_j);
    EXPECT_GT(cut_run.finger_contact_steps, 0);

    set_duration(c, 0.01);
    EXPECT_TRUE(c.plucks.empty());
    EXPECT_EQ(c.warnings.size(), whole.warnings.size() + 1);
}

}  // namespace
}  // namespace fretbuzz
