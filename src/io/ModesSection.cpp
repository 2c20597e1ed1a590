// [modes]: per-mode frequencies and dampings from a table (mode, frequency_hz, sigma_per_s).
#include <sstream>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/io/CsvTable.hpp"

namespace fretbuzz {

void read_modes_section(TomlSection& section, const DataSource& data, std::size_t mode_count, Case& c) {
    const std::string file = section.text("table");
    const CsvTable table = parse_csv(data.read(file, section.key_path("table")), file, 3);
    if (table.row_count() < mode_count) {
        std::ostringstream msg;
        msg << section.key_path("table") << " = \"" << file << "\" lists " << table.row_count()
            << " modes but string.modes = " << mode_count << " are requested";
        throw InputError(msg.str());
    }
    ModeTable& modes = c.modes;
    for (std::size_t j = 0; j < mode_count; ++j) {
        const auto& row = table.rows[j];
        if (row[0] != static_cast<double>(j + 1)) {
            std::ostringstream msg;
            msg << file << ": data row " << j + 1 << " is mode " << row[0] << "; modes must be listed 1, 2, 3, ... in order";
            throw InputError(msg.str());
        }
        modes.frequency_hz.push_back(row[1]);
        modes.sigma_per_s.push_back(row[2]);
        modes.source.push_back(ModeSource::measured);
    }
    modes.validate();
}

}  // namespace fretbuzz
