// The hazards and case-format gaps of issue 17: modes aliasing under contact are refused
// (or warned about, naming them), new case keys each drive a run, an obstacle above is
// the exact mirror of one below, and the bridge force follows its closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"

namespace fretbuzz {
namespace {

using std::numbers::pi;

// An ideal string (L = 1 m, T = 200 N, mu = 1e-3 kg/m: f1 = 100 sqrt(5) = 223.607 Hz) over a
// flat barrier 1 mm below it, plucked up at 0.3 m. At fs = 176.4 kHz mode 788 is 197.7 Hz
// below fs and mode 789 25.9 Hz above it.
std::string flat_barrier(std::size_t modes, const std::string& extra_run = "") {
    return R"(name = "flat-barrier"
[string]
L = 1.0
T = 200.0
mu = 1e-3
modes = )" + std::to_string(modes) +
           R"(
ideal = true
[obstacle]
type = "flat"
height = -1e-3
[excitation]
type = "triangle"
position = 0.3
amplitude = 2e-3
[contact]
K = 1e12
alpha = 1.5
[run]
fs = 176400
duration = 0.002
lossless = true
)" + extra_run + R"(
[observe]
x = [0.7]
)";
}

Case parse(const std::string& text) { return parse_case(text, "test.toml", DataSource::builtin()); }

