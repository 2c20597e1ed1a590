#pragma once
// Advances the string one time step with the scheme of Issanchou et al. 2017 (eq. 4),
// in modal coordinates:
//     q^{n+1} = C q^n - C~ q^{n-1} + (dt^2/mu) dx S^T f^n,
// where f^n_i = (Psi(eta_i^{n+1}) - Psi(eta_i^{n-1})) / (eta_i^{n+1} - eta_i^{n-1}) is found by a
// scalar solve at each grid point that can touch (ContactScheduler says which). It also keeps
// the discrete energy H^{n+1/2} and the energy dissipated by damping, every step, so that
// H + dissipated is constant to round-off. Fingers (see Finger) and pluckers (Pluck) are
// advanced with the string: their pad points are solved every step (a plucker's until it has
// left). Force gestures (ForceProfile) load the modes at their exact positions, explicitly,
// the contacts of the step being solved with their load. The balance becomes
// H - work + dissipated = constant (work: done by the pressing forces, the gestures and the
// pluckers' motions). Nothing here does I/O.
//
// The facade of an Assembly of one string: the string (VibratingString) owns its modal state,
// its contacts and played parts (ContactSet), its gestures, its free-flight scheduler, its
// pickups and its energy ledger; this class keeps the one-string interface every caller uses.
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/scheme/Assembly.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"

namespace fretbuzz {

class Stepper {
public:
    // Starts at n = 0 from modal displacement q0 and velocity v0 (dq/dt).
    Stepper(const Plan& plan, std::span<const double> q0, std::span<const double> v0) : assembly_(plan, q0, v0) {}

    // n -> n + 1. The first step is the exact free motion; the others are the scheme.
    void step() { assembly_.step(); }
    // Free flight over the next M = flight.steps() steps while no point can touch: only the
    // first `head` modes are stepped (the probes, mode shapes used up to `head`, are sampled
    // at every step into `u`, and `v` for velocities if not null: one row of probes.size()
    // values per step); the other modes jump in closed form at the end, and checks of
    // sleeping points use the head modes plus a bound on the rest. Stops early if a point
    // might touch (the state is then complete at that step). Returns the steps flown
    // (0 if a flight cannot start). Energy and dissipation stay exact. step_head: the head
    // modes step one by one even with no probe, as they would for probes (a caller that makes
    // the per-step signal elsewhere, from the flight's start, and wants the same steps, bit for
    // bit; otherwise a flight with no point due is one jump of every mode).
    long free_flight(const FreeFlight& flight, std::size_t head, std::span<const std::vector<double>> probes,
                     std::vector<double>& u, std::vector<double>* v, bool step_head = false) {
        return string().free_flight(flight, head, probes, u, v, step_head);
    }

    // Gives the string its second polarisation y (plan.two_polarisations() must hold), from
    // modal displacement and velocity at n = 0; before the first step. Without it the
    // stepper runs z alone, exactly as it always has.
    void add_second_polarisation(std::span<const double> q0, std::span<const double> v0) {
        string().add_second_polarisation(q0, v0);
    }
    const SecondPolarisation* second_polarisation() const { return string().second_polarisation(); }

    // Adds a displacement and a velocity (modal, dq/dt) to the current state, as an external
    // impulse between two steps would: q^n += dq, q^{n-1} += dq - dv dt. The energy H^{n-1/2}
    // changes by the work done; the caller reads it with energy() before and after.
    void perturb(std::span<const double> displacement, std::span<const double> velocity) {
        string().perturb(displacement, velocity);
    }
    // Takes the state and the plan as they are now (after perturb, or after the plan's contact
    // law or damping changed): every obstacle point is looked at again and the contact energy
    // recomputed. Allocates nothing.
    void restart() { string().restart(); }
    // Puts the string at rest (q = d = 0), keeping the step count and the losses so far.
    void silence() { string().silence(); }
    // Fingers at run time (a real-time engine), after the first step; none allocates, and the
    // caller counts the energy each adds or removes (the finger's own, and the restart's).
    // lift_finger: finger f leaves the string at once (its motion and contact are forgotten,
    // its pad points go back to the obstacle's solve, it is no longer stepped).
    void lift_finger(std::size_t f) { string().lift_finger(f); }
    // place_finger: finger f (lifted first if it was on) lands at rest on the string with its
    // pad centred at centre_m (width at most its spec's). False, and the finger stays off, if
    // the pad would overlap another finger's or a plucker's (a force gesture claims no pad).
    bool place_finger(std::size_t f, double centre_m, double width_m) { return string().place_finger(f, centre_m, width_m); }
    // press_finger: from this step on, its pressing force ramps to force_n over ramp_steps steps.
    void press_finger(std::size_t f, double force_n, long ramp_steps) { string().press_finger(f, force_n, ramp_steps); }
    bool finger_on(std::size_t f) const { return string().finger_on(f); }  // (std::out_of_range for no finger f)

