#pragma once
// Eigenfrequencies of a stiff string with a mobile nut, by perturbation of the
// wavenumbers (Issanchou et al. 2017, section 2.4, after Valette & Cuesta and
// Paté et al.):
//   nu_j = nu_0j (1 + B j^2 / 2 + (mu c / (j pi)) Im Y_s(omega_0j)),
// with nu_0j = j c / (2L), c = sqrt(T/mu), omega_0j = j pi c / L = 2 pi nu_0j,
// B the inharmonicity coefficient and Y_s the nut mobility.
#include <cstddef>

#include "fretbuzz/model/NutMobility.hpp"
#include "fretbuzz/model/TautString.hpp"

namespace fretbuzz {

class FrequencyModel {
public:
    FrequencyModel(TautString string, double inharmonicity, NutMobility nut = {});

    // nu_j in Hz, j >= 1.
    double frequency_hz(std::size_t j) const;
    const TautString& string() const { return string_; }

private:
    TautString string_;
    double inharmonicity_;
    NutMobility nut_;
};

}  // namespace fretbuzz
