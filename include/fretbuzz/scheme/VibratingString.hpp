#pragma once
// One string as the scheme steps it: its modal state (ModalState, over its plan's propagator),
// every contact on it with the parts playing it (ContactSet), the force gestures along it
// (ForceGestures), its free-flight scheduler (Screening), the rows read off it (Pickups), its
// energy ledger (EnergyLedger) and, where the case has two, its second polarisation. A step is
// three phases, in order (what an assembly interleaves with the links between its strings):
// begin_step (points due woken, the loads of step n), solve_contacts (the contact set's joint
// solve), end_step (the impulse, the one pass over the modes, friction, the screening's
// bookkeeping, the forces reported). Nothing here does I/O.
#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/scheme/ContactSet.hpp"
#include "fretbuzz/scheme/EnergyLedger.hpp"
#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Pickups.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Screening.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"

namespace fretbuzz {

class VibratingString {
public:
    // At n = 0 from modal displacement q0 and velocity v0 (dq/dt), on `plan` (which outlives it).
    VibratingString(const Plan& plan, std::span<const double> q0, std::span<const double> v0);
    // With loads driven from outside after the plan's gestures (ForceGestures), one per shape: a
    // bridge's end on the string (BridgeEnd).
    VibratingString(const Plan& plan, std::span<const double> q0, std::span<const double> v0,
                    std::span<const std::vector<double>> driven);

    // n -> n + 1 (the first step is the exact free motion), as its three phases.
    void step();
    void begin_step();
    void solve_contacts();
    void end_step();
    // Free flight (see Stepper::free_flight).
    long free_flight(const FreeFlight& flight, std::size_t head, std::span<const std::vector<double>> probes,
                     std::vector<double>& u, std::vector<double>* v, bool step_head);

    void add_second_polarisation(std::span<const double> q0, std::span<const double> v0);
    const SecondPolarisation* second_polarisation() const { return y_ ? &*y_ : nullptr; }
    void perturb(std::span<const double> displacement, std::span<const double> velocity);
    void restart();
    void silence();
    void lift_finger(std::size_t f);
    bool place_finger(std::size_t f, double centre_m, double width_m);
    void press_finger(std::size_t f, double force_n, long ramp_steps);
    bool finger_on(std::size_t f) const;

    const Plan& plan() const { return *plan_; }
    long step_index() const { return n_; }
    const ModalState& modes() const { return modes_; }
    // Of both polarisations (ModalState::subnormal_coordinates).
    std::size_t subnormal_coordinates() const {
        return modes_.subnormal_coordinates() + (y_ ? y_->subnormal_coordinates() : 0);
    }
    const ContactSet& contacts() const { return contacts_; }
    ContactSet& contacts() { return contacts_; }
    const ForceGestures& gestures() const { return gestures_; }
    ForceGestures& gestures() { return gestures_; }
    Pickups& pickups() { return pickups_; }
    const Pickups& pickups() const { return pickups_; }
    EnergyLedger& ledger() { return ledger_; }
    const EnergyLedger& ledger() const { return ledger_; }
    const StepRecord& record() const { return record_; }
    const Screening& screening() const { return screening_; }

    // The energy terms of the interval (t_{n-1}, t_n) (see Stepper).
    double modal_energy() const { return ledger_.modal_energy(modes_, n_); }
    double energy() const;
    double dissipated() const;
    double work() const;
    bool played() const { return !contacts_.parts().empty() || !gestures_.empty(); }

    // Nothing on the string but loads driven from outside (its bridge end): nothing can touch it,
    // no gesture of its own, one polarisation, past its first step. Its step is then one pass over
    // the modes (step_driven), as a sympathetic string's is.
    bool driven_only() const { return n_ != 0 && !y_ && plan_->forces().empty() && contacts_.none(); }
    // n -> n + 1 of a driven-only string: its driven loads pushed by rows in the pass, and
    // predicted[r] = rows[r] . (free q^{n+2}) formed in it for r < m (m <= kernels::kMaxPassRows).
    void step_driven(const double* const* rows, std::size_t m, double* predicted);
    // Counts the changes of state other than steps (a strike, a damping change, a finger: every
    // restart), so that what was formed for the next step can be known stale.
    long revision() const { return revision_; }

private:
    void first_step();
    void advance();  // the pass over the modes, the gestures' work around it where they load it
    // The plan's step kernel on `pass`, with the observation row and (where audited) the energy
    // of the state it leaves formed in it; its losses counted.
    void run_pass(kernels::StepPass& pass);
    // The flight's closing jump of modes [first, N) after `flown` steps, the modal energy and the
    // pickups' rows of the state it leaves formed in the same pass.
    void land(const FreeFlight& flight, std::size_t first, long flown);
    long end_flight(long flown, double energy_before);

    const Plan* plan_;
    long n_ = 0;
    ModalState modes_;
    ForceGestures gestures_;
    ContactSet contacts_;
    Screening screening_;
    Pickups pickups_;
    EnergyLedger ledger_;
    StepRecord record_;
    std::optional<SecondPolarisation> y_;  // empty with one polarisation (a string stays copyable)
    long revision_ = 0;
};

// The balance's terms, read at every audited step, and the step's phases, here so that step()
// runs them without a call each.
inline double VibratingString::energy() const {
    const double h = modal_energy() + contacts_.energy() + (y_ ? y_->energy() : 0.0);
    return played() ? h + contacts_.parts().energy() : h;
}

inline double VibratingString::dissipated() const {
    const double played_loss = contacts_.parts().loss();
    if (!y_) return ledger_.damping() + played_loss;
    return ledger_.damping() + played_loss + (y_->damping_dissipated() + y_->friction_dissipated());
}

inline double VibratingString::work() const {
    const double e = gestures_.add_work(contacts_.parts().work());
    return y_ ? e + y_->work() : e;
}

inline void VibratingString::begin_step() {
    contacts_.wake_due(screening_, modes_);
    record_.loaded = false;
    if (!gestures_.empty() && gestures_.load(n_)) record_.mark_loaded();
}

inline void VibratingString::solve_contacts() { contacts_.solve(modes_, gestures_, n_, record_); }

inline void VibratingString::end_step() {
    advance();
    if (y_) contacts_.step_friction(*y_, n_);
    contacts_.end_step(screening_, modes_, n_ + 1);
    ++n_;
}

inline void VibratingString::advance() {
    const bool loaded = record_.loaded;
    if (loaded) gestures_.begin_step(modes_);
    kernels::StepPass pass;
    contacts_.fill_pass(pass, gestures_);
    run_pass(pass);
    if (loaded) gestures_.end_step(modes_);
}

inline void VibratingString::run_pass(kernels::StepPass& pass) {
    const bool audited = ledger_.audited(n_ + 1);
    double energy = 0.0;
    if (plan_->options().fused_step) {
        if (pickups_.row() != nullptr) {
            pass.observe_row = pickups_.row();
            pass.observed = pickups_.observed();
        }
        if (audited) pass.energy = &energy;
    }
    ledger_.add_damping(modes_.advance(plan_->step_kernel(), pass));
    if (pass.energy != nullptr) ledger_.keep_modal_energy(n_ + 1, energy);
}

}  // namespace fretbuzz
