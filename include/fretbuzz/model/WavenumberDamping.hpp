#pragma once
// The two-parameter damping law many string papers use (e.g. Bilbao's stiff string):
//   sigma_j = eta0 + eta2 k_j^2,   k_j = j pi / L,
// a frequency-independent loss eta0 (1/s) plus one growing with the wavenumber squared
// (eta2 in m^2/s).
#include "fretbuzz/model/ModalDamping.hpp"

namespace fretbuzz {

class WavenumberDamping : public ModalDamping {
public:
    WavenumberDamping(double length_m, double eta0_per_s, double eta2_m2_per_s)
        : length_m_(length_m), eta0_(eta0_per_s), eta2_(eta2_m2_per_s) {}
    double sigma_per_s(std::size_t j, double frequency_hz) const override;

private:
    double length_m_;
    double eta0_;
    double eta2_;
};

}  // namespace fretbuzz
