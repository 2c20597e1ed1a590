#pragma once
// The ideal taut string under the frequency and damping models: wave speed
// c = sqrt(T/mu) and the harmonic series nu_0j = j c / (2L)
// (Issanchou et al. 2017, section 2.4).
#include <cmath>
#include <cstddef>
#include <numbers>

namespace fretbuzz {

struct TautString {
    double length_m = 0.0;        // L
    double tension_n = 0.0;       // T
    double linear_density = 0.0;  // mu, kg/m

    // The string of length L and mass mu tuned to f: T = mu (2 L f)^2.
    static TautString tuned_with_mass(double length, double linear_density, double frequency_hz) {
        const double wavelength_per_period = 2.0 * length * frequency_hz;  // 2 L f = c
        return {length, linear_density * wavelength_per_period * wavelength_per_period, linear_density};
    }
    // The string of length L under tension T tuned to f: mu = T / (2 L f)^2.
    static TautString tuned_with_tension(double length, double tension, double frequency_hz) {
        const double wavelength_per_period = 2.0 * length * frequency_hz;
        return {length, tension, tension / (wavelength_per_period * wavelength_per_period)};
    }

    double wave_speed() const { return std::sqrt(tension_n / linear_density); }
    double fundamental_hz() const { return harmonic_frequency_hz(1); }
    // nu_0j, Hz.
    double harmonic_frequency_hz(std::size_t j) const {
        return static_cast<double>(j) * wave_speed() / (2.0 * length_m);
    }
    // Bending stiffness EI that gives inharmonicity B: B = pi^2 EI / (T L^2).
    double bending_stiffness_for(double inharmonicity) const {
        return inharmonicity * tension_n * length_m * length_m / (std::numbers::pi * std::numbers::pi);
    }
    double inharmonicity_for(double bending_stiffness) const {
        return std::numbers::pi * std::numbers::pi * bending_stiffness / (tension_n * length_m * length_m);
    }
};

}  // namespace fretbuzz
