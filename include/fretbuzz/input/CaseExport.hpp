#pragma once
// Case files in and out: a built-in case written out with its data files, and the set of
// keys the parser looks up (to check the case-format reference against).
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {

// A file of an exported case: its path relative to the folder it is written into, and its text.
struct ExportedFile {
    std::string path;
    std::string text;
};

// Built-in case `name` as NAME.toml with every built-in data file its text names (at the same
// relative paths, e.g. data/...), ready to edit and run: the written case parses to the same
// Case. A built-in strings case (cases/bridges/NAME.toml) comes as it is, beside each
// one-string case its [[string]] tables name (at the paths they name them by: sitar.toml,
// bridges/taraf-string.toml) with their data files: the folder runs as it is. The case first.
// InputError for an unknown name. (output/CaseExportFolder.hpp writes them out.)
std::vector<ExportedFile> builtin_case_files(std::string_view name);

// Every key path (e.g. "string.L", "obstacle.frets.count") that parse_case looks up while
// parsing this text, whether the text has it or not: the schema the parser enforces.
// Throws what parse_case throws.
std::set<std::string> case_keys_looked_up(std::string_view toml_text, const std::string& source_name,
                                          const DataSource& data);

}  // namespace fretbuzz
