#pragma once
// Numeric CSV tables (mode tables, obstacle profiles, initial shapes): comma-separated
// numbers, one row per line; lines starting with '#' and a first line of column names
// are headers. Text columns after the required numbers (a mode table's `source`) are
// labels, kept apart from the numbers. Every error names the file, the line and what was expected.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace fretbuzz {

struct CsvTable {
    std::string source;                     // file name, for messages
    std::vector<std::string> column_names;  // from the header, if any
    std::vector<std::vector<double>> rows;
    std::vector<std::string> labels;        // per row: the first text cell after its numbers, or ""

    std::size_t row_count() const { return rows.size(); }
    // Column c of every row; throws InputError if a row is too short.
    std::vector<double> column(std::size_t c) const;
};

// Parses text; requires at least min_columns numbers per row and at least one row.
CsvTable parse_csv(std::string_view text, const std::string& source, std::size_t min_columns);

}  // namespace fretbuzz
