#pragma once
// A string's energy accounts that are not a contact's or a played part's own: the modal energy
// H^{n-1/2} of its state and the energy its modes' damping has taken since H^{1/2}. The modal
// energy is kept for the step it belongs to: the pass into a step the caller audits (audit_every)
// and a flight's closing jump form it in their own pass over the modes, so reading it costs no
// pass of its own at an audio rate.
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"

namespace fretbuzz {

class EnergyLedger {
public:
    explicit EnergyLedger(const Plan& plan) : plan_(&plan) {}

    // H^{n-1/2} without the contact part (J), formed at most once per step.
    double modal_energy(const ModalState& modes, long n) const {
        if (energy_step_ != n) keep_modal_energy(n, modes.scaled_energy());
        return modal_energy_;
    }
    // The modal energy of step `step` as a pass or a jump formed it (scaled_energy's scale).
    void keep_modal_energy(long step, double scaled) const {
        modal_energy_ = plan_->modal_energy_scale() * scaled;
        energy_step_ = step;
    }
    void forget() { energy_step_ = -1; }  // the state changed from outside

    // The caller reads the energy after every step that is a multiple of `steps` (0: no promise).
    void audit_every(long steps) { audit_stride_ = steps; }
    // Whether the pass into step `next` should form the modal energy.
    bool audited(long next) const {
        // (at an audio rate every step: no integer division for it)
        return audit_stride_ == 1 || (audit_stride_ > 1 && next % audit_stride_ == 0);
    }

    // The damping terms a pass summed (ModalState::advance's return), and energy lost over a flight.
    void add_damping(double pass_losses) { damping_ += plan_->modal_loss_scale() * pass_losses; }
    void add_lost(double joules) { damping_ += joules; }
    double damping() const { return damping_; }  // since H^{1/2} (J)

private:
    const Plan* plan_;
    double damping_ = 0.0;
    mutable long energy_step_ = -1;
    mutable double modal_energy_ = 0.0;
    long audit_stride_ = 0;
};

}  // namespace fretbuzz
