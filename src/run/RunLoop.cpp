#include "RunLoop.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/BridgeForce.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz {

RunLayout layout_of(const Case& c) {
    RunLayout layout;
    layout.source = &c;
    layout.dt = 1.0 / c.run.sample_rate_hz;
    layout.steps = std::lround(c.run.duration_s * c.run.sample_rate_hz);
    layout.output_stride = output_stride(c);
    layout.output_rate_hz = c.run.sample_rate_hz / static_cast<double>(layout.output_stride);
    layout.observation_points_m = c.observation_points_m;
    layout.fingers = c.fingers.size() + c.forces.size() + c.plucks.size();
    layout.polarisations = c.polarisation.count;
    return layout;
}

RunSummary summary_of(const Case& c, const Plan& plan, const RunLayout& layout) {
    RunSummary s;
    s.case_name = c.name;
    s.sample_rate_hz = c.run.sample_rate_hz;
    s.duration_s = static_cast<double>(layout.steps) / c.run.sample_rate_hz;
    s.steps = layout.steps;
    s.modes = c.mode_count();
    s.polarisations = c.two_polarisations() ? 2 : 1;
    s.output_rate_hz = layout.output_rate_hz;
    s.lossless = plan.propagator().lossless();
    s.mode_choice = c.mode_choice.empty() ? "as the case gives" : c.mode_choice;
    s.warnings = c.warnings;
    s.warnings.insert(s.warnings.end(), plan.warnings().begin(), plan.warnings().end());
    s.contact_law = contact_law_name(plan.law());
    s.restitution = plan.restitution();
    return s;
}

namespace {

PlanOptions with_screening(PlanOptions options, bool screen) {
    options.screen_contacts = screen;
    return options;
}

}  // namespace

RunLoop::RunLoop(const Case& c, std::span<RunObserver* const> observers, const RunOptions& options)
    : case_(c),
      observers_(observers),
      options_(options),
      start_(Clock::now()),
      last_progress_(start_),
      screening_(choose_screening(c, options.plan, options.free_flight && output_stride(c) > 1)),
      plan_(c, 1.0 / c.run.sample_rate_hz, with_screening(options.plan, screening_.screen)),
      layout_(layout_of(c)),
      stepper_(plan_, plan_.oriented(along_polarisation(c.initial_displacement, c, false)),
               plan_.oriented(along_polarisation(c.initial_velocity, c, false))) {
    // Signals are linear in q: mirroring their coefficients mirrors them back.
    for (double x : c.observation_points_m) shapes_.push_back(plan_.oriented(plan_.basis().mode_shapes_at(x)));
    bridge_ = plan_.oriented(bridge_force_coefficients(c));
    for (const std::vector<double>& shape : shapes_) row_rows_.push_back(shape.data());
    row_rows_.push_back(bridge_.data());
    row_values_.resize(row_rows_.size());
    u_.resize(shapes_.size());
    step_u_.resize(shapes_.size());
    if (c.two_polarisations()) {
        stepper_.add_second_polarisation(along_polarisation(c.initial_displacement, c, true),
                                         along_polarisation(c.initial_velocity, c, true));
        // y is never mirrored: its shapes are the plain mode shapes.
        for (double x : c.observation_points_m) shapes_y_.push_back(plan_.basis().mode_shapes_at(x));
        y_.resize(shapes_.size());
    }

    summary_ = summary_of(c, plan_, layout_);
    summary_.screened = screening_.screen;
    summary_.screening = screening_.reason;
    summary_.fingers = c.fingers.size();
    summary_.gestures = c.forces.size() + c.plucks.size();
}

RunSummary RunLoop::run() {
    const SubnormalFlush flushed;  // for every step of the run, on whichever thread runs it
    connect_observers();
    plan_free_flight();
    report_observation();
    if (audio_wanted_) report_step();
    report_snapshots();
    while (n_ < layout_.steps) {
        // A signal (Ctrl-C) stops the run between steps; the outputs then discard their files.
        throw_if_stopped();
        if (const long flown = fly(); flown > 0) {
            n_ += flown;
            report_flight(flown);
            continue;
        }
        if (band_) band_->resume(n_, stepper_.modal_displacement(), stepper_.modal_difference());
        stepper_.step();
        ++n_;
        if (band_) band_->stepped(n_);
        after_step();
    }
    // The last segment ends at the run's end, as a single stream would.
    if (band_) band_->resume(n_, stepper_.modal_displacement(), stepper_.modal_difference());
    if (per_step_queue_) per_step_queue_->drain();
    if (audio_wanted_) audio_->finish(summary_.duration_s);
    // The summary's final energy is the state's at the last step, whatever the output rate.
    if (n_ > 0 && audited_step_ != n_) audit_energy();
    finish_summary();
    for (RunObserver* o : observers_) o->finish(summary_);
    throw_if_stopped();
    return summary_;
}