    long step_index() const { return string().step_index(); }
    double time() const { return static_cast<double>(step_index()) * string().plan().dt(); }
    std::span<const double> modal_displacement() const { return string().modes().q(); }  // q^n
    std::span<const double> modal_difference() const { return string().modes().d(); }    // q^n - q^{n-1}
    std::size_t subnormal_coordinates() const { return string().subnormal_coordinates(); }
    // u(x, t_n) = phi(x) . q^n
    double displacement(std::span<const double> mode_shapes) const { return string().modes().at(mode_shapes.data()); }
    // (u(x, t_n) - u(x, t_{n-1})) / dt
    double velocity(std::span<const double> mode_shapes) const;
    // An observation row (a pickup's mode shapes, kept by the caller, which may change its
    // values and then calls observe again): observation() is displacement(mode_shapes), formed
    // by the step's own pass over the modes (one pass fewer).
    void observe(std::span<const double> mode_shapes) { string().pickups().observe(mode_shapes.data(), string().modes()); }
    double observation() const {
        return string().pickups().observation(string().plan().options().fused_step, string().modes());
    }
    // Rows read after free flights (an output row's probes and bridge, kept by the caller, which
    // calls observe_rows again after changing their values): out[r] = displacement(rows[r]),
    // formed by a flight's closing jump in its own pass over the modes when it can.
    void observe_rows(std::span<const double* const> rows) { string().pickups().observe_rows(rows); }
    void row_displacements(std::span<double> out) const {
        string().pickups().row_displacements(out, step_index(), string().modes());
    }
    // The caller reads energy() after every step that is a multiple of `steps` (its audit at
    // each output row; 0: no such promise): the pass that steps the modes into such a step
    // forms the modal energy too (one pass fewer at an audio rate).
    void audit_every(long steps) { string().ledger().audit_every(steps); }

    // Energy terms of the interval (t_{n-1}, t_n), defined for n >= 1 (joules).
    double energy() const { return string().energy(); }  // H^{n-1/2}: string, obstacle contact and fingers
    double contact_energy() const { return string().contacts().energy(); }  // dx (Psi(eta^n) + Psi(eta^{n-1})) / 2
    // Losses since H^{1/2}: modal damping plus the fingers' contact losses (and with two
    // polarisations the y modes' damping and the friction).
    double dissipated() const { return string().dissipated(); }
    double damping_dissipated() const { return string().ledger().damping(); }
    double finger_energy() const { return played_parts().energy(); }  // kinetic and contact energy of the fingers
    double finger_loss() const { return played_parts().loss(); }      // their contact losses so far (>= 0)
    double work() const { return string().work(); }  // work of the external forces (pressing forces, gestures) so far
    const std::vector<Finger>& fingers() const { return played_parts().fingers(); }
    // Whether fingers, gestures or pluckers act (the balance then counts their work).
    bool played() const { return string().played(); }
    const std::vector<Pluck>& plucks() const { return played_parts().plucks(); }
    // Every part playing the string at a pad, fingers first, then pluckers (the case's order).
    const PlayedParts& played_parts() const { return string().contacts().parts(); }
    // The force gestures along z (the case's order).
    const std::vector<ForceProfile>& gestures() const { return string().gestures().list(); }

    // Whether the obstacle pushed on the string in the last step (forces() also holds the
    // fingers' and pluckers' forces at their pads, a plucker at its exact position at its
    // nearest grid point; a gesture's load is not a force there).
    bool touched_obstacle() const { return string().record().touched_obstacle; }
    // Points with a non-zero force in the last step and that force (N/m).
    std::span<const std::pair<std::size_t, double>> forces() const { return string().contacts().forces(); }
    const StepStatistics& statistics() const { return string().record().stats; }
    const ContactScheduler& scheduler() const { return string().screening().scheduler(); }

    // The assembly behind the facade, and its one string.
    const Assembly& assembly() const { return assembly_; }
    VibratingString& string() { return assembly_.string(0); }
    const VibratingString& string() const { return assembly_.string(0); }

private:
    Assembly assembly_;
};

}  // namespace fretbuzz
