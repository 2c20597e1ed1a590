#pragma once
// A case read from its parsed TOML document: what parse_case does after parsing the text.
// Sweeps and the mode-count study set values in a parsed document and read it here, so
// their cases are checked by the same reader as case files, without going back to text.
#include <string>

#include <toml++/toml.h>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/CaseFile.hpp"

namespace fretbuzz {

// source_text: what the case records as its text (provenance).
Case parse_case_document(const toml::table& root, std::string source_text, const DataSource& data);

// The document as TOML text (what a case built from an edited document records).
std::string toml_text(const toml::table& root);

}  // namespace fretbuzz
