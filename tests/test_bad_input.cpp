// Bad input must be refused with a message naming the parameter and what is allowed, a
// non-zero exit status, and no output left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "TestSupport.hpp"

namespace fretbuzz {
namespace {

using testing::run_cli;
using testing::ScratchDir;

struct BadRun {
    std::string arguments;      // after `run`, before `--out`
    std::string must_mention;   // a fragment of the message: the parameter at fault
};

void expect_refused(const BadRun& bad) {
    ScratchDir scratch("bad-input");
    const std::filesystem::path out = scratch.path() / "out";
    const auto result = run_cli("run " + bad.arguments + " --out " + out.string() + " -q");
    EXPECT_NE(result.exit_code, 0) << bad.arguments << "\n" << result.output;
    EXPECT_NE(result.output.find(bad.must_mention), std::string::npos)
        << "`" << bad.arguments << "` should name '" << bad.must_mention << "', said: " << result.output;
    EXPECT_FALSE(std::filesystem::exists(out)) << bad.arguments << ": an output directory was left behind";
}

TEST(BadInput, CommandLineValuesAreCheckedAndNamed) {
    const BadRun cases[] = {
        {"no-such-case", "unknown case 'no-such-case'"},
        {"bass-pop --fs 0", "run.fs"},
        {"bass-pop --fs -4e6", "run.fs"},
        {"bass-pop --fs nan", "run.fs"},
        {"bass-pop --fs inf", "run.fs"},
        {"bass-pop --duration 0", "run.duration"},
        {"bass-pop --duration -1", "run.duration"},
        {"bass-pop --K 0", "contact.K"},
        {"bass-pop --K -1e13", "contact.K"},
        {"bass-pop --K nan", "contact.K"},
        {"bass-pop --alpha 0.5", "contact.alpha"},
        {"bass-pop --alpha nan", "contact.alpha"},
        {"bass-pop --observe 0", "observation point"},
        {"bass-pop --observe 0.863", "observation point"},
        {"bass-pop --observe -0.1", "observation point"},
        {"bass-pop --observe nan", "observation point"},
        {"bass-pop --output-rate abc", "--output-rate"},
        {"bass-pop --output-rate 8e6", "run.output_rate"},
        {"bass-pop --output-rate 0", "run.output_rate"},
        {"bass-pop --fs 1e12 --duration 10", "number of steps"},
    };
    for (const BadRun& bad : cases) expect_refused(bad);
}

// A misspelt subcommand or option gets the nearest registered name (exit 2); a word far
// from every name gets no guess.
TEST(BadInput, MisspeltCommandsAndOptionsSuggestTheNearest) {
    const std::pair<std::string, std::string> cases[] = {
        {"runn bass-pop", "unknown command 'runn'; did you mean `fretbuzz run`?"},
        {"swep spec.toml", "did you mean `fretbuzz sweep`?"},
        {"shwo bass-pop", "did you mean `fretbuzz show`?"},
        {"run bass-pop --duratoin 0.1", "unknown option --duratoin of `fretbuzz run`; did you mean --duration?"},
        {"run bass-pop --fs 4e5 --alhpa=2", "did you mean --alpha?"},
        {"sweep spec.toml --out x --max-run 3", "did you mean --max-runs?"},
        {"--versoin", "did you mean --version?"},
        {"xyzzy", "unknown command 'xyzzy' (fretbuzz --help lists the commands)"},
    };
    for (const auto& [arguments, said] : cases) {
        const auto r = run_cli(arguments);
        EXPECT_EQ(r.exit_code, 2) << arguments << "\n" << r.output;
        EXPECT_NE(r.output.find(said), std::string::npos) << arguments << " should say " << said << ": " << r.output;
    }
    const auto far = run_cli("run bass-pop --zzzzzzzz 1");
    EXPECT_EQ(far.exit_code, 2) << far.output;
    EXPECT_EQ(far.output.find("did you mean"), std::string::npos) << far.output;
}

TEST(BadInput, CaseFilesAreCheckedAndNamed) {
    ScratchDir scratch("bad-case");
    const auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(scratch.path() / name) << text;
        return (scratch.path() / name).string();
    };
    const std::string base = R"(name = "probe"
[string]
L = 0.65
T = 80.0
mu = 1e-3
modes = 3
[modes]
table = "modes.csv"
[obstacle]
type = "table"
file = "obstacle.csv"
[excitation]
type = "modal"
file = "shape.csv"
[contact]
K = 1e10
alpha = 1.5
[run]
fs = 100000
duration = 0.001
[observe]
x = [0.3]
)";
    write("modes.csv", "1,100,1\n2,200,1\n3,300,1\n");
    write("shape.csv", "1,1e-3\n2,0\n3,0\n");
    const double dx = 0.65 / 4.0;
    const std::string below = std::to_string(dx) + ",-1e-3\n" + std::to_string(2 * dx) + ",-1e-3\n" +
                              std::to_string(3 * dx) + ",-1e-3\n";
    write("obstacle.csv", below);
    // The good file runs (the harness itself is sound).
    {
        ScratchDir out("good-case");
        const auto ok = run_cli("run " + write("good.toml", base) + " --out " + out.str() + "/o -q");
        ASSERT_EQ(ok.exit_code, 0) << ok.output;
    }
    const std::string above = std::to_string(dx) + ",2e-3\n" + std::to_string(2 * dx) + ",-1e-3\n" +
                              std::to_string(3 * dx) + ",-1e-3\n";
    write("above.csv", above);
    const BadRun cases[] = {
        {(scratch.path() / "absent.toml").string(), "cannot read"},
        {write("syntax.toml", "name = \"x\"\n[string\nL = 1\n"), "syntax.toml:"},
        {write("typo.toml", std::string(base).replace(base.find("mu = "), 2, "muu")), "found string.muu instead"},
        {write("negative_tension.toml", std::string(base).replace(base.find("T = 80.0"), 8, "T = -80.0")),
         "string.T"},
        {write("nan_length.toml", std::string(base).replace(base.find("L = 0.65"), 8, "L = nan")), "string.L"},
        {write("no_contact.toml", std::string(base).replace(base.find("[contact]"), 9, "[contactt]")),
         "contact"},
        {write("missing_file.toml", std::string(base).replace(base.find("modes.csv"), 9, "nothere.csv")),
         "nothere.csv"},
        {write("penetrating.toml", std::string(base).replace(base.find("obstacle.csv"), 12, "above.csv")),
         "penetrates the obstacle"},
    };
    for (const BadRun& bad : cases) expect_refused(bad);
    write("malformed.csv", "1,100,1\n2,oops,1\n3,300,1\n");
    expect_refused({write("malformed.toml", std::string(base).replace(base.find("modes.csv"), 9, "malformed.csv")),
                    "malformed.csv:2"});
}

