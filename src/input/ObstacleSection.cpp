// [obstacle]: the obstacle profile g(x) sampled on the interior grid. A case may list
// several ([[obstacle]]); the caller combines them by their maximum (their minimum when
// they lie above the string, side = "above"; heights are then where the string's top
// meets them, and contact is where u > g).
#include <cmath>

#include "CaseSections.hpp"
#include "FretboardSection.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"
#include "fretbuzz/geometry/ParabolicBridge.hpp"
#include "fretbuzz/geometry/SimpleObstacles.hpp"

namespace fretbuzz {

namespace {

// A position along the string, checked to lie in [0, L].
double position_on_string(TomlSection& s, std::string_view key, double length) {
    const double x = s.number(key);
    if (!(x >= 0.0 && x <= length))
        throw InputError(out_of_range_message(s.key_path(key), x, "must lie on the string, in [0, L] = [0, " +
                                                                      std::to_string(length) + "] m"));
    return x;
}

// Obstacle heights are m above the string's rest line: a few cm either way is plenty.
double obstacle_height(TomlSection& s, std::string_view key) {
    const double h = s.number(key);
    if (!(std::abs(h) <= 0.1))
        throw InputError(out_of_range_message(s.key_path(key), h, "must be in [-0.1, 0.1] m"));
    return h;
}

std::vector<double> read_table(TomlSection& s, const DataSource& data, const Grid& grid) {
    const CsvTable table = read_section_table(s, "file", data, 2);
    try {
        return sample_profile_on_grid(table.column(0), table.column(1), grid, table.source);
    } catch (const InputError& e) {
        throw InputError(s.key_path("file") + ": " + e.what());
    }
}

std::vector<double> read_flat(TomlSection& s, const Grid& grid) {
    const double height = obstacle_height(s, "height");
    const double start = s.has("start") ? position_on_string(s, "start", grid.length_m) : 0.0;
    const double end = s.has("end") ? position_on_string(s, "end", grid.length_m) : grid.length_m;
    if (!(end > start))
        throw InputError(out_of_range_message(s.key_path("end"), end, "must exceed " + s.key_path("start")));
    return flat_obstacle(grid, height, start, end);
}

// The points at their exact positions, each acting over `width` of string (default: the
// case's grid step, the length a grid point stands for).
std::vector<PointObstacle> read_point_list(TomlSection& s, const Grid& grid) {
    const std::vector<double> x = s.numbers("x");
    std::vector<double> heights = s.numbers("height");
    if (heights.size() == 1) heights.resize(x.size(), heights.front());
    if (heights.size() != x.size())
        throw InputError(s.key_path("height") + " has " + std::to_string(heights.size()) + " values but " +
                         s.key_path("x") + " has " + std::to_string(x.size()) + ": give one height, or one per point");
    const double width = s.optional_positive("width").value_or(grid.step());
    if (!(width <= grid.length_m))
        throw InputError(out_of_range_message(s.key_path("width"), width, "must be in (0, L] m"));
    std::vector<PointObstacle> points;
    for (std::size_t k = 0; k < x.size(); ++k) {
        const std::string item = std::string("[").append(std::to_string(k)).append("]");
        if (!(x[k] > 0.0 && x[k] < grid.length_m))
            throw InputError(
                out_of_range_message(s.key_path("x").append(item), x[k], "must lie inside the string, in (0, L)"));
        if (!(std::abs(heights[k]) <= 0.1))
            throw InputError(
                out_of_range_message(s.key_path("height").append(item), heights[k], "must be in [-0.1, 0.1] m"));
        points.push_back({x[k], heights[k], width});
    }
    return points;
}

std::vector<double> read_points(TomlSection& s, const Grid& grid) {
    std::vector<double> x, heights;
    for (const PointObstacle& p : read_point_list(s, grid)) {
        x.push_back(p.x_m);
        heights.push_back(p.height_m);
    }
    return point_obstacles(grid, x, heights);
}

std::vector<double> read_bridge(TomlSection& s, const Grid& grid) {
    ParabolicBridge bridge;
    bridge.position_m = position_on_string(s, "position", grid.length_m);
    bridge.length_m = s.positive("length");
    if (bridge.position_m + bridge.length_m > grid.length_m * (1.0 + 1e-12))
        throw InputError(out_of_range_message(s.key_path("length"), bridge.length_m,
                                              "must keep the bridge on the string: position + length <= L"));
    bridge.height_m = obstacle_height(s, "height");
    bridge.curvature_per_m = s.non_negative("curvature");
    bridge.apex_m = bridge.position_m;
    if (s.has("apex")) {
        bridge.apex_m = s.number("apex");
        if (!(bridge.apex_m >= bridge.position_m && bridge.apex_m <= bridge.position_m + bridge.length_m))
            throw InputError(out_of_range_message(s.key_path("apex"), bridge.apex_m,
                                                  "must lie on the bridge, in [position, position + length]"));
    }
    return bridge.sample(grid);
}

}  // namespace

std::string to_string(ObstacleSide side) { return side == ObstacleSide::above ? "above" : "below"; }

ObstacleSide read_obstacle_side(TomlSection& section) {
    const std::string side = section.optional_text("side").value_or("below");
    if (side == "below") return ObstacleSide::below;
    if (side == "above") return ObstacleSide::above;
    throw InputError(section.key_path("side") + " = \"" + side + "\": must be \"below\" (the default: contact where "
                     "u < g) or \"above\" (contact where u > g)");
}

bool is_point_section(TomlSection& section) { return section.text("type") == "points"; }

std::vector<PointObstacle> read_point_section(TomlSection& section, const Case& c) {
    return read_point_list(section, Grid{c.string.length_m, c.mode_count()});
}

std::vector<double> read_obstacle_section(TomlSection& section, const DataSource& data, const Case& c,
                                          std::vector<PointObstacle>& points, std::vector<double>& frets) {
    const std::string type = section.text("type");
    const Grid grid{c.string.length_m, c.mode_count()};
    if (type == "none") return no_obstacle(grid);
    if (type == "table") return read_table(section, data, grid);
    if (type == "flat") return read_flat(section, grid);
    if (type == "points") return read_points(section, grid);
    if (type == "bridge") return read_bridge(section, grid);
    if (type == "fretboard") return read_fretboard(section, grid, points, frets);
    throw InputError(section.key_path("type") + " = \"" + type +
                     "\": must be one of \"table\", \"flat\", \"points\", \"bridge\", \"fretboard\", \"none\"");
}

}  // namespace fretbuzz
