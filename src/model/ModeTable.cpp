#include "fretbuzz/model/ModeTable.hpp"

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

std::string to_string(ModeSource source) { return source == ModeSource::measured ? "measured" : "model"; }

void ModeTable::validate() const {
    if (frequency_hz.empty()) throw InputError("modes: the mode table is empty; at least 1 mode is required");
    if (sigma_per_s.size() != frequency_hz.size() || source.size() != frequency_hz.size())
        throw InputError("modes: frequency, damping and source columns differ in length");
    for (std::size_t j = 0; j < size(); ++j) {
        const std::string mode = "mode " + std::to_string(j + 1);
        require_positive(mode + " frequency_hz", frequency_hz[j]);
        require_non_negative(mode + " sigma_per_s", sigma_per_s[j]);
    }
}

}  // namespace fretbuzz
