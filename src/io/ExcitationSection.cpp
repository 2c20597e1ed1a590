// [excitation]: the initial state. Shapes given in space are projected on the modes with
// the scheme's own discrete transform (q = dx S^T u), so u(x_i, 0) is reproduced exactly;
// so are velocity fields.
#include <cmath>
#include <sstream>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/InitialShape.hpp"
#include "fretbuzz/scheme/ModalBasis.hpp"

namespace fretbuzz {

namespace {

constexpr double kMaxDisplacement = 0.05;  // m
constexpr double kMaxVelocity = 100.0;     // m/s

std::vector<double> read_modal_column(TomlSection& section, const DataSource& data, std::size_t n) {
    const CsvTable table = read_section_table(section, "file", data, 2);
    if (table.row_count() < n)
        throw InputError(section.key_path("file") + " = \"" + section.text("file") + "\" lists " +
                         std::to_string(table.row_count()) + " modes but the case has " + std::to_string(n));
    std::vector<double> q(table.column(1));
    q.resize(n);
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
                         "\": must be one of \"modal\", \"triangle\", \"rounded-triangle\", \"shape\", \"strike\"");
    }
}

}  // namespace fretbuzz
