// Strings-on-a-bridge case files: a [[string]] turned end for end (mirror = true) and one with
// keys of its case set over it (set.KEY = ...), against the same strings written out by hand;
// bad keys refused naming them (exit 2, nothing written); `fretbuzz show` and `export` of a
// strings case.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/StringsCaseFile.hpp"
#include "fretbuzz/run/StringsRun.hpp"

namespace fretbuzz {
namespace {

void write_text(const std::filesystem::path& path, const std::string& text) {
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path) << text;
}

std::string read_text(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

// `text` with `from` replaced once; fails the test where `from` is not there exactly once.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const std::size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// A strings case of `strings` ([[string]] tables) on one bridge mode, in `dir`.
StringsCase strings_case(const testing::ScratchDir& dir, double fs, double duration, const std::string& strings,
                         std::size_t count) {
    std::string participation;
    for (std::size_t s = 0; s < count; ++s) participation += s == 0 ? "1.0" : ", 0.6";
    const std::string text = "name = \"probe\"\n[run]\nfs = " + std::to_string(fs) + "\nduration = " +
                             std::to_string(duration) + "\n[bridge]\n[[bridge.mode]]\nmass_kg = 0.05\n"
                             "frequency_hz = 200.0\ndamping_ratio = 0.04\nparticipation = [" + participation + "]\n" +
                             strings;
    return parse_strings_case({text, (dir.path() / "probe.toml").string(), DataSource::directory(dir.path())});
}

TEST(StringsCases, MirroredSitarIsTheSitarWrittenEndForEnd) {
    // The built-in sitar turned end for end against the same string with every position
    // written as L - x by hand (0.88 m: the jawari from 0.855 m to its apex at L, the pluck
    // at 0.63 m, the pickup at 0.08 m), buzzing on its jawari at the bridge end beside a taraf
    // string: the same run to round-off.
    const testing::ScratchDir dir("strings-mirror");
    std::string by_hand = builtin_case_text("sitar");
    by_hand = replaced(by_hand, "position = 0.0         # m, the bridge starts", "position = 0.855  #");
    by_hand = replaced(by_hand, "apex = 0.0", "apex = 0.88");
    by_hand = replaced(by_hand, "position = 0.25        # m", "position = 0.63");
    by_hand = replaced(by_hand, "x = [0.8]", "x = [0.08]");
    write_text(dir.path() / "sitar-by-hand.toml", by_hand);
    const std::string taraf = "[[string]]\nname = \"Sa\"\ncase = \"bridges/taraf-string.toml\"\nat_rest = true\n";
    const StringsCase turned = strings_case(
        dir, 400000, 0.03, "[[string]]\nname = \"main\"\ncase = \"sitar.toml\"\nmirror = true\n" + taraf, 2);
    const StringsCase written = strings_case(
        dir, 400000, 0.03, "[[string]]\nname = \"main\"\ncase = \"sitar-by-hand.toml\"\n" + taraf, 2);
    // The jawari is at the bridge end: the heights there, none at the nut.
    const Case& main = turned.strings[0];
    EXPECT_TRUE(std::isfinite(main.obstacle_height_m.back()));
    EXPECT_FALSE(std::isfinite(main.obstacle_height_m.front()));
    EXPECT_TRUE(turned.origins[0].turned);

    const StringsRun a = simulate_strings(turned), b = simulate_strings(written);
    ASSERT_EQ(a.energy[0].size(), b.energy[0].size());
    // The main string buzzes: its contacts take energy up into high partials.
    ASSERT_GT(a.energy[1].back(), 0.0);
    // The energies to round-off of the energy in play (the main string's); the main string's
    // pickup to round-off of its own. The taraf string and the bridge carry a millionth of the
    // main string's energy: the round-off that the two ways of writing the positions leave in
    // its state shows at about 1e-11 of their own signals.
    const double scale = std::sqrt(std::inner_product(a.energy[0].begin(), a.energy[0].end(), a.energy[0].begin(), 0.0));
    const auto against_main = [scale](const std::vector<double>& x, const std::vector<double>& y) {
        return testing::relative_l2(x, y) * std::sqrt(std::inner_product(y.begin(), y.end(), y.begin(), 0.0)) / scale;
    };
    const struct {
        const char* what;
        double error, bound;
    } signals[] = {
        {"main string's energy (of its own)", testing::relative_l2(a.energy[0], b.energy[0]), 1e-12},
        {"taraf string's energy (of the main string's)", against_main(a.energy[1], b.energy[1]), 1e-12},
        {"bridge's energy (of the main string's)", against_main(a.bridge_energy, b.bridge_energy), 1e-12},
        {"main pickup (of its own)", testing::relative_l2(a.pickup_audio[0], b.pickup_audio[0]), 1e-12},
        {"taraf pickup (of its own)", testing::relative_l2(a.pickup_audio[1], b.pickup_audio[1]), 1e-9},
        {"bridge's speed (of its own)", testing::relative_l2(a.bridge_audio, b.bridge_audio), 1e-9},
    };
    for (const auto& s : signals) {
        std::printf("mirror = true against the sitar written end for end, %s: relative L2 %.2e\n", s.what, s.error);
        EXPECT_LT(s.error, s.bound) << s.what;
    }
}

TEST(StringsCases, SetKeysGiveTheCaseWithThoseKeysWritten) {
    // The guitar string with guitar-chord's A2 values set over it is the guitar string file
    // with those values written in: the same modes, obstacle, fingers and pick.
    const testing::ScratchDir dir("strings-set");
    std::string by_hand = read_text(std::filesystem::path(FRETBUZZ_SOURCE_DIR) / "cases/bridges/guitar-string.toml");
    by_hand = replaced(by_hand, "T = 77.84", "T = 86.74");
    by_hand = replaced(by_hand, "mu = 6.82476e-03", "mu = 4.26801e-03");
    by_hand = replaced(by_hand, "E_core_I_core = 4.290e-04", "E_core_I_core = 2.069e-04");
    by_hand = replaced(by_hand, "action_nut = 3.305e-04", "action_nut = 2.747e-04");
    by_hand = replaced(by_hand, "time = 0.010", "time = 0.012");
    by_hand = replaced(by_hand, "[[gesture]]", "[[finger]]\nfret = 2\n\n[[gesture]]");
    write_text(dir.path() / "a2.toml", by_hand);
    const StringsCase sc = strings_case(dir, 192000, 0.05,
                                        "[[string]]\nname = \"set\"\ncase = \"bridges/guitar-string.toml\"\n"
                                        "set.string = { T = 86.74, mu = 4.26801e-03, E_core_I_core = 2.069e-04 }\n"
                                        "set.obstacle.action_nut = 2.747e-04\n"
                                        "set.finger = [{ fret = 2 }]\n"
                                        "[[string.set.gesture]]\ntype = \"pluck\"\nposition = 0.528\nwidth = 0.005\n"
                                        "direction = \"up\"\ntime = 0.012\nrelease_displacement = 0.6e-3\n"
                                        "[[string]]\nname = \"written\"\ncase = \"a2.toml\"\n",
                                        2);
    const Case &set = sc.strings[0], &written = sc.strings[1];
    EXPECT_EQ(set.string.tension_n, 86.74);
    EXPECT_EQ(set.modes.frequency_hz, written.modes.frequency_hz);
    EXPECT_EQ(set.modes.sigma_per_s, written.modes.sigma_per_s);
    EXPECT_EQ(set.obstacle_height_m, written.obstacle_height_m);
    ASSERT_EQ(set.fingers.size(), 1u);
    ASSERT_EQ(written.fingers.size(), 1u);
    EXPECT_EQ(set.fingers[0].position_m, written.fingers[0].position_m);
    ASSERT_EQ(set.plucks.size(), 1u);  // the array replaced the base's, not added to it
    EXPECT_EQ(set.plucks[0].start_s, written.plucks[0].start_s);
    // The first partial is the A string's (f1 = sqrt(T / mu) / 2L, stiffness raising it a little).
    EXPECT_NEAR(set.modes.frequency_hz[0], 110.0, 0.002 * 110.0);
    EXPECT_EQ(sc.origins[0].overrides.size(), 6u);
}

TEST(StringsCases, GuitarChordStringsAreTheirNotes) {
    // Each string of the built-in chord, the one guitar string with its own values set: its
    // open f1 is its note (the tension chart's pitch), its finger where the chord puts one.
    const StringsCase sc = parse_strings_case(*read_strings_case_text("guitar-chord"));
    const struct {
        const char* name;
        double hz;
        std::size_t fingers;
    } notes[] = {{"E2", 82.4069, 0}, {"A2", 110.0, 1}, {"D3", 146.8324, 1},
                 {"G3", 195.9977, 1}, {"B3", 246.9417, 0}, {"E4", 329.6276, 0}};
    ASSERT_EQ(sc.strings.size(), 6u);
    for (std::size_t s = 0; s < 6; ++s) {
        EXPECT_EQ(sc.string_names[s], notes[s].name);
        EXPECT_NEAR(sc.strings[s].modes.frequency_hz[0], notes[s].hz, 0.002 * notes[s].hz) << notes[s].name;
        EXPECT_EQ(sc.strings[s].fingers.size(), notes[s].fingers) << notes[s].name;
        EXPECT_EQ(sc.origins[s].case_file, "bridges/guitar-string.toml");
    }
}

TEST(StringsCases, BadKeysExit2NamingTheKey) {
    const testing::ScratchDir dir("strings-bad-keys");
    const std::string head = "name = \"bad\"\n[run]\nfs = 96000\nduration = 0.01\n[bridge]\n[[bridge.mode]]\n"
                             "mass_kg = 0.005\nfrequency_hz = 300.0\nparticipation = [1.0, 1.0]\n"
                             "[[string]]\nname = \"a\"\ncase = \"bridges/pair-string.toml\"\n"
                             "[[string]]\nname = \"b\"\ncase = \"bridges/pair-string.toml\"\n";
    const struct {
        std::string line, named;
    } bad[] = {
        {"set.string.Tx = 3.0", "unknown key string[1].set.string.Tx: did you mean string[1].set.string.T?"},
        {"set.string.T = -3.0", "string[1].set.string.T = -3"},
        {"set.obstacle.apex = 0.1", "unknown key string[1].set.obstacle.apex"},
        {"set.modes.damping.eta9 = 1.0", "unknown key string[1].set.modes.damping.eta9"},
        {"set.excitation.type = \"nope\"", "string[1].set.excitation.type = \"nope\": must be one of"},
        {"set.finger = [{ fret = 2 }]", "string[1].set.finger[0].fret = 2: this case has no frets"},
        {"set.gesture = [{ type = \"pluck\", position = 0.3 }]", "string[1].set.gesture[0].direction is missing"},
        {"set.string = 5", "string[1].set.string must be a table"},
        {"set = 3", "string[1].set: must be a table"},
        {"set.run.fs = 48000", "string[1].set.run.fs: every string runs by the strings case's [run] fs"},
        {"mirror = 2", "string[1].mirror must be true or false"},
        {"mirrror = true", "unknown key string[1].mirrror: did you mean string[1].mirror?"},
    };
    const std::filesystem::path out = dir.path() / "out";
    for (const auto& b : bad) {
        write_text(dir.path() / "bad.toml", head + b.line + "\n");
        const testing::CommandResult r = testing::run_cli("run " + (dir.path() / "bad.toml").string() + " -q --out " +
                                                          out.string());
        EXPECT_EQ(r.exit_code, 2) << b.line << "\n" << r.output;
        EXPECT_NE(r.output.find(b.named), std::string::npos) << b.line << "\n" << r.output;
        EXPECT_FALSE(std::filesystem::exists(out)) << b.line;  // no partial output
    }
}

// The number after `what` on the line of `output` that starts with `line`.
double number_after(const std::string& output, const std::string& line, const std::string& what) {
    const std::size_t at = output.find(line);
    if (at == std::string::npos) return NAN;
    const std::string row = output.substr(at, output.find('\n', at) - at);
    const std::size_t value = row.find(what);
    return value == std::string::npos ? NAN : std::stod(row.substr(value + what.size()));
}

TEST(StringsCases, ShowPrintsTheCaseAndEachStringAsRead) {
    const testing::CommandResult r = testing::run_cli("show guitar-chord");
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::string file = read_text(std::filesystem::path(FRETBUZZ_SOURCE_DIR) / "cases/bridges/guitar-chord.toml");
    EXPECT_EQ(r.output.substr(0, file.size()), file);  // the case as written, then comments
    EXPECT_NE(r.output.find("#   bridge.mode[2]: M = 0.4 kg, f = 850 Hz"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("#   string[1] A2: bridges/guitar-string.toml with string.T = 86.74, string.mu = "
                            "0.00426801, string.E_core_I_core = 0.0002069, obstacle.action_nut = 0.0002747"),
              std::string::npos) << r.output;
    const struct {
        const char* line;
        double hz;
    } notes[] = {{"#   string[0] E2:", 82.4069}, {"#   string[1] A2:", 110.0}, {"#   string[5] E4:", 329.6276}};
    for (const auto& n : notes) EXPECT_NEAR(number_after(r.output, n.line, "f1 = "), n.hz, 0.002 * n.hz) << n.line;
    // What it prints is still the case: it reads back to the same strings.
    const StringsCase printed = parse_strings_case({r.output, "shown.toml", DataSource::builtin()});
    EXPECT_EQ(printed.string_names.size(), 6u);

    const testing::CommandResult sitar = testing::run_cli("show sitar-taraf");
    ASSERT_EQ(sitar.exit_code, 0) << sitar.output;
    EXPECT_NE(sitar.output.find("#   string[0] main: sitar.toml turned end for end; f1 = 69.3"), std::string::npos)
        << sitar.output;
    EXPECT_NEAR(number_after(sitar.output, "#   string[2] Ni-low:", "f1 = "), 138.62 * 15.0 / 16.0, 0.01);
    // And a one-string case a strings case names, by its built-in path.
    const testing::CommandResult taraf = testing::run_cli("show bridges/taraf-string.toml");
    EXPECT_EQ(taraf.exit_code, 0) << taraf.output;
    EXPECT_NE(taraf.output.find("name = \"taraf-string\""), std::string::npos) << taraf.output;
}

TEST(StringsCases, ExportWritesAFolderThatRunsAndReadsItsOwnCopies) {
    const testing::ScratchDir dir("strings-export");
    const testing::CommandResult r = testing::run_cli("export sitar-taraf " + dir.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    for (const char* file : {"sitar-taraf.toml", "sitar.toml", "bridges/taraf-string.toml"})
        EXPECT_TRUE(std::filesystem::is_regular_file(dir.path() / file)) << file << "\n" << r.output;
    const auto read_exported = [&dir] {
        const std::filesystem::path path = dir.path() / "sitar-taraf.toml";
        return parse_strings_case(*read_strings_case_text(path.string()));
    };
    const StringsCase exported = read_exported(), builtin = parse_strings_case(*read_strings_case_text("sitar-taraf"));
    ASSERT_EQ(exported.strings.size(), builtin.strings.size());
    for (std::size_t s = 0; s < exported.strings.size(); ++s) {
        EXPECT_EQ(exported.strings[s].modes.frequency_hz, builtin.strings[s].modes.frequency_hz);
        EXPECT_EQ(exported.strings[s].initial_displacement, builtin.strings[s].initial_displacement);
        EXPECT_EQ(exported.strings[s].obstacle_height_m, builtin.strings[s].obstacle_height_m);
    }
    // The copy beside it is what the strings case reads: a pluck twice as deep there, twice here.
    const std::filesystem::path sitar = dir.path() / "sitar.toml";
    write_text(sitar, replaced(read_text(sitar), "amplitude = 1e-3       # m", "amplitude = 2e-3"));
    const StringsCase edited = read_exported();
    const std::vector<double>&q = edited.strings[0].initial_displacement, &q0 = builtin.strings[0].initial_displacement;
    for (std::size_t j = 0; j < 5; ++j) EXPECT_NEAR(q[j], 2.0 * q0[j], 1e-15 * std::abs(q0[0])) << j;

    const testing::ScratchDir guitar("strings-export-guitar");
    const testing::CommandResult g = testing::run_cli("export guitar-chord " + guitar.str());
    ASSERT_EQ(g.exit_code, 0) << g.output;
    EXPECT_TRUE(std::filesystem::is_regular_file(guitar.path() / "bridges/guitar-string.toml")) << g.output;
    const testing::CommandResult run = testing::run_cli("run " + (guitar.path() / "guitar-chord.toml").string() +
                                                        " --duration 0.002 -q --out " + (guitar.path() / "out").string());
    EXPECT_EQ(run.exit_code, 0) << run.output;
}

TEST(StringsCases, ReportPlotsEveryStringsEnergyAndTheBridges) {
    const testing::ScratchDir dir("strings-report");
    const testing::CommandResult r =
        testing::run_cli("run guitar-chord --duration 0.04 --report -q --out " + dir.str());
    ASSERT_EQ(r.exit_code, 0) << r.output;
    const std::filesystem::path png = dir.path() / "strings_energy.png";
    ASSERT_TRUE(std::filesystem::is_regular_file(png)) << r.output;
    EXPECT_GT(std::filesystem::file_size(png), 20000u);
    // The figure's legend, as the plot wrote it into the PNG: every string, then the bridge.
    EXPECT_NE(read_text(png).find("curves: E2, A2, D3, G3, B3, E4, bridge"), std::string::npos);
    const std::string page = read_text(dir.path() / "report.html");
    EXPECT_NE(page.find("id=\"fig-strings-energy\"><img"), std::string::npos);
    EXPECT_NE(page.find("src=\"data:image/png;base64,"), std::string::npos);
    std::size_t players = 0;
    for (std::size_t at = page.find("<audio controls"); at != std::string::npos; at = page.find("<audio controls", at + 1))
        ++players;
    EXPECT_EQ(players, 7u);  // the bridge and six pickups
    for (const char* name : {"E2", "A2", "D3", "G3", "B3", "E4"})
        EXPECT_NE(page.find("String " + std::string(name) + " at its pickup"), std::string::npos) << name;
    EXPECT_NE(page.find("Strings on the bridge</th><td>E2; A2; D3; G3; B3; E4"), std::string::npos);
    EXPECT_NE(page.find("set.string.T = 86.74"), std::string::npos);  // the case file
}

}  // namespace
}  // namespace fretbuzz
