#pragma once
// Base64 (RFC 4648, with padding), for data: URIs in the self-contained HTML report.
#include <string>
#include <string_view>

namespace fretbuzz {

std::string base64_encode(std::string_view bytes);

}  // namespace fretbuzz
