#pragma once
// Case files of strings on a bridge (StringsCase): a [bridge] of [[bridge.mode]] tables and
// [[string]] tables each naming a one-string case (a built-in name or a .toml path, relative to
// this file), with one [run] for all. See docs/case-format.md ("Strings on a bridge").
#include <optional>
#include <string>
#include <string_view>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {

// The text of a strings case: a built-in one (cases/bridges/NAME.toml) or a .toml file with a
// [bridge] table; nothing for any other name (a one-string case).
std::optional<CaseText> read_strings_case_text(const std::string& name_or_path);
StringsCase parse_strings_case(const CaseText& source);
// What `fretbuzz show` adds to a strings case's text, as TOML comments: the bridge's modes and
// each string with the case it names, how it was changed (mirror, set keys, at rest, pitch
// ratio) and its first partial as read.
std::string describe_strings_case(const StringsCase& sc);
// The built-in strings cases' names.
std::vector<BuiltinCaseInfo> builtin_strings_cases();

}  // namespace fretbuzz
