#pragma once
// JSON text as nlohmann's dump() writes it, but with every floating-point number in its
// shortest form that reads back to the same double (std::to_chars): dump() uses Grisu2, which
// gives a longer form for about 1 double in 2000 (23.479179565158798 for 23.4791795651588).
// Non-finite numbers are written as null, as dump() writes them.
#include <string>

#include <nlohmann/json.hpp>

namespace fretbuzz {

// indent < 0: compact, as dump(); otherwise one member per line, indented by `indent` spaces.
std::string json_text(const nlohmann::ordered_json& value, int indent = -1);

}  // namespace fretbuzz
