// Obstacle generators: the fretboard against the published Jazz Bass neck, the parabolic
// bridge, point and flat obstacles and their union.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fretbuzz/geometry/Fretboard.hpp"
#include "fretbuzz/geometry/ParabolicBridge.hpp"
#include "fretbuzz/geometry/SimpleObstacles.hpp"
#include "fretbuzz/input/BuiltinFiles.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/CsvTable.hpp"

namespace fretbuzz {
namespace {

constexpr double kNothing = -std::numeric_limits<double>::infinity();

// The bass neck: 862 interior points, dx = 1 mm.
const Grid kBassGrid{0.863, 862};

// The measurements of the bass neck (see cases/bass-pluck.toml).
Fretboard bass_fretboard() {
    Fretboard board;
    board.scale_length_m = 0.863;
    board.fret_count = 20;
    board.fret_height_m = 1.2e-3;
    board.crown_width_m = 0.0;
    board.action_at_nut_m = 0.35e-3;
    board.action_at_last_fret_m = 2.34e-3;
    board.relief = NeckRelief::curve({0.178, 0.319, 0.4315, 0.5205}, {0.41e-3, 0.595e-3, 0.517e-3, 0.228e-3});
    board.board_end_m = 0.600;
    board.body_height_m = -10.08e-3;
    return board;
}

std::vector<double> published_bass_neck() {
    const auto text = find_builtin_file("data/bass_fretted_obstacle.csv");
    EXPECT_TRUE(text.has_value());
    return parse_csv(*text, "bass_fretted_obstacle.csv", 2).column(1);
}

// Grid indices that stand above both neighbours: the frets.
std::vector<std::size_t> peaks(const std::vector<double>& g) {
    std::vector<std::size_t> found;
    for (std::size_t i = 1; i + 1 < g.size(); ++i)
        if (g[i] > g[i - 1] + 1e-7 && g[i] > g[i + 1] + 1e-7) found.push_back(i);
    return found;
}

void expect_matches_published_neck(const std::vector<double>& generated) {
    const std::vector<double> published = published_bass_neck();
    ASSERT_EQ(generated.size(), published.size());
    const auto published_frets = peaks(published);
    const auto generated_frets = peaks(generated);
    ASSERT_EQ(published_frets.size(), 20u);
    ASSERT_EQ(generated_frets.size(), 20u);
    for (std::size_t n = 0; n < 20; ++n) {
        const auto a = static_cast<long>(published_frets[n]);
        const auto b = static_cast<long>(generated_frets[n]);
        EXPECT_LE(std::abs(a - b), 1) << "fret " << n + 1 << " position, in grid steps";
        EXPECT_NEAR(generated[generated_frets[n]], published[published_frets[n]], 0.05e-3) << "fret " << n + 1;
    }
    // Past the end of the fingerboard (x > 0.6 m) the body is 10.08 mm down.
    for (std::size_t i = 600; i < published.size(); ++i) EXPECT_DOUBLE_EQ(generated[i], published[i]);
}

TEST(ObstacleGeometry, FretsSitAtEqualTemperedPositions) {
    const Fretboard board = bass_fretboard();
    // x_12 = S / 2 (the octave), x_n = S (1 - 2^(-n/12)).
    EXPECT_DOUBLE_EQ(board.fret_position(12), 0.863 / 2.0);
    EXPECT_NEAR(board.fret_position(1), 0.863 * (1.0 - 1.0 / 1.0594630943592953), 1e-15);
    // The fret line passes through the actions at the nut and at the last fret.
    EXPECT_NEAR(board.fret_line_height(0.0), -0.35e-3, 1e-15);
    EXPECT_NEAR(board.fret_line_height(board.fret_position(20)), -2.34e-3, 1e-15);
}

TEST(ObstacleGeometry, FretboardReproducesThePublishedBassNeck) {
    expect_matches_published_neck(bass_fretboard().sample(kBassGrid));
}

TEST(ObstacleGeometry, BassPluckCaseBuildsThePublishedNeck) {
    // Its crowns are exact points: on the grid, each on its nearest grid point, as published.
    const Case c = load_case("bass-pluck");
    EXPECT_EQ(c.point_obstacles.size(), 20u);
    expect_matches_published_neck(c.obstacle_on_grid());
}

TEST(ObstacleGeometry, FretboardBoardLiesOneFretHeightBelowTheFretLine) {
    const std::vector<double> g = bass_fretboard().sample(kBassGrid);
    const Fretboard board = bass_fretboard();
    const std::size_t between_frets_1_and_2 = 70;  // x = 0.071 m
    EXPECT_NEAR(g[between_frets_1_and_2], board.fret_line_height(kBassGrid.x(between_frets_1_and_2)) - 1.2e-3, 1e-15);
}

TEST(ObstacleGeometry, ParabolicReliefBowsDeepestAtMidSpan) {
    const NeckRelief bow = NeckRelief::bow(0.3e-3);
    EXPECT_DOUBLE_EQ(bow.depth_at(0.25, 0.5), 0.3e-3);
    EXPECT_DOUBLE_EQ(bow.depth_at(0.125, 0.5), 4.0 * 0.3e-3 * 0.25 * 0.75);
    EXPECT_DOUBLE_EQ(bow.depth_at(0.0, 0.5), 0.0);
    EXPECT_DOUBLE_EQ(bow.depth_at(0.6, 0.5), 0.0);
}

TEST(ObstacleGeometry, WideCrownsCoverSeveralGridPoints) {
    Fretboard board = bass_fretboard();
    board.crown_width_m = 2.2e-3;  // +-1.1 mm around x_12 = 0.4315 m: the points at 0.431 and 0.432 m
    const std::vector<double> g = board.sample(kBassGrid);
    const double top = board.fret_line_height(board.fret_position(12));
    std::size_t on_top = 0;
    for (double h : g) on_top += h == top ? 1 : 0;
    EXPECT_EQ(on_top, 2u);
}

TEST(ObstacleGeometry, ParabolicBridgeFollowsItsCurvature) {
    // Sitar bridge: apex at x = 0, 25 mm long, kappa = 0.16 1/m: g(25 mm) = -0.08 * 0.025^2 = -50 um.
    const ParabolicBridge bridge{0.0, 0.025, 0.0, 0.16, 0.0};
    EXPECT_DOUBLE_EQ(bridge.height_at(0.0), 0.0);
    EXPECT_NEAR(bridge.height_at(0.025), -50e-6, 1e-18);
    EXPECT_EQ(bridge.height_at(0.026), kNothing);
    const Grid grid{1.0, 999};  // dx = 1 mm
    const std::vector<double> g = bridge.sample(grid);
    EXPECT_NEAR(g[9], -0.08 * 0.01 * 0.01, 1e-18);  // x = 10 mm
    EXPECT_EQ(g[25], kNothing);                      // x = 26 mm
}

TEST(ObstacleGeometry, PointsTakeTheNearestGridPointAndObstaclesCombineByTheirMaximum) {
    const Grid grid{1.0, 9};  // x_i = 0.1, 0.2, ..., 0.9
    const std::vector<double> points = point_obstacles(grid, {0.31, 0.74}, {-1e-3, 2e-3});
    EXPECT_EQ(points[2], -1e-3);  // 0.31 -> 0.3
    EXPECT_EQ(points[6], 2e-3);   // 0.74 -> 0.7
    EXPECT_EQ(points[0], kNothing);
    const std::vector<double> flat = flat_obstacle(grid, 0.0, 0.25, 0.65);
    EXPECT_EQ(flat[1], kNothing);
    EXPECT_EQ(flat[2], 0.0);
    EXPECT_EQ(flat[6], kNothing);
    const std::vector<double> both = highest_of({points, flat});
    EXPECT_EQ(both[2], 0.0);   // the flat surface is above the point at 0.3
    EXPECT_EQ(both[6], 2e-3);  // the point at 0.7 stands alone
    EXPECT_EQ(both[0], kNothing);
}

}  // namespace
}  // namespace fretbuzz
