// CSV files named in a case file: the key that names the file is put in front of every
// error, so a malformed table points back to the line of the case file at fault.
#include <string>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

CsvTable read_section_table(TomlSection& section, std::string_view key, const DataSource& data,
                            std::size_t min_columns) {
    const std::string file = section.text(key);
    const std::string key_path = section.key_path(key);
    const std::string text = data.read(file, key_path);  // its errors name the key already
    try {
        return parse_csv(text, file, min_columns);
    } catch (const InputError& e) {
        throw InputError(key_path + " = \"" + file + "\": " + e.what());
    }
}

}  // namespace fretbuzz