// A file that is there but that the system fails to read is an I/O failure (exit 1), not the
// user's input (exit 2): /proc/self/mem is a regular file whose first page cannot be read (EIO).
TEST(BadInput, AFileTheSystemCannotReadExitsOneNotTwo) {
    ScratchDir scratch("unreadable");
    const std::filesystem::path link = scratch.path() / "mem.toml";
    std::filesystem::create_symlink("/proc/self/mem", link);
    const auto result = run_cli("run " + link.string() + " --out " + (scratch.path() / "out").string() + " -q");
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_NE(result.output.find("cannot read " + link.string()), std::string::npos) << result.output;
    EXPECT_FALSE(std::filesystem::exists(scratch.path() / "out"));
    const auto absent = run_cli("run " + (scratch.path() / "absent.toml").string() + " --out " +
                                (scratch.path() / "out").string() + " -q");
    EXPECT_EQ(absent.exit_code, 2) << absent.output;
    EXPECT_NE(absent.output.find("no such file"), std::string::npos) << absent.output;
}

TEST(BadInput, UnwritableOutputDirectoryIsRefused) {
    ScratchDir scratch("unwritable");
    const std::filesystem::path file = scratch.path() / "a-file";
    std::ofstream(file) << "not a directory";
    const auto result = run_cli("run bass-pop --duration 0.001 --fs 100000 --allow-aliasing --out " + (file / "out").string() + " -q");
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("--out"), std::string::npos) << result.output;
    const auto inside_file = run_cli("run bass-pop --duration 0.001 --fs 100000 --allow-aliasing --out " + file.string() + " -q");
    EXPECT_EQ(inside_file.exit_code, 2) << inside_file.output;
    EXPECT_NE(inside_file.output.find("not a directory"), std::string::npos) << inside_file.output;
}

TEST(BadInput, GoodRunWritesEveryOutput) {
    ScratchDir scratch("good");
    const auto out = scratch.path() / "out";
    const auto result = run_cli("run bass-pop --fs 400000 --duration 0.02 --output-rate native --out " + out.string() + " -q");
    ASSERT_EQ(result.exit_code, 0) << result.output;
    for (const char* name : {"observation.csv", "energy.csv", "summary.json", "audio.wav"})
        EXPECT_TRUE(std::filesystem::exists(out / name)) << name;
    // Native rate: one row per step from t = 0 (8000 steps), plus the header.
    std::ifstream in(out / "observation.csv");
    std::size_t lines = 0;
    for (std::string line; std::getline(in, line);) ++lines;
    EXPECT_EQ(lines, 8002u);
    for (const auto& entry : std::filesystem::directory_iterator(out))
        EXPECT_EQ(entry.path().filename().string().rfind(".fretbuzz-partial", 0), std::string::npos);
}

}  // namespace
}  // namespace fretbuzz
