#pragma once
// `fretbuzz export CASE DIR`: a built-in case and its data files written out all at once, as a
// run writes its results (OutputDirectory): into a staging folder beside DIR, swapped in with
// one rename. A full disk or an interrupt leaves DIR as it was and nothing else; no link in DIR
// is followed; no file already in DIR is replaced (its own files stay, beside the case).
#include <filesystem>
#include <string_view>
#include <vector>

namespace fretbuzz {

// Writes built-in case `name` (input/CaseExport.hpp: builtin_case_files) into dir; returns the
// paths written, the case first. InputError (naming DIR) for an unknown name, a DIR that
// cannot be an output directory, or one that already holds a name the export writes (a file,
// a folder or a link); std::runtime_error naming the file when writing fails.
std::vector<std::filesystem::path> export_builtin_case(std::string_view name, const std::filesystem::path& dir);

}  // namespace fretbuzz
