#pragma once
// Reading the text files a case names (case files, tables, sweep specs) as someone else's
// input: regular files only (a FIFO would block, /dev/zero never ends), at most a given
// size, and errors that name the file and the key that named it, never its content.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace fretbuzz {

inline constexpr std::size_t kMaxCaseFileBytes = 4u << 20;   // a case file: a few kB in practice
inline constexpr std::size_t kMaxDataFileBytes = 64u << 20;  // a table: a mode table of 10^4 modes is 0.5 MB
inline constexpr std::size_t kMaxLineBytes = 64u << 10;      // one row of a table

// The whole file; throws InputError starting with `what` (say `modes.file = "m.csv"`) if
// the path's names are too long, it names no file ("no such file"), not a regular file, or
// one larger than max_bytes; std::runtime_error (exit 1) if the system cannot read it.
std::string read_text_file(const std::filesystem::path& path, const std::string& what, std::size_t max_bytes);

// s without its leading and trailing blanks (spaces, tabs, carriage returns).
inline std::string_view trim_blanks(std::string_view s) {
    const auto first = s.find_first_not_of(" \t\r");
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(" \t\r");
    return s.substr(first, last - first + 1);
}

}  // namespace fretbuzz