void RunLoop::connect_observers() {
    for (RunObserver* o : observers_) o->begin(layout_);
    snapshots_.emplace(case_, plan_, observers_);
    audio_.emplace(observers_, case_.run.sample_rate_hz, shapes_.size(), case_.polarisation.count);
    audio_wanted_ = !audio_->empty();
    velocity_wanted_ = audio_->wants_velocity();
    step_v_.resize(velocity_wanted_ ? shapes_.size() : 0);
    if (options_.per_step_thread && !case_.two_polarisations() && audio_wanted_)
        per_step_queue_.emplace(
            [&audio = *audio_](const double* u, const double* v, std::size_t count) { audio.frames(u, v, count); },
            shapes_.size(), velocity_wanted_);
    // The output rows' products, formed by each flight's closing jump (only when someone reads them).
    if (!observers_.empty()) stepper_.observe_rows(row_rows_);
    // One probe read every step (the usual pickup): the step's own pass forms it.
    if (audio_wanted_ && shapes_.size() == 1) stepper_.observe(shapes_[0]);
    // The energy balance is audited at every output row, outputs or not (report_output).
    stepper_.audit_every(layout_.output_stride);
}

void RunLoop::plan_free_flight() {
    // Free flight jumps whole output intervals, so it needs intervals longer than a step. Meanwhile
    // the audio is fed only the modes below 0.6 x its rate (the resampler removes the others
    // anyway). Switching the out-of-band modes off and on at the edges of those stretches
    // leaves a trace of about -110 dB relative to the signal (tests/test_long_run.cpp);
    // `fretbuzz run --no-free-flight` avoids it.
    if (!(options_.free_flight && plan_.options().screen_contacts && layout_.output_stride > 1)) return;
    const double band_hz = audio_wanted_ ? 0.6 * audio_->lowest_rate_hz() : 0.0;
    while (head_ < case_.mode_count() && case_.modes.frequency_hz[head_] < band_hz) ++head_;
    check_head_ = std::min(kMinimumFlightModes, case_.mode_count());
    head_ = std::max(head_, check_head_);
    flight_.emplace(plan_.propagator(), layout_.output_stride);
    // The band synthesises z only: with a second polarisation, y's audio comes from per-step rows.
    if (options_.closed_form_audio && case_.polarisation.count == 1 &&
        AudioBand::applies(*audio_, plan_.propagator(), head_, layout_.output_stride))
        band_.emplace(*audio_, plan_.propagator(), head_, shapes_, layout_.output_stride,
                      per_step_queue_ ? &*per_step_queue_ : nullptr);
}

long RunLoop::fly() {
    const long stride = layout_.output_stride;
    if (!flight_ || n_ <= 1 || n_ % stride != 0 || n_ + stride > layout_.steps || snapshots_->due_within(n_, stride)) return 0;
    // Per-step probe signals only for the observers that read them, and only where the band
    // cannot make them: out of it, it makes a flight's frames from the flight's start, on the
    // per-step thread. The flight steps the audio modes one by one all the same: its checks
    // use them (with fewer, flights stop at other steps, and the sound near contacts is
    // worse), and so the string moves as it did with the frames made here, bit for bit.
    const bool in_band = band_ && band_->in_band();
    const bool frames_by_band = band_ && !in_band;
    if (frames_by_band) band_->flight_start(stepper_.modal_displacement(), stepper_.modal_difference());
    const std::span<const std::vector<double>> probes = !audio_wanted_ || band_
                                                            ? std::span<const std::vector<double>>()
                                                            : std::span<const std::vector<double>>(shapes_);
    return stepper_.free_flight(*flight_, in_band ? check_head_ : head_, probes, flight_u_,
                                velocity_wanted_ ? &flight_v_ : nullptr, frames_by_band);
}

