#pragma once
// A number as the messages of the estimation quote it (the stream's default six digits).
#include <sstream>
#include <string>

namespace fretbuzz {

inline std::string number_text(double value) {
    std::ostringstream s;
    s << value;
    return s.str();
}

}  // namespace fretbuzz
