#include "fretbuzz/model/FrequencyModel.hpp"

#include <numbers>

namespace fretbuzz {

FrequencyModel::FrequencyModel(TautString string, double inharmonicity, NutMobility nut)
    : string_(string), inharmonicity_(inharmonicity), nut_(std::move(nut)) {}

double FrequencyModel::frequency_hz(std::size_t j) const {
    const double order = static_cast<double>(j);
    const double harmonic = string_.harmonic_frequency_hz(j);
    const double stiffness_shift = inharmonicity_ * order * order / 2.0;
    // The nut term is a small correction: Im Y_s is read at the unperturbed frequency.
    const double nut_shift = string_.linear_density * string_.wave_speed() / (order * std::numbers::pi) *
                             nut_.at_frequency(harmonic).imag();
    return harmonic * (1.0 + stiffness_shift + nut_shift);
}

}  // namespace fretbuzz