void RunLoop::after_step() {
    if (!stepper_.forces().empty()) {
        if (stepper_.touched_obstacle()) {  // the fingers' and gestures' own forces are counted apart
            if (summary_.first_contact_s < 0.0) summary_.first_contact_s = stepper_.time();
            summary_.last_contact_s = stepper_.time();
        }
        if (observers_.empty()) {
            // no one to tell (a run for its summary: a sweep's, a benchmark's)
        } else if (plan_.orientation() > 0.0) {
            for (RunObserver* o : observers_) o->contacts(stepper_.time(), stepper_.forces());
        } else {
            mirrored_forces_.assign(stepper_.forces().begin(), stepper_.forces().end());
            for (auto& force : mirrored_forces_) force.second = plan_.oriented(force.second);
            for (RunObserver* o : observers_) o->contacts(stepper_.time(), mirrored_forces_);
        }
    }
    if (audio_wanted_) report_step();
    if (!snapshots_->empty()) report_snapshots();
    if (on_output_row() || n_ == 1) report_output();
    if ((n_ & 0xfff) == 0) {
        // Between output rows too: a run gone to NaN stops within a few thousand steps.
        if (audited_step_ != n_) check_state(stepper_.energy());
        if (options_.progress) report_progress();
    }
}

void RunLoop::report_observation() {
    if (observers_.empty()) return;  // the probe products only when someone reads them
    if (const SecondPolarisation* y = stepper_.second_polarisation()) {
        for (std::size_t p = 0; p < shapes_y_.size(); ++p) y_[p] = y->displacement(shapes_y_[p]);
        for (RunObserver* o : observers_) o->observation_y(stepper_.time(), y_);
    }
    double force = 0.0;
    if (step_u_at_ == n_) {
        u_ = step_u_;  // at an output rate equal to fs, the per-step products of this very step
        force = stepper_.displacement(bridge_);
    } else {
        // The probes and the bridge in one pass over the modes (each the same sum as a dot),
        // or as the flight that ended here formed them.
        stepper_.row_displacements(row_values_);
        std::copy(row_values_.begin(), row_values_.end() - 1, u_.begin());
        force = row_values_.back();
    }
    for (RunObserver* o : observers_) o->observation(stepper_.time(), u_);
    for (RunObserver* o : observers_) o->bridge_force(stepper_.time(), force);
}

void RunLoop::report_step() {
    if (const SecondPolarisation* y = stepper_.second_polarisation())
        for (std::size_t p = 0; p < shapes_y_.size(); ++p) y_[p] = y->displacement(shapes_y_[p]);
    if (shapes_.size() == 1)
        step_u_[0] = stepper_.observation();  // displacement(shapes_[0]), to round-off
    else
        for (std::size_t p = 0; p < shapes_.size(); ++p) step_u_[p] = stepper_.displacement(shapes_[p]);
    step_u_at_ = n_;
    for (std::size_t p = 0; p < step_v_.size(); ++p) step_v_[p] = n_ > 0 ? stepper_.velocity(shapes_[p]) : 0.0;
    deliver_frame(step_u_, step_v_, y_);
}

void RunLoop::deliver_frame(std::span<const double> u, std::span<const double> v, std::span<const double> y) {
    if (per_step_queue_)
        per_step_queue_->frame(u, v);  // (one polarisation)
    else
        audio_->frame(u, v, y);
}

void RunLoop::report_flight(long flown) {
    const bool complete = flown == layout_.output_stride;  // a complete flight ends on an output step
    const std::span<const double> q = stepper_.modal_displacement(), d = stepper_.modal_difference();
    if (band_ && band_->in_band()) {
        // No probe rows were taken; cut short, contact may come: the per-step signal resumes here.
        if (complete)
            band_->flown(n_, true, q, d);
        else
            band_->resume(n_, q, d);
    } else if (band_) {
        band_->flight_frames(flown);
        band_->flown(n_, complete, q, d);
    } else {
        report_flight_rows(flown);
    }
    if (complete) {
        report_snapshots();
        report_output();
    }
    if (options_.progress) report_progress();
}

void RunLoop::report_flight_rows(long flown) {
    const std::size_t width = shapes_.size();
    // Without audio the flight records no probe rows (the buffers stay empty).
    const SecondPolarisation* y = stepper_.second_polarisation();
    for (long m = 0; m < flown && audio_wanted_; ++m) {
        const auto row = static_cast<std::size_t>(m) * width;
        const std::span<const double> row_u(flight_u_.data() + row, width);
        const std::span<const double> row_v =
            velocity_wanted_ ? std::span<const double>(flight_v_.data() + row, width) : std::span<const double>();
        deliver_frame(row_u, row_v, y != nullptr ? std::span<const double>(y->flight_rows().data() + row, width)
                                                 : std::span<const double>());
    }
}

void RunLoop::report_snapshots() { snapshots_->report(n_, stepper_.time(), stepper_.modal_displacement()); }

