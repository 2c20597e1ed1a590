// Case files: every form of [modes], [obstacle] and [excitation] parses to the Case it
// describes, and every mistake is an InputError that names the key at fault.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/CsvTable.hpp"

namespace fretbuzz {
namespace {

// A small valid case; tests replace one line at a time.
const std::string kBase = R"(name = "schema"
[string]
L = 1.0
T = 100.0
mu = 1e-3
modes = 49
[modes.frequency]
model = "harmonic"
[modes.damping]
model = "none"
[obstacle]
type = "none"
[excitation]
type = "triangle"
position = 0.3
amplitude = 1e-3
[contact]
K = 1e10
alpha = 1.5
[run]
fs = 48000
duration = 0.1
[observe]
x = [0.5]
)";

std::string replaced(std::string text, const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << "test setup: '" << from << "' not in the case";
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

// A folder with the CSV files the case texts name.
class CaseFileSchema : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("fretbuzz-schema-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }
    Case parse(const std::string& text) const { return parse_case(text, "schema.toml", DataSource::directory(dir_)); }
    // Parses text expecting an InputError whose message contains every one of parts.
    void expect_error(const std::string& text, const std::vector<std::string>& parts) const {
        try {
            Case c = parse(text);
            c.validate();
            ADD_FAILURE() << "no error; expected one naming " << parts.front();
        } catch (const InputError& e) {
            const std::string message = e.what();
            for (const auto& part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
        }
    }
    std::filesystem::path dir_;
};

TEST_F(CaseFileSchema, BaseCaseIsValid) {
    const Case c = parse(kBase);
    c.validate();
    EXPECT_EQ(c.mode_count(), 49u);
    // Harmonic, lossless: nu_j = j c / 2L = j * sqrt(1e5) / 2.
    EXPECT_NEAR(c.modes.frequency_hz[2], 3.0 * std::sqrt(1e5) / 2.0, 1e-9);
    EXPECT_EQ(c.modes.sigma_per_s[2], 0.0);
    EXPECT_EQ(c.modes.source[2], ModeSource::model);
}

TEST_F(CaseFileSchema, UnknownKeysAreNamed) {
    expect_error(replaced(kBase, "mu = 1e-3", "mu = 1e-3\nTension = 3"), {"unknown key string.Tension"});
    expect_error(replaced(kBase, "model = \"none\"", "model = \"none\"\nsigma = 1"),
                 {"unknown key modes.damping.sigma"});
    expect_error(replaced(kBase, "[obstacle]\ntype = \"none\"",
                          "[[obstacle]]\ntype = \"none\"\n[[obstacle]]\ntype = \"flat\"\nheight = -1e-3\nheigth = 2"),
                 {"unknown key obstacle[1].heigth"});
    expect_error(replaced(kBase, "[obstacle]\ntype = \"none\"",
                          "[obstacle]\ntype = \"fretboard\"\naction_nut = 1e-3\naction_last_fret = 2e-3\n"
                          "[obstacle.frets]\ncount = 12\nheight = 1e-3\nhieght = 1"),
                 {"unknown key obstacle.frets.hieght"});
}

TEST_F(CaseFileSchema, MissingKeysAreNamed) {
    expect_error(replaced(kBase, "T = 100.0\n", ""), {"string.T is missing"});
    expect_error(replaced(kBase, "position = 0.3\n", ""), {"excitation.position is missing"});
    expect_error(replaced(kBase, "[modes.damping]\nmodel = \"none\"\n", ""), {"modes.damping is missing"});
    expect_error(replaced(kBase, "[obstacle]\ntype = \"none\"",
                          "[obstacle]\ntype = \"fretboard\"\naction_nut = 1e-3\naction_last_fret = 2e-3"),
                 {"obstacle.frets is missing"});
}

TEST_F(CaseFileSchema, NotANumberIsRejectedWithItsKey) {
    expect_error(replaced(kBase, "T = 100.0", "T = nan"), {"string.T", "finite"});
    expect_error(replaced(kBase, "amplitude = 1e-3", "amplitude = inf"), {"excitation.amplitude", "finite"});
}

TEST_F(CaseFileSchema, OutOfRangeValuesNameTheKeyAndTheRange) {
    expect_error(replaced(kBase, "T = 100.0", "T = -100.0"), {"string.T", "must be > 0"});
    expect_error(replaced(kBase, "modes = 49", "modes = 49.5"), {"string.modes", "whole number in [1, 100000]"});
    expect_error(replaced(kBase, "alpha = 1.5", "alpha = 0.5"), {"contact.alpha", ">= 1"});
    expect_error(replaced(kBase, "x = [0.5]", "x = [1.5]"), {"observe.x[0]", "(0, L)"});
    expect_error(replaced(kBase, "position = 0.3", "position = 1.3"), {"excitation.position", "(0, L)"});
    expect_error(replaced(kBase, "type = \"triangle\"", "type = \"rounded-triangle\"\nwidth = 0.7"),
                 {"excitation.width", "inside (0, L)"});
    expect_error(replaced(kBase, "mu = 1e-3", "mu = 1e-3\nB = -1e-5"), {"string.B", ">= 0"});
    expect_error(replaced(kBase, "model = \"none\"", "model = \"physical\"\nd_eq = 1e-3\ndelta_ve = -0.1"),
                 {"modes.damping.delta_ve", ">= 0"});
    expect_error(replaced(kBase, "[obstacle]\ntype = \"none\"",
                          "[obstacle]\ntype = \"fretboard\"\naction_nut = 1e-3\naction_last_fret = 2e-3\n"
                          "[obstacle.frets]\ncount = 12\nheight = -1e-3"),
                 {"obstacle.frets.height", "must be > 0"});
    expect_error(replaced(kBase, "[obstacle]\ntype = \"none\"",
                          "[obstacle]\ntype = \"bridge\"\nposition = 0.99\nlength = 0.05\nheight = 0\ncurvature = 1"),
                 {"obstacle.length", "position + length <= L"});
    expect_error(replaced(kBase, "type = \"none\"", "type = \"wall\""), {"obstacle.type", "\"fretboard\""});
}

TEST_F(CaseFileSchema, ModelsNeedTheStringPropertiesTheyUse) {
    expect_error(replaced(kBase, "model = \"harmonic\"", "model = \"inharmonic\""),
                 {"modes.frequency.model", "string.B"});
    expect_error(replaced(kBase, "model = \"none\"", "model = \"physical\""), {"modes.damping.d_eq"});
    expect_error(replaced(kBase, "model = \"none\"", "model = \"physical\"\nd_eq = 1e-3\ndelta_ve = 0.01"),
                 {"modes.damping.delta_ve", "string.E_core_I_core"});
}

TEST_F(CaseFileSchema, MalformedCsvNamesTheKeyAndTheLine) {
    write("modes.csv", "# mode,frequency_hz,sigma_per_s\n1,100,0.1\n2,abc,0.2\n");
    expect_error(replaced(kBase, "[modes.frequency]", "[modes]\nmeasured = \"modes.csv\"\n[modes.frequency]"),
                 {"modes.measured", "modes.csv:3"});
    write("short.csv", "1,100\n");
    expect_error(replaced(kBase, "[modes.frequency]", "[modes]\nmeasured = \"short.csv\"\n[modes.frequency]"),
                 {"modes.measured", "at least 3 columns"});
}

TEST_F(CaseFileSchema, MissingFileNamesTheKey) {
    expect_error(replaced(kBase, "[modes.frequency]", "[modes]\nmeasured = \"absent.csv\"\n[modes.frequency]"),
                 {"modes.measured = \"absent.csv\"", "cannot read"});
    expect_error(replaced(kBase, "type = \"none\"", "type = \"table\"\nfile = \"absent.csv\""),
                 {"obstacle.file = \"absent.csv\""});
}

TEST_F(CaseFileSchema, FullTableCannotBeMixedWithModels) {
    write("all.csv", "1,100,0.1\n");
    expect_error(replaced(kBase, "[modes.frequency]", "[modes]\ntable = \"all.csv\"\n[modes.frequency]"),
                 {"modes.table", "modes.frequency"});
}

TEST_F(CaseFileSchema, MeasuredModesOverrideTheModelsUpToTheGivenMode) {
    write("measured.csv", "# mode,frequency_hz,sigma_per_s\n1,51,0.5\n2,101,0.6\n3,152,0.7\n");
    const std::string measured = "[modes]\nmeasured = \"measured.csv\"\nmeasured_up_to = 2\n[modes.frequency]";
    const Case c = parse(replaced(kBase, "[modes.frequency]", measured));
    EXPECT_EQ(c.modes.frequency_hz[0], 51.0);
    EXPECT_EQ(c.modes.sigma_per_s[1], 0.6);
    EXPECT_EQ(c.modes.source[1], ModeSource::measured);
    // Mode 3 is past measured_up_to: the harmonic model, lossless.
    EXPECT_NEAR(c.modes.frequency_hz[2], 1.5 * std::sqrt(1e5), 1e-9);
    EXPECT_EQ(c.modes.source[2], ModeSource::model);
}

TEST_F(CaseFileSchema, NutMobilityFileFeedsBothModels) {
    // Constant Y_s = 1e-4 + 2e-4 i over the whole band, on a string with c = sqrt(1e5) = 316.23 m/s.
    write("nut.csv", "# frequency_hz,re,im\n0,1e-4,2e-4\n1e6,1e-4,2e-4\n");
    const std::string text = replaced(
        replaced(replaced(kBase, "[modes.frequency]", "[modes]\nnut_mobility = \"nut.csv\"\n[modes.frequency]"),
                 "model = \"harmonic\"", "model = \"inharmonic\""),
        "mu = 1e-3", "mu = 1e-3\nB = 0.0\nd = 1e-3");
    const Case c = parse(replaced(text, "model = \"none\"", "model = \"physical\"\neta_air = 1e-30"));
    const double c0 = std::sqrt(1e5), nu01 = c0 / 2.0;
    // nu_1 = nu_01 (1 + mu c Im Y / pi)
    EXPECT_NEAR(c.modes.frequency_hz[0], nu01 * (1.0 + 1e-3 * c0 * 2e-4 / std::numbers::pi), 1e-12);
    // sigma_1 = pi nu_1 (mu c^2 Re Y / (pi L nu_1)) = T Re Y / L = 100 * 1e-4 = 0.01 1/s (air ~ 0);
    // the same for every mode: the nut term alone gives a constant damping.
    EXPECT_NEAR(c.modes.sigma_per_s[0], 0.01, 1e-6);
    EXPECT_NEAR(c.modes.sigma_per_s[40], 0.01, 1e-6);
}

TEST_F(CaseFileSchema, ObstaclesAreCombinedByTheirMaximum) {
    const Case c = parse(replaced(kBase, "[obstacle]\ntype = \"none\"",
                                  "[[obstacle]]\ntype = \"flat\"\nheight = -2e-3\n"
                                  "[[obstacle]]\ntype = \"points\"\nx = [0.1, 0.9]\nheight = -1e-3"));
    // The points keep their exact positions beside the flat barrier; on the grid,
    // x_i = (i + 1) / 50: 0.1 is i = 4, 0.9 is i = 44.
    ASSERT_EQ(c.point_obstacles.size(), 2u);
    EXPECT_EQ(c.point_obstacles[0].x_m, 0.1);
    EXPECT_EQ(c.point_obstacles[1].x_m, 0.9);
    EXPECT_EQ(c.obstacle_height_m[4], -2e-3);
    const std::vector<double> on_grid = c.obstacle_on_grid();
    EXPECT_EQ(on_grid[4], -1e-3);
    EXPECT_EQ(on_grid[44], -1e-3);
    EXPECT_EQ(on_grid[20], -2e-3);
}

TEST_F(CaseFileSchema, ShapeFileIsSampledOnTheGrid) {
    write("shape.csv", "# x_m,displacement_m\n0,0\n0.5,1e-3\n1,0\n");
    const Case c = parse(replaced(kBase, "type = \"triangle\"\nposition = 0.3\namplitude = 1e-3",
                                  "type = \"shape\"\nfile = \"shape.csv\""));
    const Case triangle = parse(replaced(kBase, "position = 0.3", "position = 0.5"));
    for (std::size_t j = 0; j < c.mode_count(); ++j)
        EXPECT_NEAR(c.initial_displacement[j], triangle.initial_displacement[j], 1e-15);
}

TEST_F(CaseFileSchema, InitialShapeBelowTheObstacleIsRejected) {
    expect_error(replaced(kBase, "type = \"none\"", "type = \"flat\"\nheight = 0.5e-3"), {"penetrates the obstacle"});
}

}  // namespace
}  // namespace fretbuzz
