#pragma once
// The mode table of a run from measurements and models (Issanchou et al. 2017,
// section 4): measured nu_j, sigma_j are used for the modes they list (the paper
// measures the first 34 modes of the bass), the frequency and damping models give
// the others.
#include <cstddef>
#include <vector>

#include "fretbuzz/model/FrequencyModel.hpp"
#include "fretbuzz/model/ModalDamping.hpp"
#include "fretbuzz/model/ModeTable.hpp"

namespace fretbuzz {

struct MeasuredMode {
    std::size_t mode = 0;  // j >= 1
    double frequency_hz = 0.0;
    double sigma_per_s = 0.0;
};

// Modes 1..mode_count. A mode not in measured needs the frequency model; its damping
// comes from the damping model, or is zero when damping is null (a lossless string).
// Measured modes above mode_count are ignored. Throws InputError if a mode is left
// without a frequency.
ModeTable assemble_mode_table(std::size_t mode_count, const std::vector<MeasuredMode>& measured,
                              const FrequencyModel* frequency, const ModalDamping* damping);

}  // namespace fretbuzz
