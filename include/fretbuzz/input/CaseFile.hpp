#pragma once
// Case files: one TOML file describes a whole run (string, modes, obstacle, excitation,
// contact law, observation points, rates). Built-in cases are such files, compiled in.
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

// Where the data files a case file names (CSV tables) are read from.
class DataSource {
public:
    static DataSource directory(std::filesystem::path dir);  // relative to a case file
    static DataSource builtin();                              // the compiled-in cases/ folder
    std::string read(const std::string& relative_path, const std::string& key) const;
    bool is_builtin() const { return builtin_; }
    const std::filesystem::path& directory() const { return dir_; }  // of a case file (empty: the current one)

private:
    bool builtin_ = false;
    std::filesystem::path dir_;
};

struct BuiltinCaseInfo {
    std::string name;
    std::string description;
};

std::vector<BuiltinCaseInfo> builtin_cases();
bool is_builtin_case(std::string_view name);
// The TOML text of a built-in case; throws InputError listing the valid names.
std::string builtin_case_text(std::string_view name);

Case parse_case(std::string_view toml_text, const std::string& source_name, const DataSource& data);

// A case file's text with where it came from: what parse_case needs. Sweeps edit the
// text's TOML document and parse it again, so every value is checked as in a case file.
struct CaseText {
    std::string text;
    std::string source_name;
    DataSource data;
};
// A built-in case name, or a path to a .toml file (InputError if neither).
CaseText read_case_text(const std::string& name_or_path);
// A built-in case name, or a path to a .toml file.
Case load_case(const std::string& name_or_path);
// The case read again with string.modes = modes: its grid, obstacle, excitation and modes
// all follow from the file as they would had it said so.
Case with_mode_count(const CaseText& source, std::size_t modes);

}  // namespace fretbuzz
