#pragma once
// A bridge that strings rest on, described by its modes (BridgeModeSpec: modal mass M_b, natural
// frequency, damping ratio, and how far each string's bridge end moves with it). Each mode is a
// damped oscillator stepped with the strings' own exact one-step map (ModalPropagator), in
// mass-normalised coordinates y_b = sqrt(M_b) z_b; string s's end moves by
// w_s = sum_b p~_sb y_b, p~_sb = p_sb / sqrt(M_b).
//
// What the strings do to it (BridgeEnd forms it): each end pulls with
//     F_s = -mu_s (g_s . delta^2 q_s) / dt^2 - k_s (w_s^{n+1} + w_s^{n-1}) / 2,
// the string's inertial reaction and its static stiffness k_s = T_s / L_s, centred so that the
// exchange with the strings conserves a discrete energy exactly. Only the stiffness term holds
// the unknown w^{n+1}: one small linear solve per step, (I/dt^2 + sum_s k_s/2 p~_s p~_s^T)
// y^{n+1} = ..., whose inverse is formed once when the bridge is built (plan once).
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/ModalPropagator.hpp"
#include "fretbuzz/scheme/ModalState.hpp"

namespace fretbuzz {

class Bridge {
public:
    // `modes` with one participation per string; end_stiffness[s] = k_s (N/m).
    Bridge(std::span<const BridgeModeSpec> modes, std::span<const double> end_stiffness, double dt);

    std::size_t strings() const { return stiffness_.size(); }
    std::size_t size() const { return propagator_->size(); }
    // w_s^n and w_s^{n-1}: where string s's end is now and was a step before (m).
    double end(std::size_t s) const { return end_now_[s]; }
    double end_before(std::size_t s) const { return end_before_[s]; }
    // n -> n + 1 from the strings' pulls without their stiffness term: pull[s] =
    // -mu_s (g_s . delta^2 q_s) / dt^2 (N).
    void step(std::span<const double> pull);

    // The modes' discrete energy H^{n+1/2} (J), the energy their damping took, and the speed of
    // the bridge where every mode moves with participation 1 (sum_b dz_b/dt over the last step).
    double energy() const;
    double dissipated() const { return damping_; }
    double velocity() const;
    std::size_t subnormal_coordinates() const { return state_.subnormal_coordinates(); }

private:
    // Fixed once built and shared by copies (a copied bridge steps on from the same state).
    std::shared_ptr<const ModalPropagator> propagator_;
    ModalState state_;
    std::vector<double> share_;      // p~_sb, string by string (s * B + b)
    std::vector<double> inverse_;    // (I/dt^2 + sum_s k_s/2 p~_s p~_s^T)^-1, B x B
    std::vector<double> root_mass_;  // sqrt(M_b)
    std::vector<double> stiffness_;  // k_s
    std::vector<double> end_now_, end_before_;
    std::vector<double> predicted_, rhs_, impulse_;
    double dt_;
    double damping_ = 0.0;
};

}  // namespace fretbuzz
