// [excitation]: the initial state. Shapes given in space are projected on the modes with
// the scheme's own discrete transform (q = dx S^T u), so u(x_i, 0) is reproduced exactly;
// so are velocity fields. "sine" and "modal" give the modal amplitudes themselves.
#include <cmath>
#include <sstream>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/InitialShape.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"

namespace fretbuzz {

namespace {

constexpr double kMaxDisplacement = 0.05;  // m
constexpr double kMaxVelocity = 100.0;     // m/s

// q_j(0) from a file of (mode, q_j) rows: rows in any order, each mode 1..n at most once;
// modes not listed start at rest.
std::vector<double> read_modal_column(TomlSection& section, const DataSource& data, std::size_t n) {
    const CsvTable table = read_section_table(section, "file", data, 2);
    const std::string where = section.key_path("file") + " = \"" + section.text("file") + "\"";
    std::vector<double> q(n, 0.0);
    std::vector<bool> seen(n, false);
    for (std::size_t r = 0; r < table.row_count(); ++r) {
        const double mode = table.rows[r][0];
        const std::string at = where + " data row " + std::to_string(r + 1);
        if (!(mode == std::floor(mode) && mode >= 1.0 && mode <= static_cast<double>(n)))
            throw InputError(out_of_range_message(at + " mode", mode,
                                                  "must be a whole number in [1, " + std::to_string(n) +
                                                      "] (string.modes = " + std::to_string(n) + ")"));
        const auto j = static_cast<std::size_t>(mode) - 1;
        if (seen[j]) throw InputError(at + ": mode " + std::to_string(j + 1) + " is listed twice");
        seen[j] = true;
        q[j] = table.rows[r][1];
        require_finite(at + " q", q[j]);
    }
    return q;
}

// u(x, 0) = amplitude sin(j pi x / L): mode j alone, q_j = amplitude sqrt(L/2).
std::vector<double> read_sine(TomlSection& s, std::size_t n, double length) {
    const std::size_t mode = s.count("mode", 1, n);
    const double amplitude = s.number("amplitude");
    if (!(std::abs(amplitude) <= kMaxDisplacement))
        throw InputError(out_of_range_message(s.key_path("amplitude"), amplitude, "must be in [-0.05, 0.05] m"));
    std::vector<double> q(n, 0.0);
    q[mode - 1] = amplitude * std::sqrt(0.5 * length);
    return q;
}

double position_inside(TomlSection& s, std::string_view key, double length) {
    const double x = s.number(key);
    if (!(x > 0.0 && x < length))
        throw InputError(out_of_range_message(s.key_path(key), x, "must lie inside the string, in (0, L) = (0, " +
                                                                      std::to_string(length) + ") m"));
    return x;
}

double bounded(TomlSection& s, std::string_view key, double limit, const char* unit) {
    const double v = s.number(key);
    if (!(std::abs(v) <= limit)) {
        std::ostringstream allowed;
        allowed << "must be in [-" << limit << ", " << limit << "] " << unit;
        throw InputError(out_of_range_message(s.key_path(key), v, allowed.str()));
    }
    return v;
}

// A width centred on position that must stay inside the string.
double width_inside(TomlSection& s, double position, double length) {
    const double width = s.positive("width");
    if (!(position - 0.5 * width > 0.0 && position + 0.5 * width < length))
        throw InputError(out_of_range_message(s.key_path("width"), width,
                                              "must keep [position - width/2, position + width/2] inside (0, L)"));
    return width;
}

std::vector<double> read_shape_file(TomlSection& s, const DataSource& data, const Grid& grid) {
    const CsvTable table = read_section_table(s, "file", data, 2);
    try {
        return sample_profile_on_grid(table.column(0), table.column(1), grid, table.source);
    } catch (const InputError& e) {
        throw InputError(s.key_path("file") + ": " + e.what());
    }
}

}  // namespace

void read_excitation_section(TomlSection& section, const DataSource& data, Case& c) {
    const std::string type = section.text("type");
    const std::size_t n = c.mode_count();
    const double length = c.string.length_m;
    const Grid grid{length, n};
    const ModalBasis basis(length, n);
    c.initial_displacement.assign(n, 0.0);
    c.initial_velocity.assign(n, 0.0);
    if (type == "modal") {
        c.initial_displacement = read_modal_column(section, data, n);
    } else if (type == "sine") {
        c.initial_displacement = read_sine(section, n, length);
    } else if (type == "triangle") {
        const double position = position_inside(section, "position", length);
        const double amplitude = bounded(section, "amplitude", kMaxDisplacement, "m");
        basis.to_modes(triangle_shape(grid, position, amplitude), c.initial_displacement);
    } else if (type == "rounded-triangle") {
        const double position = position_inside(section, "position", length);
        const double width = width_inside(section, position, length);
        const double amplitude = bounded(section, "amplitude", kMaxDisplacement, "m");
        basis.to_modes(rounded_triangle_shape(grid, position, width, amplitude), c.initial_displacement);
    } else if (type == "shape") {
        basis.to_modes(read_shape_file(section, data, grid), c.initial_displacement);
    } else if (type == "strike") {
        const double position = position_inside(section, "position", length);
        const double width = width_inside(section, position, length);
        const double velocity = bounded(section, "velocity", kMaxVelocity, "m/s");
        basis.to_modes(raised_cosine_velocity(grid, position, width, velocity), c.initial_velocity);
    } else {
        throw InputError(section.key_path("type") + " = \"" + type +
                         "\": must be one of \"modal\", \"sine\", \"triangle\", \"rounded-triangle\", \"shape\", \"strike\"");
    }
}

}  // namespace fretbuzz
