#include "fretbuzz/model/FrequencyModel.hpp"

#include <cmath>
#include <numbers>

namespace fretbuzz {

FrequencyModel::FrequencyModel(TautString string, double inharmonicity, NutMobility nut, StiffnessFormula formula)
    : string_(string), inharmonicity_(inharmonicity), nut_(std::move(nut)), formula_(formula) {}

double FrequencyModel::frequency_hz(std::size_t j) const {
    const double order = static_cast<double>(j);
    const double harmonic = string_.harmonic_frequency_hz(j);
    const double stiffness = inharmonicity_ * order * order;
    const double stiffness_factor =
        formula_ == StiffnessFormula::exact ? std::sqrt(1.0 + stiffness) : 1.0 + stiffness / 2.0;
    // The nut term is a small correction: Im Y_s is read at the unperturbed frequency.
    const double nut_shift = string_.linear_density * string_.wave_speed() / (order * std::numbers::pi) *
                             nut_.at_frequency(harmonic).imag();
    return harmonic * (stiffness_factor + nut_shift);
}

}  // namespace fretbuzz