std::string message_of(const std::string& text) {
    try {
        const Case c = parse(text);
        simulate(c, {});
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

struct Recorder : RunObserver {
    std::vector<double> u, bridge, energies;
    std::vector<std::pair<std::size_t, double>> forces;
    void observation(double, std::span<const double> values) override { u.insert(u.end(), values.begin(), values.end()); }
    void bridge_force(double, double f) override { bridge.push_back(f); }
    void energy(double, double h, double, double) override { energies.push_back(h); }
    void contacts(double, std::span<const std::pair<std::size_t, double>> f) override {
        forces.insert(forces.end(), f.begin(), f.end());
    }
};

RunSummary run(const Case& c, Recorder& recorder) {
    RunObserver* observers[] = {&recorder};
    return simulate(c, observers);
}

TEST(Aliasing, AModeNearFsIsRefusedNamingIt) {
    const std::string error = message_of(flat_barrier(789));
    EXPECT_NE(error.find("mode 789"), std::string::npos) << error;
    EXPECT_NE(error.find("run.allow_aliasing"), std::string::npos) << error;
    EXPECT_NE(error.find("at most 788 modes"), std::string::npos) << error;
    // 800 modes: 789..800 all lie within 111.8 Hz (half of f1) of fs? No: only those whose
    // alias is that small; 789 is the first of them.
    EXPECT_NE(message_of(flat_barrier(800)).find("mode 789"), std::string::npos);
}

TEST(Aliasing, AllowedAliasingRunsAndKeepsTheWarningInTheSummary) {
    Recorder r;
    const RunSummary s = run(parse(flat_barrier(789, "allow_aliasing = true")), r);
    ASSERT_FALSE(s.warnings.empty());
    bool named = false;
    for (const std::string& w : s.warnings) named = named || w.find("mode 789 (") != std::string::npos;
    EXPECT_TRUE(named);
    EXPECT_GT(s.contact_steps, 0);
}

TEST(Aliasing, ModesAboveHalfFsAreWarnedAbout) {
    // 788 modes: modes 395..788 lie above fs/2 = 88.2 kHz (395 f1 = 88.3 kHz) but none
    // within f1/2 of fs: allowed, with a warning naming them.
    Recorder r;
    const RunSummary s = run(parse(flat_barrier(788)), r);
    ASSERT_EQ(s.warnings.size(), 1u);
    EXPECT_NE(s.warnings[0].find("modes 395-788"), std::string::npos) << s.warnings[0];
    const SamplingReport report = check_sampling(parse(flat_barrier(788)).modes, 176400.0);
    EXPECT_EQ(report.above_nyquist.size(), 394u);
    EXPECT_TRUE(report.hazardous.empty());
    EXPECT_NEAR(report.above_nyquist.back().alias_hz, 176400.0 - 788.0 * 100.0 * std::sqrt(5.0), 1e-6);
    // All modes below fs/2: nothing to say.
    EXPECT_TRUE(check_sampling(parse(flat_barrier(394)).modes, 176400.0).warnings.empty());
}

TEST(Aliasing, BuiltinCasesKeepEveryModeBelowHalfFs) {
    for (const auto& info : builtin_cases()) {
        const Case c = load_case(info.name);
        if (!c.has_obstacle()) continue;
        const SamplingReport report = check_sampling(c.modes, c.run.sample_rate_hz);
        // bass-pluck never touches its frets (see its case file); the others must be clean.
        if (info.name == "bass-pluck") continue;
        EXPECT_TRUE(report.above_nyquist.empty()) << info.name << ": " << report.warnings.front();
        EXPECT_TRUE(c.warnings.empty()) << info.name << ": " << c.warnings.front();
    }
}

// Where nothing can touch the string (its free motion's envelope stays clear of the
// obstacle, and no finger or gesture acts), the modal update is exact at any fs: no
// aliasing warning or refusal. Where it can, the check is as before. The envelope is a
// bound: a case it calls free runs without a contact step.
TEST(Aliasing, ACaseThatCannotTouchIsNotWarnedAbout) {
    const Case pluck = load_case("bass-pluck");  // 0.5 mm, more than 0.3 mm clear of every fret
    EXPECT_FALSE(contact_possible(pluck));
    EXPECT_TRUE(Plan(pluck, 1.0 / pluck.run.sample_rate_hz).warnings().empty());
    EXPECT_TRUE(contact_possible(load_case("bass-pop")));
    EXPECT_TRUE(contact_possible(load_case("bass-fret5-pop")));  // a finger
    EXPECT_FALSE(Plan(load_case("bass-pop"), 1e-6).warnings().empty());
    // A flat barrier 1 mm below at 0.1 mm and 1 mm of pluck: too far, and in reach.
    for (const auto& [amplitude, possible] : {std::pair{"1e-4", false}, std::pair{"1e-3", true}}) {
        std::string text = flat_barrier(100);
        text.replace(text.find("amplitude = 2e-3"), 16, std::string("amplitude = ") + amplitude);
        const Case c = parse(text);
        EXPECT_EQ(contact_possible(c), possible) << amplitude;
        if (!possible) {
            EXPECT_EQ(simulate(c, {}).contact_steps, 0) << amplitude;
        }
    }
    // At 48 kHz bass-pluck runs every mode without refusal (modes alias onto low
    // frequencies only under contact, which cannot happen).
    const auto r = testing::run_cli("run bass-pluck --fs 48000 --duration 0.01 -q --out " +
                                    (std::filesystem::temp_directory_path() / "fretbuzz-test-pluck48k").string());
    EXPECT_EQ(r.exit_code, 0) << r.output;
    EXPECT_EQ(r.output.find("warning"), std::string::npos) << r.output;
    std::filesystem::remove_all(std::filesystem::temp_directory_path() / "fretbuzz-test-pluck48k");
}

TEST(StiffString, SitarUsesTheExactModelAndTheFirstOrderOneWarns) {
    const Case sitar = load_case("sitar");
    const double f1 = std::sqrt(14.68 / 9.865e-4) / (2.0 * 0.88);
    const double b = pi * pi * (2e11 * pi * std::pow(0.4e-3, 4) / 64.0) / (14.68 * 0.88 * 0.88);
    const double j = 439.0;
    EXPECT_NEAR(sitar.modes.frequency_hz.back() / (j * f1 * std::sqrt(1.0 + b * j * j)), 1.0, 1e-9);
    EXPECT_LT(sitar.modes.frequency_hz.back(), 0.5 * sitar.run.sample_rate_hz);

    std::string text = builtin_case_text("sitar");
    text.replace(text.find("model = \"inharmonic\""), 20, "model = \"inharmonic\"\nformula = \"first-order\"");
    const Case first_order = parse(text);
    ASSERT_EQ(first_order.warnings.size(), 1u);
    EXPECT_NE(first_order.warnings[0].find("modes.frequency.formula = \"first-order\""), std::string::npos)
        << first_order.warnings[0];
    // The first-order model puts 128 of the sitar's modes above fs/2 = 250 kHz.
    EXPECT_EQ(check_sampling(first_order.modes, first_order.run.sample_rate_hz).above_nyquist.size(), 128u);
}

// A lossless ideal string with one mode excited: everything has a closed form.
std::string single_mode(const std::string& modes_and_damping, const std::string& run_extra = "",
                        const std::string& obstacle = "type = \"none\"") {
    return R"(name = "sine"
[string]
L = 0.8
T = 100.0
mu = 1e-3
modes = 40
ideal = true
)" + modes_and_damping + R"(
[obstacle]
)" + obstacle + R"(
[excitation]
type = "sine"
mode = 3
amplitude = 1e-3
[contact]
K = 1e10
alpha = 1.5
[run]
fs = 200000
duration = 0.01
output_rate = 10000
)" + run_extra + R"(
[observe]
x = [0.3]
)";
}

TEST(CaseKeys, SineShapeOnAnIdealLosslessStringOscillatesAsItsMode) {
    Recorder r;
    const Case c = parse(single_mode("", "lossless = true"));
    EXPECT_DOUBLE_EQ(c.modes.frequency_hz[2], 3.0 * std::sqrt(1e5) / 1.6);
    EXPECT_EQ(c.modes.sigma_per_s[2], 0.0);
    run(c, r);
    const double w = 2.0 * pi * c.modes.frequency_hz[2];
    for (std::size_t k = 0; k < r.u.size(); ++k) {
        const double t = static_cast<double>(k) * 1e-4;
        EXPECT_NEAR(r.u[k], 1e-3 * std::sin(3.0 * pi * 0.3 / 0.8) * std::cos(w * t), 1e-15) << t;
    }
    // The bridge force of mode 3: F = -(-1)^3 A T k_3 cos(w t) (rigid end, no stiffness).
    const double k3 = 3.0 * pi / 0.8;
    for (std::size_t k = 0; k < r.bridge.size(); ++k) {
        const double t = static_cast<double>(k) * 1e-4;
        EXPECT_NEAR(r.bridge[k], 1e-3 * 100.0 * k3 * std::cos(w * t), 1e-12) << t;
    }
}

TEST(CaseKeys, BridgeForceOfAStiffStringIncludesTheBendingTerm) {
    const std::string stiff = R"([modes.frequency]
model = "inharmonic"
[modes.damping]
model = "none")";
    std::string text = single_mode(stiff);
    text.replace(text.find("ideal = true"), 12, "B = 1e-3");
    Recorder r;
    const Case c = parse(text);
    run(c, r);
    // F(0) = A (T k + EI k^3) for mode 3 (odd), EI = B T L^2 / pi^2.
    const double k3 = 3.0 * pi / 0.8, ei = 1e-3 * 100.0 * 0.64 / (pi * pi);
    EXPECT_NEAR(r.bridge.front() / (1e-3 * (100.0 * k3 + ei * k3 * k3 * k3)), 1.0, 1e-12);
}

