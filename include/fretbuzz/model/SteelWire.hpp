#pragma once
// A round steel wire: the whole of a plain string, the core of a wound one (which bends on
// its core: the wrap adds mass, hardly stiffness). E = 200 GPa and rho = 7850 kg/m^3, music
// wire's. Its bending stiffness EI = E pi d^4 / 64 and its mass per length rho pi d^2 / 4.
//
// The mass per length of a string of outer diameter d, against a steel rod of that diameter:
// 1 for a plain string; about 0.8 for the round-wound strings of D'Addario's charts (a
// nickel-wrapped .046 in guitar string 0.81, a .100 in bass string 0.81; the paper's bass
// string, 6.69 g/m at 1.14 mm, 0.84), less for nylon. plausible_fill() says whether a string
// is of this kind: well outside, its mass or its gauge is likely wrong (a unit weight entered
// in the wrong unit is 10 or 1000 times off).
#include <cmath>
#include <numbers>

namespace fretbuzz {

struct SteelWire {
    static constexpr double kYoungModulus = 200e9;  // Pa
    static constexpr double kDensity = 7850.0;      // kg/m^3

    double diameter_m = 0.0;

    double bending_stiffness() const {
        const double d = diameter_m;
        return kYoungModulus * std::numbers::pi * d * d * d * d / 64.0;
    }
    double linear_density() const { return kDensity * std::numbers::pi * diameter_m * diameter_m / 4.0; }
    // The solid wire of a given mass per length (kg/m): d = sqrt(4 mu / (pi rho)).
    static SteelWire of_linear_density(double linear_density) {
        return {std::sqrt(4.0 * linear_density / (std::numbers::pi * kDensity))};
    }
    // A string's mass per length over this wire's, as the outer diameter's wire.
    double fill(double string_linear_density) const { return string_linear_density / linear_density(); }
    static constexpr double kPlausibleFillLow = 0.5, kPlausibleFillHigh = 1.2;
    bool plausible_fill(double string_linear_density) const {
        const double f = fill(string_linear_density);
        return f >= kPlausibleFillLow && f <= kPlausibleFillHigh;
    }
};

}  // namespace fretbuzz
