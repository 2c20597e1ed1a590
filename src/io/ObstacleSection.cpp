// [obstacle]: the obstacle profile g(x) sampled on the interior grid.
#include <cmath>
#include <limits>
#include <sstream>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"
#include "fretbuzz/io/CsvTable.hpp"

namespace fretbuzz {

void read_obstacle_section(TomlSection& section, const DataSource& data, Case& c) {
    const std::string type = section.text("type");
    const std::size_t n = c.mode_count();
    const Grid grid{c.string.length_m, n};
    if (type == "none") {
        c.obstacle_height_m.assign(n, -std::numeric_limits<double>::infinity());
    } else if (type == "table") {
        const std::string file = section.text("file");
        const CsvTable table = parse_csv(data.read(file, section.key_path("file")), file, 2);
        c.obstacle_height_m = sample_profile_on_grid(table.column(0), table.column(1), grid, file);
    } else {
        throw InputError(section.key_path("type") + " = \"" + type + "\": must be one of \"table\", \"none\"");
    }
}

}  // namespace fretbuzz
