// [string]: the physical string. L, T, mu and the mode count are required; the diameters
// and stiffness are only needed by the frequency and damping models. ideal = true: a
// string without stiffness on rigid supports, nu_j = j c / (2L), no frequency model needed.
#include <numbers>

#include "CaseSections.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {

std::optional<double> core_bending_stiffness(TomlSection& s, const std::optional<double>& core_diameter) {
    const auto given = s.optional_positive("E_core_I_core");
    const auto young_modulus = s.optional_positive("E_core");
    if (given && young_modulus)
        throw InputError(s.key_path("E_core") + " and " + s.key_path("E_core_I_core") +
                         " are both given: give one (E_core_I_core, or E_core with d_core)");
    if (given) return given;
    if (!young_modulus) return std::nullopt;
    if (!core_diameter)
        throw InputError(s.key_path("d_core") + " is missing (required with " + s.key_path("E_core") + ")");
    const double d4 = *core_diameter * *core_diameter * *core_diameter * *core_diameter;
    return *young_modulus * std::numbers::pi * d4 / 64.0;
}

}  // namespace

StringDescription read_string_section(TomlSection& s, Case& c) {
    c.string.length_m = s.positive("L");
    c.string.tension_n = s.positive("T");
    c.string.linear_density = s.positive("mu");
    StringDescription d;
    d.mode_count = s.count("modes", 1, kMaxModes);
    d.diameter_m = s.optional_positive("d");
    d.core_diameter_m = s.optional_positive("d_core");
    if (d.diameter_m && d.core_diameter_m && *d.core_diameter_m > *d.diameter_m)
        throw InputError(out_of_range_message(s.key_path("d_core"), *d.core_diameter_m,
                                              "must not exceed string.d = " + std::to_string(*d.diameter_m)));
    d.core_bending_stiffness = core_bending_stiffness(s, d.core_diameter_m);
    d.inharmonicity = s.optional_non_negative("B");
    d.ideal = s.optional_flag("ideal").value_or(false);
    if (d.ideal && (d.inharmonicity || d.core_bending_stiffness))
        throw InputError(s.key_path("ideal") + " = true means no bending stiffness: remove " +
                         s.key_path(d.inharmonicity ? "B" : (s.has("E_core") ? "E_core" : "E_core_I_core")) +
                         " (or set ideal = false)");
    if (d.inharmonicity && *d.inharmonicity > 0.1)
        throw InputError(out_of_range_message(s.key_path("B"), *d.inharmonicity,
                                              "must be in [0, 0.1] (musical strings have B of 1e-5 to 1e-3)"));
    return d;
}

}  // namespace fretbuzz
