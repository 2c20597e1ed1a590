#pragma once
// Case files in and out: a built-in case written out with its data files, and the set of
// keys the parser looks up (to check the case-format reference against).
#include <filesystem>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {

// Writes built-in case `name` as DIR/NAME.toml with every built-in data file its text
// names (at the same relative paths, e.g. DIR/data/...), ready to edit and run: the written
// case parses to the same Case. A built-in strings case (cases/bridges/NAME.toml) is written as
// it is, beside each one-string case its [[string]] tables name (at the paths they name them
// by: DIR/sitar.toml, DIR/bridges/taraf-string.toml) with their data files: the folder runs as
// it is. Creates DIR; returns the paths written, the case first.
// InputError for an unknown name; std::runtime_error when a file cannot be written.
std::vector<std::filesystem::path> export_builtin_case(std::string_view name, const std::filesystem::path& dir);

// Every key path (e.g. "string.L", "obstacle.frets.count") that parse_case looks up while
// parsing this text, whether the text has it or not: the schema the parser enforces.
// Throws what parse_case throws.
std::set<std::string> case_keys_looked_up(std::string_view toml_text, const std::string& source_name,
                                          const DataSource& data);

}  // namespace fretbuzz
