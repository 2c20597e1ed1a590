// Individual fret heights (obstacle.frets.height_offsets): an offset moves exactly one fret
// top by exactly that much, leaves the board and every other fret alone, is range-checked
// naming the entry, and a sweep sets one fret through the key height_offsets.N.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "SweepTestCases.hpp"
#include "TestSupport.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/sweep/Sweep.hpp"

namespace fretbuzz {
namespace {

using testing::ScratchDir;
using testing::write_text;

// bass-neck with extra lines in its [obstacle.frets] table.
std::string neck_with(const std::string& fret_lines) {
    std::string text = builtin_case_text("bass-neck");
    const std::string anchor = "crown_width = 0.0\n";
    text.insert(text.find(anchor) + anchor.size(), fret_lines);
    return text;
}

Case parse(const std::string& text) { return parse_case(text, "neck.toml", DataSource::builtin()); }

std::size_t nearest_point(const Case& c, double x) {
    return static_cast<std::size_t>(std::lround(x / c.grid_step())) - 1;
}

double fret_x(int n) { return 0.863 * (1.0 - std::exp2(-n / 12.0)); }

TEST(FretHeights, AnOffsetMovesOneFretTopByItsValueAndNothingElse) {
    const Case nominal = parse(neck_with(""));
    const Case changed = parse(neck_with("height_offsets = { 9 = 0.05e-3, 14 = -0.2e-3 }\n"));
    const std::size_t at9 = nearest_point(nominal, fret_x(9)), at14 = nearest_point(nominal, fret_x(14));
    // (crowns of zero width are exact points: on the grid, each on its nearest grid point)
    const std::vector<double> g_nominal = nominal.obstacle_on_grid(), g_changed = changed.obstacle_on_grid();
    ASSERT_EQ(g_nominal.size(), g_changed.size());
    EXPECT_EQ(nominal.obstacle_height_m, changed.obstacle_height_m);  // the board is unchanged
    for (std::size_t i = 0; i < g_nominal.size(); ++i) {
        const double moved = g_changed[i] - g_nominal[i];
        if (i == at9)
            EXPECT_NEAR(moved, 0.05e-3, 1e-18);
        else if (i == at14)
            EXPECT_NEAR(moved, -0.2e-3, 1e-18);
        else
            EXPECT_EQ(moved, 0.0) << "grid point " << i;
    }
    // The worn fret still stands above the board (1.2 mm fret height).
    EXPECT_GT(g_changed[at14], g_changed[at14 - 5] + 0.9e-3);
    EXPECT_EQ(changed.fret_positions_m.size(), nominal.fret_positions_m.size());
}

TEST(FretHeights, OffsetsOutOfRangeAreRefusedNamingTheEntry) {
    const struct {
        std::string lines, named;
    } bad[] = {{"height_offsets = { 9 = 2e-3 }\n", "obstacle.frets.height_offsets.9"},
               {"height_offsets = { 9 = -1.3e-3 }\n", "obstacle.frets.height_offsets.9"},
               {"height_offsets = { 21 = 1e-5 }\n", "obstacle.frets.height_offsets.21"},
               {"height_offsets = { 0 = 1e-5 }\n", "obstacle.frets.height_offsets.0"},
               {"height_offsets = { twelve = 1e-5 }\n", "obstacle.frets.height_offsets.twelve"},
               {"height_offsets = { 9 = \"high\" }\n", "obstacle.frets.height_offsets.9"},
               {"height_offsets = 1e-5\n", "obstacle.frets.height_offsets"}};
    for (const auto& b : bad) {
        try {
            parse(neck_with(b.lines));
            ADD_FAILURE() << b.lines << " accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(b.named), std::string::npos) << e.what();
        }
    }
    // From the command line: exit status 2, the key named, nothing written.
    ScratchDir dir("fret-heights");
    write_text(dir.path() / "bad.toml", neck_with("height_offsets = { 9 = 2e-3 }\n"));
    const auto r = testing::run_cli("run " + (dir.path() / "bad.toml").string() + " --out " +
                                    (dir.path() / "out").string());
    EXPECT_EQ(r.exit_code, 2) << r.output;
    EXPECT_NE(r.output.find("obstacle.frets.height_offsets.9"), std::string::npos) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out"));
}

TEST(FretHeights, ASweepSetsOneFretThroughItsKey) {
    ScratchDir dir("fret-heights-sweep");
    write_text(dir.path() / "neck.toml", neck_with("height_offsets = { 14 = -0.2e-3 }\n"));
    write_text(dir.path() / "spec.toml",
               "[sweep]\ncase = \"neck.toml\"\n[[parameter]]\nkey = \"obstacle.frets.height_offsets.9\"\n"
               "values = [0.0, 0.05e-3]\n");
    const SweepSpec spec = load_sweep(dir.path() / "spec.toml");
    ASSERT_EQ(spec.runs.size(), 2u);
    // The sweep adds fret 9 to the case's own offsets, exactly as the case file would.
    const Case swept = sweep_case(spec, spec.runs[1]);
    const Case direct = parse(neck_with("height_offsets = { 14 = -0.2e-3, 9 = 0.05e-3 }\n"));
    EXPECT_EQ(swept.obstacle_on_grid(), direct.obstacle_on_grid());
    const Case zero = sweep_case(spec, spec.runs[0]);
    EXPECT_EQ(zero.obstacle_on_grid(), parse(neck_with("height_offsets = { 14 = -0.2e-3 }\n")).obstacle_on_grid());
    // A whole table as a value too (what the set-up study writes per note).
    write_text(dir.path() / "spec2.toml",
               "[sweep]\ncase = \"neck.toml\"\n[[parameter]]\nkey = \"obstacle.frets.height_offsets\"\n"
               "values = [{ 9 = 0.05e-3 }, {}]\n");
    const SweepSpec tables = load_sweep(dir.path() / "spec2.toml");
    EXPECT_EQ(sweep_case(tables, tables.runs[0]).obstacle_on_grid(),
              parse(neck_with("height_offsets = { 9 = 0.05e-3 }\n")).obstacle_on_grid());
    EXPECT_EQ(sweep_case(tables, tables.runs[1]).obstacle_on_grid(), parse(neck_with("")).obstacle_on_grid());
    // Out of range through the sweep: refused before anything runs, naming the key.
    write_text(dir.path() / "spec3.toml",
               "[sweep]\ncase = \"neck.toml\"\n[[parameter]]\nkey = \"obstacle.frets.height_offsets.25\"\n"
               "values = [1e-5]\n");
    try {
        check_sweep(load_sweep(dir.path() / "spec3.toml"));
        ADD_FAILURE() << "fret 25 accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("height_offsets.25"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace fretbuzz
