// [excitation]: the initial state. Shapes given in space are projected on the modes with
// the scheme's own discrete transform (q = dx S^T u), so u(x_i, 0) is reproduced exactly.
#include <cmath>
#include <sstream>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/InitialShape.hpp"
#include "fretbuzz/io/CsvTable.hpp"
#include "fretbuzz/scheme/ModalBasis.hpp"

namespace fretbuzz {

namespace {

std::vector<double> read_modal_column(TomlSection& section, const DataSource& data, std::size_t n) {
    const std::string file = section.text("file");
    const CsvTable table = parse_csv(data.read(file, section.key_path("file")), file, 2);
    if (table.row_count() < n)
        throw InputError(section.key_path("file") + " = \"" + file + "\" lists " + std::to_string(table.row_count()) +
                         " modes but the case has " + std::to_string(n));
    std::vector<double> q(table.column(1));
    q.resize(n);
    return q;
}

}  // namespace

void read_excitation_section(TomlSection& section, const DataSource& data, Case& c) {
    const std::string type = section.text("type");
    const std::size_t n = c.mode_count();
    const ModalBasis basis(c.string.length_m, n);
    c.initial_velocity.assign(n, 0.0);
    if (type == "modal") {
        c.initial_displacement = read_modal_column(section, data, n);
    } else if (type == "triangle") {
        const double position = section.number("position");
        const double amplitude = section.number("amplitude");
        if (!(position > 0.0 && position < c.string.length_m))
            throw InputError(out_of_range_message(section.key_path("position"), position, "must lie in (0, L)"));
        const std::vector<double> u = triangle_shape(Grid{c.string.length_m, n}, position, amplitude);
        c.initial_displacement.resize(n);
        basis.to_modes(u, c.initial_displacement);
    } else {
        throw InputError(section.key_path("type") + " = \"" + type + "\": must be one of \"modal\", \"triangle\"");
    }
}

}  // namespace fretbuzz
