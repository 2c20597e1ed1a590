#pragma once
// Which files a strings case's [[string]] case = "..." may name, and reading one: a strings
// case is someone else's input, and the file it names is read and parsed, so the rule is
// stated and checked before anything is opened.
//
// A string's case is
//   - a built-in case's name ("sitar"), or
//   - a relative path ending in .toml, without "..", of a regular file inside the strings
//     case's own folder (its real path, links followed, lies inside that folder's), at most
//     kMaxCaseFileBytes; when the folder has no such file, the built-in file at that path
//     (a copied case still finds "bridges/taraf-string.toml"); a built-in strings case names
//     built-in files only.
// Refusals (InputError) name the key and the rule, never anything of another file's content
// or structure.
#include <string>

#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {

// The text of the case `named` by the key `key` (e.g. "string[1].case") of a strings case
// whose files come from `data`.
std::string read_case_reference(const std::string& named, const std::string& key, const DataSource& data);

}  // namespace fretbuzz