TEST(CaseKeys, DampingLawGivesEtaZeroPlusEtaTwoKSquared) {
    Recorder r;
    const Case c = parse(single_mode("[modes.damping]\nmodel = \"law\"\neta0 = 1.5\neta2 = 2e-3"));
    for (std::size_t j = 1; j <= c.mode_count(); ++j) {
        const double k = static_cast<double>(j) * pi / 0.8;
        EXPECT_DOUBLE_EQ(c.modes.sigma_per_s[j - 1], 1.5 + 2e-3 * k * k) << j;
    }
    run(c, r);
    // One damped mode: u(t) = A e^{-sigma t} (cos wd t + sigma/wd sin wd t) at the point.
    const double s = c.modes.sigma_per_s[2], w = 2.0 * pi * c.modes.frequency_hz[2];
    const double wd = std::sqrt(w * w - s * s);
    const double t = 0.01;
    EXPECT_NEAR(r.u.back(), 1e-3 * std::sin(3.0 * pi * 0.3 / 0.8) * std::exp(-s * t) *
                                (std::cos(wd * t) + s / wd * std::sin(wd * t)),
                1e-15);
}

TEST(CaseKeys, IdealStringWithoutDampingNamesTheWaysOut) {
    const std::string error = message_of(single_mode(""));
    EXPECT_NE(error.find("modes.damping is missing"), std::string::npos) << error;
    EXPECT_NE(error.find("run.lossless = true"), std::string::npos) << error;
    EXPECT_NE(error.find("model = \"physical\", \"law\""), std::string::npos) << error;
    std::string stiff = single_mode("", "lossless = true");
    stiff.replace(stiff.find("ideal = true"), 12, "ideal = true\nB = 1e-4");
    EXPECT_NE(message_of(stiff).find("string.ideal = true means no bending stiffness"), std::string::npos);
}

