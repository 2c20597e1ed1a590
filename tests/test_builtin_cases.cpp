// The shipped cases: each loads, passes Case::validate (so its initial shape clears its
// obstacle), and the bass mode table is the published data; `fretbuzz modes` prints it.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/CsvTable.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {
namespace {

CsvTable builtin_csv(const std::string& name, std::size_t columns) {
    const auto text = find_builtin_file(name);
    EXPECT_TRUE(text.has_value()) << name;
    return parse_csv(text.value_or(""), name, columns);
}

TEST(BuiltinCases, EveryShippedCaseLoadsAndValidates) {
    for (const std::string name : {"bass-pop", "bass-fretless", "bass-pluck", "tanpura", "sitar", "guitar-point",
                                   "flat-obstacle"}) {
        SCOPED_TRACE(name);
        ASSERT_TRUE(is_builtin_case(name));
        const Case c = load_case(name);
        EXPECT_NO_THROW(c.validate());
    }
}

TEST(BuiltinCases, BassPopModeTableIsThePublishedData) {
    const Case c = load_case("bass-pop");
    const CsvTable data = builtin_csv("data/bass_fretted_modes.csv", 3);
    ASSERT_EQ(c.mode_count(), data.row_count());
    for (std::size_t j = 0; j < c.mode_count(); ++j) {
        EXPECT_EQ(c.modes.frequency_hz[j], data.rows[j][1]) << "mode " << j + 1;
        EXPECT_EQ(c.modes.sigma_per_s[j], data.rows[j][2]) << "mode " << j + 1;
    }
}

TEST(BuiltinCases, FretlessBassUsesTheFrettedPluckAndItClearsTheBareNeck) {
    const Case fretless = load_case("bass-fretless");
    const Case fretted = load_case("bass-pop");
    EXPECT_EQ(fretless.initial_displacement, fretted.initial_displacement);
    EXPECT_EQ(fretless.obstacle_height_m, builtin_csv("data/bass_fretless_obstacle.csv", 2).column(1));
    EXPECT_NO_THROW(fretless.validate());
}

TEST(BuiltinCases, SitarAndTanpuraUseTheModels) {
    for (const std::string name : {"sitar", "tanpura"}) {
        const Case c = load_case(name);
        for (ModeSource s : c.modes.source) EXPECT_EQ(s, ModeSource::model) << name;
        // Stiff strings: partial 100 lies above 100 nu_1; damping grows with the mode number.
        EXPECT_GT(c.modes.frequency_hz[99], 100.0 * c.modes.frequency_hz[0]) << name;
        EXPECT_GT(c.modes.sigma_per_s[99], c.modes.sigma_per_s[9]) << name;
    }
    // The sitar's f1 = 69.3 Hz (van Walstijn et al.), within its small stiffness shift.
    EXPECT_NEAR(load_case("sitar").modes.frequency_hz[0], 69.3, 0.1);
}

TEST(BuiltinCases, BassPluckNeverTouchesTheFrets) {
    Case c = load_case("bass-pluck");
    c.run.duration_s = 0.05;
    const RunSummary summary = simulate(c, {});
    EXPECT_EQ(summary.contact_steps, 0);
    EXPECT_EQ(summary.steps, 50000);
    EXPECT_GT(summary.energy_initial_j, 0.0);
}

TEST(BuiltinCases, ModesCommandPrintsTheTableAsCsv) {
    const std::string command = std::string(FRETBUZZ_CLI) + " modes bass-pop";
    std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
    ASSERT_TRUE(pipe);
    std::string output;
    std::array<char, 4096> buffer{};
    while (std::fgets(buffer.data(), static_cast<int>(buffer.size()), pipe.get()) != nullptr) output += buffer.data();
    std::istringstream lines(output);
    std::string line;
    std::getline(lines, line);
    EXPECT_EQ(line, "mode,frequency_hz,sigma_per_s,source");
    std::getline(lines, line);
    EXPECT_EQ(line, "1,97.973197978806198,0.196419030327801,measured");
    std::size_t rows = 1;
    while (std::getline(lines, line)) ++rows;
    EXPECT_EQ(rows, 862u);
}

}  // namespace
}  // namespace fretbuzz
