#include "fretbuzz/input/CsvTable.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/input/TextFile.hpp"

namespace fretbuzz {

namespace {

std::vector<std::string_view> split(std::string_view line) {
    std::vector<std::string_view> cells;
    std::size_t start = 0;
    while (true) {
        const auto comma = line.find(',', start);
        cells.push_back(trim_blanks(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
    return cells;
}

bool parse_number(std::string_view cell, double& value) {
    if (cell.empty()) return false;
    if (cell.front() == '+') cell.remove_prefix(1);
    const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    return ec == std::errc() && ptr == cell.data() + cell.size();
}

std::vector<std::string> names_of(std::string_view header) {
    std::vector<std::string> names;
    for (std::string_view cell : split(header)) names.emplace_back(cell);
    return names;
}

}  // namespace

std::vector<double> CsvTable::column(std::size_t c) const {
    std::vector<double> values;
    values.reserve(rows.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
        if (c >= rows[r].size())
            throw InputError(source + ": data row " + std::to_string(r + 1) + " has no column " + std::to_string(c + 1));
        values.push_back(rows[r][c]);
    }
    return values;
}

CsvTable parse_csv(std::string_view text, const std::string& source, std::size_t min_columns) {
    CsvTable table;
    table.source = source;
    std::size_t line_number = 0;
    std::size_t start = 0;
    while (start <= text.size()) {
        const auto end = text.find('\n', start);
        const std::string_view raw = text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
        start = end == std::string_view::npos ? text.size() + 1 : end + 1;
        ++line_number;
        const std::string at = source + ":" + std::to_string(line_number);
        if (raw.size() > kMaxLineBytes)
            throw InputError(at + ": the line is longer than " + std::to_string(kMaxLineBytes) + " bytes");
        const std::string_view line = trim_blanks(raw);
        if (line.empty()) continue;
        if (line.front() == '#') {
            if (table.rows.empty() && table.column_names.empty()) table.column_names = names_of(trim_blanks(line.substr(1)));
            continue;
        }
        std::vector<double> row;
        std::string label;
        bool numeric = true;
        std::size_t column = 0;
        for (std::string_view cell : split(line)) {
            ++column;
            double value = 0.0;
            if (!parse_number(cell, value)) {
                // Text after the required numbers is a label (the `source` column of a mode table).
                numeric = row.size() >= min_columns;
                label = cell;
                break;
            }
            if (!std::isfinite(value))
                throw InputError(at + ": the value in column " + std::to_string(column) + " is not a finite number");
            row.push_back(value);
        }
        if (!numeric) {
            if (table.rows.empty() && table.column_names.empty()) {  // a plain header line
                table.column_names = names_of(line);
                continue;
            }
            // The file is someone else's: say where, never echo what (it may not be a table at all).
            throw InputError(at + ": expected " + std::to_string(min_columns) +
                             " comma-separated numbers, column " + std::to_string(column) + " is not a number");
        }
        if (row.size() < min_columns)
            throw InputError(at + ": expected at least " +
                             std::to_string(min_columns) + " columns, got " + std::to_string(row.size()));
        table.rows.push_back(std::move(row));
        table.labels.push_back(std::move(label));
    }
    if (table.rows.empty()) throw InputError(source + ": no data rows");
    return table;
}

}  // namespace fretbuzz