TEST(CaseKeys, ModalFileHonoursItsModeColumn) {
    testing::ScratchDir dir("modal");
    const auto write_case = [&](const std::string& rows) {
        std::ofstream(dir.path() / "q.csv") << "mode,q\n" << rows;
        std::string text = single_mode("", "lossless = true");
        const std::string sine = "type = \"sine\"\nmode = 3\namplitude = 1e-3";
        text.replace(text.find(sine), sine.size(), "type = \"modal\"\nfile = \"q.csv\"");
        std::ofstream(dir.path() / "case.toml") << text;
        return (dir.path() / "case.toml").string();
    };
    // Rows out of order and fewer modes than the case: the rest start at rest.
    const Case c = load_case(write_case("5,2e-4\n2,-1e-4\n"));
    ASSERT_EQ(c.initial_displacement.size(), 40u);
    EXPECT_EQ(c.initial_displacement[1], -1e-4);
    EXPECT_EQ(c.initial_displacement[4], 2e-4);
    EXPECT_EQ(c.initial_displacement[0], 0.0);
    EXPECT_EQ(c.initial_displacement[39], 0.0);
    const auto error_of = [&](const std::string& rows) {
        try {
            load_case(write_case(rows));
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(error_of("2,1e-4\n2,1e-4\n").find("data row 2: mode 2 is listed twice"), std::string::npos);
    EXPECT_NE(error_of("41,1e-4\n").find("must be a whole number in [1, 40]"), std::string::npos);
    EXPECT_NE(error_of("1.5,1e-4\n").find("excitation.file"), std::string::npos);
}

TEST(ObstacleSide, ABarrierAboveIsTheMirrorOfOneBelow) {
    // The same problem written both ways: barrier 0.3 mm below, string plucked up 1 mm at
    // mode 1; and barrier 0.3 mm above, string plucked down. Motions are exact opposites.
    std::string below = single_mode("", "lossless = true", "type = \"flat\"\nheight = -3e-4");
    below.replace(below.find("mode = 3"), 8, "mode = 1");
    std::string above = single_mode("", "lossless = true", "type = \"flat\"\nheight = 3e-4\nside = \"above\"");
    above.replace(above.find("amplitude = 1e-3"), 16, "amplitude = -1e-3");
    above.replace(above.find("mode = 3"), 8, "mode = 1");
    Recorder down, up;
    const RunSummary s_below = run(parse(below), down);
    const RunSummary s_above = run(parse(above), up);
    ASSERT_GT(s_below.contact_steps, 0);
    EXPECT_EQ(s_above.contact_steps, s_below.contact_steps);
    ASSERT_EQ(up.u.size(), down.u.size());
    for (std::size_t k = 0; k < up.u.size(); ++k) EXPECT_EQ(up.u[k], -down.u[k]) << k;
    for (std::size_t k = 0; k < up.bridge.size(); ++k) EXPECT_EQ(up.bridge[k], -down.bridge[k]) << k;
    EXPECT_EQ(up.energies, down.energies);
    ASSERT_EQ(up.forces.size(), down.forces.size());
    for (std::size_t k = 0; k < up.forces.size(); ++k) {
        EXPECT_EQ(up.forces[k].first, down.forces[k].first);
        EXPECT_EQ(up.forces[k].second, -down.forces[k].second);
        EXPECT_LT(up.forces[k].second, 0.0);  // a barrier above pushes down
    }
}

TEST(ObstacleSide, RefusesMixedSidesAndAPenetratingStart) {
    std::string mixed = single_mode("", "lossless = true", "type = \"flat\"\nheight = -3e-4");
    mixed.replace(mixed.find("[obstacle]\n"), 11, "[[obstacle]]\n");
    mixed.replace(mixed.find("[excitation]"), 12,
                  "[[obstacle]]\ntype = \"flat\"\nheight = 3e-3\nside = \"above\"\n[excitation]");
    EXPECT_NE(message_of(mixed).find("same side of the string"), std::string::npos) << message_of(mixed);
    // Plucked 1 mm up into a barrier 0.3 mm above.
    const std::string into = single_mode("", "lossless = true", "type = \"flat\"\nheight = 3e-4\nside = \"above\"");
    EXPECT_NE(message_of(into).find("u(x, 0) <= g(x)"), std::string::npos) << message_of(into);
    const std::string typo = single_mode("", "lossless = true", "type = \"flat\"\nheight = 3e-4\nside = \"top\"");
    EXPECT_NE(message_of(typo).find("obstacle.side = \"top\""), std::string::npos) << message_of(typo);
}

// The second polarisation's measured table gets the checks of [modes]: a damping or a
// frequency too large for the step is refused before the run, naming the table, the mode and
// the column (it used to fail inside the run, exit 3, naming "the energy").
TEST(PolarisationY, ItsTableIsCheckedAsTheModeTableIs) {
    testing::ScratchDir scratch("y-table");
    std::string table = std::string(*find_builtin_file("data/bass_fretted_modes.csv"));
    const auto write_table = [&](const std::string& name, std::size_t column, const std::string& value) {
        std::string text = table;
        const std::size_t row = text.find("\n3,") + 1;
        std::size_t start = row;
        for (std::size_t c = 0; c < column; ++c) start = text.find(',', start) + 1;
        const std::size_t end = text.find_first_of(",\n", start);
        text.replace(start, end - start, value);
        std::ofstream(scratch.path() / name) << text;
    };
    write_table("sigma.csv", 2, "1e300");
    write_table("frequency.csv", 1, "1e300");
    std::string y = builtin_case_text("bass-pluck-y");
    y.replace(y.find("duration = 0.5"), 14, "duration = 0.001");
    for (const auto& [file, column] : {std::pair<std::string, std::string>{"sigma.csv", "sigma_per_s"},
                                       {"frequency.csv", "frequency_hz"}}) {
        const std::filesystem::path path = scratch.path() / ("y-" + file + ".toml");
        std::ofstream(path) << y << "\n[polarisation_y]\ntable = \"" << file << "\"\n";
        const auto r = testing::run_cli("run " + path.string() + " -q --out " + (scratch.path() / "o").string());
        EXPECT_EQ(r.exit_code, 2) << r.output;
        EXPECT_NE(r.output.find("polarisation_y.table mode 3 " + column + " = 1.0000000000000001e+300 is out of range"),
                  std::string::npos)
            << r.output;
        EXPECT_FALSE(std::filesystem::exists(scratch.path() / "o"));
    }
}

}  // namespace
}  // namespace fretbuzz
