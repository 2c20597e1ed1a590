#pragma once
// Modal damping of a wound string (Issanchou et al. 2017, section 2.5, after Valette &
// Cuesta and Paté et al.), as a quality factor Q_j = pi nu_j / sigma_j with
//   1/Q_j = 1/Q_air + 1/Q_ve + 1/Q_te + (mu c^2 / (pi L nu_j)) Re Y_s(omega_j)
//   1/Q_air = (nu_0j / nu_j) R / (2 pi mu nu_j),
//             R = 2 pi eta_air + 2 pi d_eq sqrt(pi eta_air rho_air nu_j)   (air friction)
//   1/Q_ve  = 4 pi^2 mu E_core I_core delta_ve nu_0j^3 / (T^2 nu_j)      (viscoelasticity)
//   1/Q_te  = constant                                                   (thermoelasticity)
// and the last term the losses into the neck through the nut (counted once: the paper's
// printed formula repeats it by a typesetting slip).
#include <cstddef>

#include "fretbuzz/model/ModalDamping.hpp"
#include "fretbuzz/model/NutMobility.hpp"
#include "fretbuzz/model/TautString.hpp"

namespace fretbuzz {

struct DampingParameters {
    double air_viscosity = 1.8e-5;          // eta_air, kg/(m s)
    double air_density = 1.2;               // rho_air, kg/m^3
    double equivalent_diameter_m = 0.0;     // d_eq of the wound string in air
    double viscoelastic_loss = 0.0;         // delta_ve (loss angle)
    double core_bending_stiffness = 0.0;    // E_core I_core, N m^2
    double thermoelastic_inverse_q = 0.0;   // 1/Q_te
};

class DampingModel : public ModalDamping {
public:
    DampingModel(TautString string, DampingParameters parameters, NutMobility nut = {});

    // The contributions to 1/Q_j of mode j at its frequency nu_j (Hz).
    double air_inverse_q(std::size_t j, double frequency_hz) const;
    double viscoelastic_inverse_q(std::size_t j, double frequency_hz) const;
    double thermoelastic_inverse_q() const { return parameters_.thermoelastic_inverse_q; }
    double nut_inverse_q(double frequency_hz) const;
    double inverse_q(std::size_t j, double frequency_hz) const;
    // sigma_j = pi nu_j / Q_j, 1/s.
    double sigma_per_s(std::size_t j, double frequency_hz) const override;

private:
    TautString string_;
    DampingParameters parameters_;
    NutMobility nut_;
};

}  // namespace fretbuzz