double RunLoop::audit_energy() {
    const double h = stepper_.energy();
    check_state(h);
    if (!stepper_.played()) {
        audit_.record(h, stepper_.dissipated());
        audit_.write_to(summary_);
    } else {
        audit_.record(h, stepper_.dissipated(), stepper_.work());
        audit_.write_to(summary_);
        summary_.work_j = stepper_.work();
        summary_.finger_energy_final_j = stepper_.finger_energy();
        summary_.finger_loss_j = stepper_.finger_loss();
    }
    if (const SecondPolarisation* y = stepper_.second_polarisation()) {
        summary_.energy_y_final_j = y->energy();
        summary_.damping_y_j = y->damping_dissipated();
        summary_.friction_j = y->friction_dissipated();
        summary_.max_friction_iterations = y->max_iterations();
    }
    audited_step_ = n_;
    return h;
}

void RunLoop::report_bad_state(double h) const {
    // Name the first quantity that went bad: a modal coordinate, else an energy term.
    std::string what = std::isfinite(h) ? "the dissipated energy" : "the energy";
    const std::span<const double> q = stepper_.modal_displacement();
    const std::span<const double> d = stepper_.modal_difference();
    for (std::size_t j = 0; j < q.size(); ++j) {
        if (!std::isfinite(q[j]) || !std::isfinite(d[j])) {
            what = "the displacement of mode " + std::to_string(j + 1) + " (q_" + std::to_string(j + 1) + " = " +
                   std::to_string(std::isfinite(q[j]) ? d[j] : q[j]) + ")";
            break;
        }
    }
    if (what == "the energy" && !std::isfinite(stepper_.contact_energy())) what = "the contact energy";
    throw SolverError("the simulation produced a non-finite value at t = " + std::to_string(stepper_.time()) +
                      " s (step " + std::to_string(n_) + "): " + what +
                      "; check the case's extreme values (string.mu, contact.K, contact.alpha, the modes' sigma)");
}

void RunLoop::report_output() {
    const double h = audit_energy();
    if (!on_output_row() || observers_.empty()) return;  // audited, reported to no one
    report_observation();
    const double t_half = (static_cast<double>(n_) - 0.5) * layout_.dt;
    if (stepper_.played()) report_played();
    if (const SecondPolarisation* y = stepper_.second_polarisation())
        for (RunObserver* o : observers_)
            o->polarisation_energy(y->energy(), y->damping_dissipated(), y->friction_dissipated());
    // Once, not per observer (the calls between are virtual: the compiler would sum them again)
    const double contact = stepper_.contact_energy(), dissipated = stepper_.dissipated();
    for (RunObserver* o : observers_) o->energy(t_half, h, contact, dissipated);
}

void RunLoop::report_played() {
    for (RunObserver* o : observers_) o->finger_energy(stepper_.finger_energy(), stepper_.work(), stepper_.finger_loss());
    played_heights_.clear();
    // The case's order: fingers, force gestures (no body: NaN), pluckers.
    const PlayedParts& parts = stepper_.played_parts();
    const std::size_t fingers = stepper_.fingers().size();
    for (std::size_t k = 0; k <= parts.size(); ++k) {
        if (k == fingers) played_heights_.insert(played_heights_.end(), stepper_.gestures().size(), std::nan(""));
        if (k < parts.size()) played_heights_.push_back(plan_.oriented(parts[k].body_height()));
    }
    for (RunObserver* o : observers_) o->played_heights(played_heights_);
}

void RunLoop::report_progress() {
    const auto now = Clock::now();
    if (now - last_progress_ < std::chrono::milliseconds(500)) return;
    last_progress_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double fraction = static_cast<double>(n_) / static_cast<double>(layout_.steps);
    options_.progress({fraction, stepper_.time(), elapsed, elapsed * (1.0 - fraction) / fraction});
}

void RunLoop::finish_summary() {
    const StepStatistics& stats = stepper_.statistics();
    const double steps = static_cast<double>(layout_.steps);
    summary_.contact_steps = stats.contact_steps;
    summary_.finger_contact_steps = stats.played_steps;
    summary_.max_newton_iterations = stats.max_newton_iterations;
    summary_.mean_points_solved = layout_.steps > 0 ? stats.points_solved / steps : 0.0;
    summary_.free_flight_fraction = layout_.steps > 0 ? static_cast<double>(stats.free_flight_steps) / steps : 0.0;
    summary_.subnormal_coordinates = stepper_.subnormal_coordinates();
    summary_.wall_seconds = std::chrono::duration<double>(Clock::now() - start_).count();
    summary_.steps_per_second = summary_.wall_seconds > 0.0 ? steps / summary_.wall_seconds : 0.0;
}

}  // namespace fretbuzz
