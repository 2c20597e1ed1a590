#include "fretbuzz/scheme/VibratingString.hpp"

#include <stdexcept>
#include <string>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

VibratingString::VibratingString(const Plan& plan, std::span<const double> q0, std::span<const double> v0)
    : VibratingString(plan, q0, v0, {}) {}

VibratingString::VibratingString(const Plan& plan, std::span<const double> q0, std::span<const double> v0,
                                 std::span<const std::vector<double>> driven)
    : plan_(&plan),
      modes_(plan.propagator(), q0, v0),
      gestures_(plan, driven),
      contacts_(plan, gestures_),
      screening_(plan),
      ledger_(plan) {
    // The penalty scheme's string: a plan for the impact law is stepped by NewtonImpact, which
    // simulate() runs; the parts built on this string (the real-time engines, strings on a
    // bridge) do not run that law yet.
    if (plan.law() == ContactLawKind::impact)
        throw InputError("contact.law = \"impact\" is run by simulate() (fretbuzz run, sweeps, the set-up bench) "
                         "only: the real-time engine and strings on a bridge step the penalty law (use "
                         "contact.law = \"penalty\")");
}

void VibratingString::add_second_polarisation(std::span<const double> q0, std::span<const double> v0) {
    if (n_ != 0 || !plan_->two_polarisations())
        throw std::logic_error("Stepper::add_second_polarisation: only at n = 0 on a plan with two polarisations");
    y_.emplace(*plan_, q0, v0);
}

void VibratingString::perturb(std::span<const double> displacement, std::span<const double> velocity) {
    modes_.perturb(displacement, velocity, n_ != 0);
    if (n_ != 0) restart();
}

void VibratingString::silence() {
    modes_.silence();
    if (y_) y_->silence();
    restart();
}

void VibratingString::restart() {
    ++revision_;
    // What the passes formed belongs to the state before the change.
    ledger_.forget();
    pickups_.forget();
    pickups_.keep(modes_);
    contacts_.restart(modes_, screening_, n_);
}

bool VibratingString::finger_on(std::size_t f) const {
    if (f >= contacts_.parts().fingers().size()) throw std::out_of_range("Stepper: no finger " + std::to_string(f));
    return contacts_.parts().on(f);  // finger f is part f
}

void VibratingString::lift_finger(std::size_t f) {
    if (!finger_on(f)) return;
    contacts_.lift_finger(f);
    restart();  // its pad points go back to the obstacle's own solve
}

bool VibratingString::place_finger(std::size_t f, double centre_m, double width_m) {
    if (n_ == 0) throw std::logic_error("Stepper::place_finger: only after the first step");
    lift_finger(f);
    if (!contacts_.place_finger(f, centre_m, width_m)) return false;
    restart();  // u^n and u^{n-1} read where the pad is; the pad leaves the obstacle's solve
    contacts_.land(f);
    return true;
}

void VibratingString::press_finger(std::size_t f, double force_n, long ramp_steps) {
    contacts_.parts().finger(f).press(force_n, n_, ramp_steps);
}

void VibratingString::step() {
    if (n_ == 0) {
        first_step();
        if (y_) y_->first_step();
        return;
    }
    begin_step();
    solve_contacts();
    end_step();
}

void VibratingString::step_driven(const double* const* rows, std::size_t m, double* predicted) {
    if (!driven_only()) throw std::logic_error("VibratingString::step_driven: something else acts on the string");
    record_.loaded = false;
    if (gestures_.load(n_)) record_.mark_loaded();
    kernels::StepPass pass;
    gestures_.push_rows(plan_->force_to_displacement(), pass);
    pass.predict_rows = rows;
    pass.predict_count = m;
    pass.predicted = predicted;
    run_pass(pass);
    ++n_;
}

void VibratingString::first_step() {
    // q^1 is the exact free motion of each mode; contact acts from step 1 on.
    contacts_.first_step(modes_, screening_);
    pickups_.keep(modes_);
    n_ = 1;
}




long VibratingString::free_flight(const FreeFlight& flight, std::size_t head, std::span<const std::vector<double>> probes,
                                  std::vector<double>& u, std::vector<double>* v, bool step_head) {
    const long steps = flight.steps();
    // A finger may touch at any time: its pad points are solved every step (and awake exact points);
    // a gesture loads the string until its force has ended.
    if (n_ == 0 || !screening_.on() || !contacts_.quiet() || gestures_.act_from(n_)) return 0;
    ContactScheduler& scheduler = screening_.scheduler();
    scheduler.refresh_amplitudes(modes_.q(), modes_.d());  // the head changes below: the tail is summed anew
    const double energy_before = modal_energy();
    // With no per-step row wanted and no point due before its end, the whole flight is one jump.
    if (probes.empty() && !step_head && !y_ && flight.first() == 0 && scheduler.park_due(steps)) {
        land(flight, 0, steps);
        scheduler.end_steps(steps);
        return end_flight(steps, energy_before);
    }
    const long flown = screening_.fly_head(modes_, steps, head, probes, u, v);
    if (flown == steps) {
        land(flight, head, steps);
    } else {
        // Cut short (rare: a point may touch): the other modes take the flown steps one by
        // one, which allocates nothing (a real-time engine flies too).
        const std::size_t rest = modes_.size() - head;
        for (long m = 0; m < flown; ++m) modes_.step_modes(head, rest);
        pickups_.keep(modes_);
    }
    scheduler.set_head_modes(0);
    if (flown == 0) return 0;
    if (y_) y_->fly(flown, steps, head, probes);
    return end_flight(flown, energy_before);
}

void VibratingString::land(const FreeFlight& flight, std::size_t first, long flown) {
    ledger_.keep_modal_energy(n_ + flown, flight.jump_with_products(modes_.q(), modes_.d(), first, plan_->propagator(),
                                                                    pickups_.landing_rows(), pickups_.landing_values()));
    pickups_.landed(n_ + flown);
}

long VibratingString::end_flight(long flown, double energy_before) {
    contacts_.forget_forces();  // (and the forecasts, formed for points now asleep, before the flight)
    record_.touched_obstacle = false;
    n_ += flown;
    ledger_.add_lost(energy_before - modal_energy());
    record_.stats.free_flight_steps += flown;
    screening_.refresh_after_flight(modes_, n_);
    return flown;
}

}  // namespace fretbuzz
