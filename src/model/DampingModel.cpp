#include "fretbuzz/model/DampingModel.hpp"

#include <cmath>
#include <numbers>

namespace fretbuzz {

using std::numbers::pi;

DampingModel::DampingModel(TautString string, DampingParameters parameters, NutMobility nut)
    : string_(string), parameters_(parameters), nut_(std::move(nut)) {}

double DampingModel::air_inverse_q(std::size_t j, double frequency_hz) const {
    const double eta = parameters_.air_viscosity;
    const double resistance = 2.0 * pi * eta + 2.0 * pi * parameters_.equivalent_diameter_m *
                                                   std::sqrt(pi * eta * parameters_.air_density * frequency_hz);
    const double harmonic_ratio = string_.harmonic_frequency_hz(j) / frequency_hz;
    return harmonic_ratio * resistance / (2.0 * pi * string_.linear_density * frequency_hz);
}

double DampingModel::viscoelastic_inverse_q(std::size_t j, double frequency_hz) const {
    const double harmonic = string_.harmonic_frequency_hz(j);
    const double tension = string_.tension_n;
    return 4.0 * pi * pi * string_.linear_density * parameters_.core_bending_stiffness *
           parameters_.viscoelastic_loss * harmonic * harmonic * harmonic / (tension * tension * frequency_hz);
}

double DampingModel::nut_inverse_q(double frequency_hz) const {
    // mu c^2 = T.
    return string_.tension_n / (pi * string_.length_m * frequency_hz) * nut_.at_frequency(frequency_hz).real();
}

double DampingModel::inverse_q(std::size_t j, double frequency_hz) const {
    return air_inverse_q(j, frequency_hz) + viscoelastic_inverse_q(j, frequency_hz) + thermoelastic_inverse_q() +
           nut_inverse_q(frequency_hz);
}

double DampingModel::sigma_per_s(std::size_t j, double frequency_hz) const {
    return pi * frequency_hz * inverse_q(j, frequency_hz);
}

}  // namespace fretbuzz
