#pragma once
// The per-mode linear description of a string: frequency nu_j and damping sigma_j
// of each transverse mode j = 1..Nm (Issanchou et al. 2017, eq. 3). Where each
// pair came from (a measurement or a model) is kept so users can see it.
#include <cstddef>
#include <string>
#include <vector>

namespace fretbuzz {

enum class ModeSource { measured, model };

std::string to_string(ModeSource source);

struct ModeTable {
    std::vector<double> frequency_hz;  // nu_j, j = 1..Nm (index j-1)
    std::vector<double> sigma_per_s;   // sigma_j, amplitude decay rate
    std::vector<ModeSource> source;

    std::size_t size() const { return frequency_hz.size(); }
    // Throws InputError naming the first mode whose values are not finite,
    // not positive (frequency) or negative (damping).
    void validate() const;
};

}  // namespace fretbuzz
