#pragma once
// Eigenfrequencies of a stiff string with a mobile nut. The stiff string with simply
// supported ends has, exactly,
//   nu_j = nu_0j sqrt(1 + B j^2)                                   (formula "exact")
// with nu_0j = j c / (2L), c = sqrt(T/mu), B the inharmonicity coefficient. Issanchou et
// al. 2017 (section 2.4, after Valette & Cuesta and Paté et al.) use its first-order
// expansion, with the nut's shift by perturbation of the wavenumbers,
//   nu_j = nu_0j (1 + B j^2 / 2 + (mu c / (j pi)) Im Y_s(omega_0j))  (formula "first-order"),
// which is good only while B j^2 is small: at B j^2 = 0.1 it is 0.11 % high, at
// B j^2 = 50 (mode 475 of a sitar-like string) 4.4 times too high. The nut term, a
// small correction either way, is added to both.
#include <cstddef>

#include "fretbuzz/model/NutMobility.hpp"
#include "fretbuzz/model/TautString.hpp"

namespace fretbuzz {

enum class StiffnessFormula { exact, first_order };

class FrequencyModel {
public:
    // Above this B j^2 the first-order formula is more than 0.1 % off the exact one.
    static constexpr double kFirstOrderLimit = 0.1;

    FrequencyModel(TautString string, double inharmonicity, NutMobility nut = {},
                   StiffnessFormula formula = StiffnessFormula::exact);

    // nu_j in Hz, j >= 1.
    double frequency_hz(std::size_t j) const;
    const TautString& string() const { return string_; }
    double inharmonicity() const { return inharmonicity_; }
    StiffnessFormula formula() const { return formula_; }

private:
    TautString string_;
    double inharmonicity_;
    NutMobility nut_;
    StiffnessFormula formula_;
};

}  // namespace fretbuzz
