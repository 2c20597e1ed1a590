#pragma once
// A length in metres as the set-up's messages and advice quote it: "1.25 mm" (three digits).
#include <sstream>
#include <string>

namespace fretbuzz {

inline std::string mm_text(double metres) {
    std::ostringstream out;
    out.precision(3);
    out << metres * 1e3 << " mm";
    return out.str();
}

}  // namespace fretbuzz
