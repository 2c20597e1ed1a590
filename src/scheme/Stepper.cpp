#include "fretbuzz/scheme/Stepper.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
// Free modes decay: tighten the speed bound this often even when nothing touches.
constexpr long kSpeedRefreshSteps = 1L << 14;

// The plan's played parts of one kind (its specs, in order), built on its grid and obstacle.
template <class Part, class Spec>
std::vector<Part> parts_of(const Plan& plan, const std::vector<Spec>& specs) {
    std::vector<Part> parts;
    parts.reserve(specs.size());
    for (const Spec& spec : specs)
        parts.emplace_back(spec, plan.basis().grid_step(), plan.obstacle(), plan.contact(), plan.dt(),
                           plan.force_to_displacement());
    return parts;
}

// At their exact positions (plucks_exact), each plucker's scalar equation is the whole contact
// solve of a step where it acts alone, else it is one more equation in the system of the exact
// points, the other pluckers, the grid's obstacle points and the fingers (PointContact). Force
// gestures load the string explicitly.
std::vector<Pluck> plucks_of(const Plan& plan) {
    if (!plucks_exact(plan.plucks().size())) return parts_of<Pluck>(plan, plan.plucks());
    std::vector<Pluck> plucks;
    plucks.reserve(plan.plucks().size());
    for (const PluckSpec& spec : plan.plucks())
        plucks.emplace_back(spec, pad_mean_shapes(plan.basis(), spec.position_m, spec.width_m), plan.contact(), plan.dt(),
                            plan.force_to_displacement());
    return plucks;
}

// The case's force gestures along z, each at its exact position.
std::vector<ForceProfile> gestures_of(const Plan& plan) {
    std::vector<ForceProfile> gestures;
    for (const ForceSpec& spec : plan.forces())
        gestures.emplace_back(spec, plan.basis(), plan.dt(), -spec.direction * polarisation_share(spec.angle_deg, false));
    return gestures;
}
}  // namespace

PlayedParts::PlayedParts(std::vector<Finger> fingers, std::vector<Pluck> plucks)
    : fingers_(std::move(fingers)), plucks_(std::move(plucks)) {
    link();
    on_.assign(parts_.size(), 1);
}

PlayedParts::PlayedParts(const PlayedParts& other)
    : fingers_(other.fingers_), plucks_(other.plucks_), on_(other.on_) {
    link();
}

void PlayedParts::link() {
    parts_.clear();
    for (Finger& f : fingers_) parts_.push_back(&f);
    for (Pluck& p : plucks_) parts_.push_back(&p);
}

Stepper::Stepper(const Plan& plan, std::span<const double> q0, std::span<const double> v0)
    : plan_(plan),
      scheduler_(plan),
      screening_(plan.options().screen_contacts),
      q_(q0.begin(), q0.end()),
      d_(q0.size(), 0.0),
      v0_(v0.begin(), v0.end()),
      predicted_(q0.size(), 0.0),
      impulse_(q0.size(), 0.0),
      grid_(q0.size(), 0.0),
      eta_prev_(q0.size(), 0.0),
      eta_curr_(q0.size(), 0.0),
      parts_(parts_of<Finger>(plan, plan.fingers()), plucks_of(plan)),
      gestures_(gestures_of(plan)),
      gesture_load_(gestures_.size(), 0.0),
      on_pad_(q0.size(), 0),
      points_(plan.point_contact().make_state()),
      point_predicted_(plan.point_contact().size(), 0.0),
      point_forecast_(plan.point_contact().size(), 0.0) {
    // Every list the step fills is bounded by the grid: reserve it once, so that a running
    // stepper never allocates (real-time use).
    active_.reserve(q0.size());
    solve_a_.reserve(q0.size());
    solve_b_.reserve(q0.size());
    solutions_.reserve(q0.size());
    due_.reserve(2 * q0.size() + 16);
    forces_.reserve(q0.size());
    pushes_.reserve(q0.size() + plan.point_contact().size());
    rubbing_.reserve(q0.size());
    pad_w_.reserve(q0.size());  // any pad, even one moved at run time (place_finger)
    pad_f_.reserve(q0.size());
    joint_pads_.reserve(q0.size());
    joint_w_.reserve(q0.size());
    joint_trial_.reserve(q0.size());
    others_.reserve(q0.size());
    std::size_t k = 0;  // the parts are in the specs' order
    for (const FingerSpec& spec : plan.fingers()) claim_pad(parts_[k++].pad(), spec.key);
    for (const PluckSpec& spec : plan.plucks()) claim_pad(parts_[k++].pad(), spec.key);
    const PointContact& points = plan.point_contact();
    // s . phi(x_p) of a pad's shape s with each exact point's row, appended to `out`.
    const auto at_points = [&](std::span<const double> s, std::vector<double>& out) {
        for (std::size_t p = 0; p < points.size(); ++p) out.push_back(kernels::dot(s.data(), points.row(p).data(), s.size()));
    };
    for (const ForceProfile& g : gestures_) at_points(g.shape(), gesture_at_points_);
    if (!parts_.plucks().empty() && parts_.plucks().front().exact()) {
        first_pluck_ = parts_.fingers().size();
        exact_plucks_ = parts_.plucks().size();
        const auto shape = [&](std::size_t j) { return parts_.plucks()[j].shape(); };
        for (const ForceProfile& g : gestures_)
            for (std::size_t j = 0; j < exact_plucks_; ++j)
                gesture_at_pluck_.push_back(kernels::dot(g.shape().data(), shape(j).data(), q0.size()));
        const std::size_t n = q0.size();
        // m_i = s . S_i: each pad's coupling to the grid's obstacle and finger pad points
        const bool beside_grid = !plan.obstacle_points().empty() || !plan.fingers().empty();
        if (beside_grid) pluck_at_grid_.resize(exact_plucks_ * n);
        for (std::size_t j = 0; j < exact_plucks_; ++j) {
            at_points(shape(j), pluck_at_points_);
            if (beside_grid) plan.basis().to_grid(shape(j), std::span<double>(pluck_at_grid_).subspan(j * n, n));
            for (std::size_t b = 0; b < exact_plucks_; ++b)
                pluck_cross_.push_back(kernels::dot(shape(j).data(), shape(b).data(), n));
        }
        pluck_load_.assign(exact_plucks_, 0.0);
        acting_plucks_.reserve(exact_plucks_);
        pads_.reserve(exact_plucks_);
        pad_cross_.reserve(exact_plucks_ * exact_plucks_);
    }
}

void Stepper::add_second_polarisation(std::span<const double> q0, std::span<const double> v0) {
    if (n_ != 0 || !plan_.two_polarisations())
        throw std::logic_error("Stepper::add_second_polarisation: only at n = 0 on a plan with two polarisations");
    y_.emplace(plan_, q0, v0);
}

void Stepper::perturb(std::span<const double> displacement, std::span<const double> velocity) {
    const double dt = plan_.dt();
    if (n_ == 0) {
        for (std::size_t j = 0; j < q_.size(); ++j) {
            q_[j] += displacement[j];
            v0_[j] += velocity[j];
        }
        return;
    }
    for (std::size_t j = 0; j < q_.size(); ++j) {
        q_[j] += displacement[j];
        d_[j] += velocity[j] * dt;
    }
    restart();
}

void Stepper::silence() {
    std::fill(q_.begin(), q_.end(), 0.0);
    std::fill(d_.begin(), d_.end(), 0.0);
    std::fill(v0_.begin(), v0_.end(), 0.0);
    if (y_) y_->silence();
    restart();
}

void Stepper::restart() {
    // What the passes formed belongs to the state before the change.
    energy_step_ = flight_rows_step_ = point_forecast_step_ = -1;
    forecast_.count = 0;
    keep_observation();
    if (n_ == 0) return;  // the first step looks at everything anyway
    // u^n into grid_, u^{n-1} = S (q - d) into impulse_ (scratch until the next impulse), where
    // they are read: at the obstacle's points and the pads of the parts on the string. By
    // rows where these are at most the transform threshold (a real-time engine sets it beyond
    // every count where FFTW's transform would allocate), else by two transforms.
    const std::vector<std::size_t>& points = plan_.obstacle_points();
    if (points.size() + pad_points_ > plan_.transform_threshold()) {
        for (std::size_t j = 0; j < q_.size(); ++j) predicted_[j] = q_[j] - d_[j];
        plan_.basis().to_grid(predicted_, impulse_);
        plan_.basis().to_grid(q_, grid_);
    } else {
        const auto by_row = [&](std::size_t i) {
            kernels::dot_current_previous(plan_.basis().row(i).data(), q_.data(), d_.data(), q_.size(), grid_[i], impulse_[i]);
        };
        for (std::size_t i : points) by_row(i);
        parts_.each_on([&](const PlayedPart& part) {
            for (std::size_t i : part.pad()) by_row(i);
        });
    }
    scheduler_.clear();
    active_.clear();
    psi_prev_ = psi_curr_ = 0.0;
    plan_.point_contact().start(points_, q_, d_);
    if (screening_) {
        scheduler_.update_speed(q_, d_);
        next_speed_refresh_ = n_ + kSpeedRefreshSteps;
    }
    classify_exact_points();
    parts_.each_on([&](PlayedPart& part) { part.read_obstacle(plan_.obstacle()); });
    for (std::size_t j = 0; j < exact_plucks_; ++j) {
        if (!exact_pluck_on(j)) continue;
        double u_now = 0.0, u_before = 0.0;
        kernels::dot_current_previous(exact_pluck(j).shape().data(), q_.data(), d_.data(), q_.size(), u_now, u_before);
        start_exact_pluck(j, u_before, u_now);
    }
    classify_points(grid_, impulse_);
}

bool Stepper::any_exact_pluck_on() const {
    for (std::size_t j = 0; j < exact_plucks_; ++j)
        if (exact_pluck_on(j)) return true;
    return false;
}

void Stepper::start_exact_pluck(std::size_t j, double u_before, double u_now) {
    exact_pluck(j).start(std::span<const double>(&u_before, 1), std::span<const double>(&u_now, 1));
}

bool Stepper::exact_plucks_act() {
    acting_plucks_.clear();  // (within its reserved room)
    for (std::size_t j = 0; j < exact_plucks_; ++j) {
        if (!exact_pluck_on(j)) continue;
        if (exact_pluck(j).left()) {
            parts_.set_on(first_pluck_ + j, false);
            continue;
        }
        acting_plucks_.push_back(j);
    }
    return !acting_plucks_.empty();
}

double Stepper::exact_pluck_prediction(std::size_t j) const {
    // w_s = s . (free q^{n+1}), shifted by the gestures' loads of this step (before the pluckers' own).
    const ModalPropagator& prop = plan_.propagator();
    const double* row = parts_.plucks()[j].shape().data();
    double w = 0.0;
    kernels::predict_dot_rows(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), &row, 1, q_.size(), &w);
    if (loaded_)
        for (std::size_t g = 0; g < gestures_.size(); ++g)
            w += plan_.force_to_displacement() * gesture_load_[g] * gesture_at_pluck_[g * exact_plucks_ + j];
    return w;
}

void Stepper::take_pluck_force(std::size_t j, double force) {
    stats_.max_newton_iterations = std::max(stats_.max_newton_iterations, exact_pluck(j).max_iterations());
    pluck_load_[j] = force;
    if (force != 0.0) {
        if (!loaded_) ++stats_.played_steps;  // (load_gestures counted a loaded step)
        loaded_ = true;
    }
}

void Stepper::solve_exact_pluck_alone() {
    const std::size_t j = acting_plucks_.front();
    const double w = exact_pluck_prediction(j);
    double force = 0.0;
    psi_curr_ += exact_pluck(j).step(n_, std::span<const double>(&w, 1), std::span<double>(&force, 1));
    take_pluck_force(j, force);
}

std::span<PointContact::Pad> Stepper::exact_pads(bool with_grid) {
    const std::size_t count = acting_plucks_.size();
    const std::size_t points = plan_.point_contact().size(), n = q_.size();
    pads_.clear();  // (within their reserved room)
    pad_cross_.clear();
    for (std::size_t a : acting_plucks_)
        for (std::size_t b : acting_plucks_) pad_cross_.push_back(pluck_cross_[a * exact_plucks_ + b]);
    for (std::size_t a = 0; a < count; ++a) {
        const std::size_t j = acting_plucks_[a];
        Pluck& pluck = exact_pluck(j);
        pluck.prepare(n_);
        const double w = exact_pluck_prediction(j);
        const std::span<const double> grid =
            with_grid ? std::span<const double>(pluck_at_grid_).subspan(j * n, n) : std::span<const double>();
        pads_.push_back({&pluck, w, pluck.shape_square(), std::span<const double>(pad_cross_).subspan(a * count, count),
                         std::span<const double>(pluck_at_points_).subspan(j * points, points), pluck.solve_alone(w), grid});
    }
    return pads_;
}

void Stepper::conclude_exact_pads() {
    for (std::size_t a = 0; a < pads_.size(); ++a) {
        const std::size_t j = acting_plucks_[a];
        take_pluck_force(j, exact_pluck(j).conclude(n_, pads_[a].x));
    }
}

bool Stepper::finger_on(std::size_t f) const {
    if (f >= parts_.fingers().size()) throw std::out_of_range("Stepper: no finger " + std::to_string(f));
    return parts_.on(f);  // finger f is part f
}

void Stepper::lift_finger(std::size_t f) {
    if (!finger_on(f)) return;
    Finger& finger = parts_.finger(f);
    for (std::size_t i : finger.pad()) on_pad_[i] = 0;
    pad_points_ -= finger.pad().size();
    parts_.set_on(f, false);
    finger.rest();
    restart();  // its pad points go back to the obstacle's own solve
}

bool Stepper::place_finger(std::size_t f, double centre_m, double width_m) {
    if (n_ == 0) throw std::logic_error("Stepper::place_finger: only after the first step");
    lift_finger(f);
    Finger& finger = parts_.finger(f);
    finger.place(centre_m, width_m, plan_.obstacle());
    for (std::size_t i : finger.pad())
        if (on_pad_[i] != 0) return false;  // another part acts there: the finger stays off
    for (std::size_t i : finger.pad()) on_pad_[i] = 1;
    pad_points_ += finger.pad().size();
    parts_.set_on(f, true);
    restart();  // u^n in grid_, u^{n-1} in impulse_; the pad leaves the obstacle's solve
    start_part(finger, impulse_, grid_);  // lands at rest on the highest pad point, as at the first step
    return true;
}

void Stepper::start_part(PlayedPart& part, std::span<const double> u_before, std::span<const double> u_now) {
    pad_values(part.pad(), u_now);
    pad_f_ = pad_w_;  // within the reserved capacity: no allocation
    pad_values(part.pad(), u_before);
    part.start(pad_w_, pad_f_);
}

void Stepper::press_finger(std::size_t f, double force_n, long ramp_steps) {
    parts_.finger(f).press(force_n, n_, ramp_steps);
}

void Stepper::classify_points(std::span<const double> u_now, std::span<const double> u_before) {
    const std::vector<double>& g = plan_.obstacle();
    const PenaltyContact& law = plan_.contact();
    for (std::size_t i : plan_.obstacle_points()) {
        psi_prev_ += law.potential(g[i] - u_before[i]);
        psi_curr_ += law.potential(g[i] - u_now[i]);
        if (on_pad_[i] != 0) continue;  // solved with its finger
        const bool apart = g[i] - u_before[i] <= 0.0 && g[i] - u_now[i] <= 0.0;
        if (!screening_ || !apart || !scheduler_.sleep(i, u_now[i] - g[i])) activate(i, u_now[i], u_before[i]);
    }
}

void Stepper::claim_pad(const std::vector<std::size_t>& pad, const std::string& key) {
    for (std::size_t i : pad) {
        if (on_pad_[i] != 0)
            throw InputError(key + ": it acts on x = " + std::to_string(plan_.basis().grid_point(i)) +
                             " m where another finger or gesture acts; they must not overlap");
        on_pad_[i] = 1;
    }
    pad_points_ += pad.size();
}

void Stepper::pad_values(const std::vector<std::size_t>& pad, std::span<const double> field) {
    pad_w_.clear();
    for (std::size_t i : pad) pad_w_.push_back(field[i]);
}

double Stepper::displacement(std::span<const double> mode_shapes) const {
    return kernels::dot(mode_shapes.data(), q_.data(), q_.size());
}

void Stepper::observe(std::span<const double> mode_shapes) {
    observed_row_ = mode_shapes.data();
    keep_observation();  // (the row's values may have changed)
    landing_rows();
}

void Stepper::keep_observation() {
    if (observed_row_ != nullptr) observed_ = kernels::dot(observed_row_, q_.data(), q_.size());
}

double Stepper::observation() const {
    if (observed_row_ == nullptr) throw std::logic_error("Stepper::observation: no row to observe (call observe first)");
    return plan_.options().fused_step ? observed_ : kernels::dot(observed_row_, q_.data(), q_.size());
}

void Stepper::observe_rows(std::span<const double* const> rows) {
    flight_rows_.assign(rows.begin(), rows.end());
    flight_rows_step_ = -1;  // the rows' values may have changed
    landing_rows();
}

void Stepper::landing_rows() {
    landing_rows_ = flight_rows_;
    if (observed_row_ != nullptr) landing_rows_.push_back(observed_row_);
    landing_values_.resize(landing_rows_.size());
}

void Stepper::row_displacements(std::span<double> out) const {
    if (out.size() != flight_rows_.size()) throw std::logic_error("Stepper::row_displacements: not the observed rows");
    if (flight_rows_step_ == n_)
        std::copy(landing_values_.begin(), landing_values_.begin() + static_cast<long>(out.size()), out.begin());
    else
        kernels::dot_rows(flight_rows_.data(), flight_rows_.size(), q_.data(), q_.size(), out.data());
}

double Stepper::velocity(std::span<const double> mode_shapes) const {
    return kernels::dot(mode_shapes.data(), d_.data(), d_.size()) / plan_.dt();
}

double Stepper::modal_energy() const {
    // The state changes only with n: one evaluation per step at most.
    if (energy_step_ != n_) keep_modal_energy(n_, plan_.propagator().scaled_modal_energy(q_, d_));
    return modal_energy_;
}

void Stepper::keep_modal_energy(long step, double scaled) const {
    modal_energy_ = plan_.modal_energy_scale() * scaled;
    energy_step_ = step;
}

double Stepper::energy() const {
    const double h = modal_energy() + contact_energy() + (y_ ? y_->energy() : 0.0);
    return played() ? h + finger_energy() : h;
}

// (every part, on the string or not: a lifted finger's or a gone plucker's so far still count)
double Stepper::finger_energy() const {
    double e = 0.0;
    for (std::size_t k = 0; k < parts_.size(); ++k) e += parts_[k].energy();
    return e;
}

double Stepper::finger_loss() const {
    double e = 0.0;
    for (std::size_t k = 0; k < parts_.size(); ++k) e += parts_[k].loss();
    return e;
}

double Stepper::work() const {
    double e = 0.0;
    for (std::size_t k = 0; k < parts_.size(); ++k) e += parts_[k].work();
    for (const ForceProfile& g : gestures_) e += g.work();
    return y_ ? e + y_->work() : e;
}

double Stepper::contact_energy() const {
    const double grid = 0.5 * plan_.basis().grid_step() * (psi_curr_ + psi_prev_);
    const PointContact& points = plan_.point_contact();
    if (points_.awake == 0) return grid;  // (no points, or all resting: apart, Psi = 0)
    return grid + 0.5 * (points.potential(points_, plan_.contact(), true) + points.potential(points_, plan_.contact(), false));
}

void Stepper::step() {
    if (n_ == 0) {
        first_step();
        if (y_) y_->first_step();
        return;
    }
    wake_due_points();
    solve_contacts();
    apply_impulse();
    if (loaded_)
        advance_loaded();
    else
        advance_modes();
    // Friction from this step's normal forces (the grid's and the exact points').
    if (y_) y_->step(n_, rubbing_points(), points_pushed_ ? std::span<const double>(points_.force) : std::span<const double>());
    if (screening_) {
        scheduler_.end_step();
        if (n_ + 1 >= next_speed_refresh_) {
            scheduler_.motion_changed(q_, d_);  // the modes have decayed: a tighter bound
            next_speed_refresh_ = n_ + 1 + kSpeedRefreshSteps;
        } else if (loaded_ || (points_pushed_ && !points_by_rows())) {
            scheduler_.pushed(q_, d_, impulse_);  // apply_impulse formed the whole impulse
        } else if (points_pushed_) {
            // The points' rows went into the pass with the grid's: the bounds grow by each push
            // times its point's weight (exact point p screened as N + p, its force as one per dx).
            pushes_.assign(forces_.begin(), forces_.end());
            const PointContact& points = plan_.point_contact();
            const double dx = plan_.basis().grid_step();
            for (std::size_t p = 0; p < points.size(); ++p)
                if (points_.force[p] != 0.0) pushes_.emplace_back(q_.size() + p, points.weight(p) * points_.force[p] / dx);
            scheduler_.pushed(q_, d_, pushes_, plan_.impulse_scale());
        } else if (!forces_.empty()) {
            // the motion from here on is a new free motion; where apply_impulse projected the
            // forces onto the modes, the bounds grow by that impulse (no point's weight needed)
            if (plan_.pushes_inline(forces_.size()))
                scheduler_.pushed(q_, d_, forces_, plan_.impulse_scale());
            else
                scheduler_.pushed(q_, d_, impulse_);
        }
        put_points_to_sleep();
    }
    if (points_pushed_) report_point_forces();
    for (std::size_t j = 0; j < exact_plucks_; ++j)
        if (pluck_load_[j] != 0.0) report_force_at(plan_.plucks()[j].position_m, pluck_load_[j]);
    ++n_;
}

long Stepper::free_flight(const FreeFlight& flight, std::size_t head, std::span<const std::vector<double>> probes,
                          std::vector<double>& u, std::vector<double>* v, bool step_head) {
    const long steps = flight.steps();
    // A finger may touch at any time: its pad points are solved every step (and awake exact points);
    // a gesture loads the string until its force has ended.
    if (n_ == 0 || !screening_ || pad_points_ != 0 || any_exact_pluck_on() || points_.awake != 0 || !active_.empty() ||
        psi_curr_ != 0.0 || psi_prev_ != 0.0 || gestures_act_from(n_))
        return 0;
    scheduler_.refresh_amplitudes(q_, d_);  // the head changes below: the tail is summed anew
    const ModalPropagator& prop = plan_.propagator();
    const double energy_before = modal_energy();
    const std::size_t width = probes.size();
    // With no per-step row wanted and no point due before its end, the whole flight is one jump.
    if (width == 0 && !step_head && !y_ && flight.first() == 0 && scheduler_.park_due(steps)) {
        land(flight, 0, steps);
        scheduler_.end_steps(steps);
        return end_flight(steps, energy_before);
    }
    scheduler_.set_head_modes(head);
    const double tail = scheduler_.tail_bound();
    u.resize(static_cast<std::size_t>(steps) * width);
    if (v != nullptr) v->resize(u.size());
    long flown = 0;
    bool interrupted = false;
    while (flown < steps && !interrupted) {
        due_.clear();
        scheduler_.pop_due(due_);
        for (std::size_t i : due_) {
            if (!interrupted && scheduler_.park(i)) continue;
            if (interrupted || !sleeps_on_low_modes(i, head, tail)) {
                interrupted = true;  // a closer look is needed: leave it to a full step
                scheduler_.wake_now(i);
            }
        }
        if (interrupted) break;
        kernels::advance(prop.decay().data(), prop.beta().data(), nullptr, nullptr, q_.data(), d_.data(), head);
        for (std::size_t p = 0; p < width; ++p) {
            const std::size_t at = static_cast<std::size_t>(flown) * width + p;
            u[at] = kernels::dot(probes[p].data(), q_.data(), head);
            if (v != nullptr) (*v)[at] = kernels::dot(probes[p].data(), d_.data(), head) / plan_.dt();
        }
        scheduler_.end_step();
        ++flown;
    }
    if (flown == steps) {
        land(flight, head, steps);
    } else {
        // Cut short (rare: a point may touch): the other modes take the flown steps one by
        // one, which allocates nothing (a real-time engine flies too).
        const std::size_t rest = q_.size() - head;
        for (long m = 0; m < flown; ++m)
            kernels::advance(prop.decay().data() + head, prop.beta().data() + head, nullptr, nullptr,
                             q_.data() + head, d_.data() + head, rest);
        keep_observation();
    }
    scheduler_.set_head_modes(0);
    if (flown == 0) return 0;
    if (y_) y_->fly(flown, steps, head, probes);
    return end_flight(flown, energy_before);
}

void Stepper::land(const FreeFlight& flight, std::size_t first, long flown) {
    keep_modal_energy(n_ + flown, flight.jump_with_products(q_, d_, first, plan_.propagator(), landing_rows_,
                                                            landing_values_.data()));
    flight_rows_step_ = n_ + flown;
    if (observed_row_ != nullptr) observed_ = landing_values_.back();
}

long Stepper::end_flight(long flown, double energy_before) {
    forecast_.count = 0;  // (formed for points now asleep, before the flight)
    forces_.clear();
    touched_obstacle_ = false;
    n_ += flown;
    dissipated_ += energy_before - modal_energy();
    stats_.free_flight_steps += flown;
    if (n_ >= next_speed_refresh_) {
        scheduler_.update_speed(q_, d_);
        next_speed_refresh_ = n_ + kSpeedRefreshSteps;
    }
    return flown;
}

void Stepper::first_step() {
    // q^1 is the exact free motion of each mode; contact acts from step 1 on.
    std::vector<double> u0(q_.size());
    AlignedVector q1(q_.size());
    std::vector<double> pad_before(exact_plucks_);  // each exact plucker's u_s at level 0
    for (std::size_t j = 0; j < exact_plucks_; ++j) pad_before[j] = kernels::dot(exact_pluck(j).shape().data(), q_.data(), q_.size());
    plan_.propagator().first_step(q_, v0_, q1, d_);
    plan_.basis().to_grid(q_, u0);
    q_ = std::move(q1);
    plan_.basis().to_grid(q_, grid_);
    keep_observation();
    if (screening_) scheduler_.update_speed(q_, d_);
    classify_points(grid_, u0);
    plan_.point_contact().start(points_, q_, d_);
    classify_exact_points();
    // Each played part starts from the string under its pad at levels 0 and 1.
    for (std::size_t k = 0; k < parts_.size(); ++k) {
        if (is_exact_pluck(k)) {
            const std::size_t j = k - first_pluck_;
            start_exact_pluck(j, pad_before[j], kernels::dot(exact_pluck(j).shape().data(), q_.data(), q_.size()));
        } else {
            start_part(parts_[k], u0, grid_);
        }
    }
    next_speed_refresh_ = 1 + kSpeedRefreshSteps;
    n_ = 1;
}

void Stepper::activate(std::size_t i, double u_now, double u_before) {
    eta_curr_[i] = plan_.obstacle()[i] - u_now;
    eta_prev_[i] = plan_.obstacle()[i] - u_before;
    active_.push_back(i);
}

bool Stepper::sleeps_on_low_modes(std::size_t i, std::size_t head, double tail) {
    // u_i >= (first `head` modes of u_i) - tail: a lower bound on the gap, cheap to get.
    const double low = kernels::dot(plan_.screened_row(i).data(), q_.data(), head);
    return scheduler_.sleep(i, low - tail - plan_.screened_height(i));
}

void Stepper::wake_due_points() {
    if (!screening_) return;
    due_.clear();
    scheduler_.pop_due(due_);
    if (due_.empty()) return;
    const std::vector<double>& g = plan_.obstacle();
    const std::size_t n = q_.size();
    const bool use_transform = due_.size() > plan_.transform_threshold();
    if (use_transform) plan_.basis().to_grid(q_, grid_);
    const std::size_t head = scheduler_.head_modes();
    const double tail = scheduler_.tail_bound();
    for (std::size_t i : due_) {
        if (i >= n) {  // an exact point
            wake_exact_point(i - n, head, tail);
            continue;
        }
        const std::span<const double> row = plan_.basis().row(i);
        // Cheapest first: the low modes and a bound on the rest, then the exact height.
        double u_now = 0.0, u_before = 0.0;
        if (use_transform) {
            u_now = grid_[i];
        } else {
            if (head < n && sleeps_on_low_modes(i, head, tail)) continue;
            u_now = kernels::dot(row.data(), q_.data(), n);
        }
        if (scheduler_.sleep(i, u_now - g[i])) continue;
        kernels::dot_current_previous(row.data(), q_.data(), d_.data(), n, u_now, u_before);
        activate(i, u_now, u_before);
    }
}

void Stepper::wake_exact_point(std::size_t p, std::size_t head, double tail) {
    const std::size_t n = q_.size();
    const std::size_t i = n + p;
    if (head < n && sleeps_on_low_modes(i, head, tail)) return;
    const double u_now = kernels::dot(plan_.point_contact().row(p).data(), q_.data(), n);
    if (scheduler_.sleep(i, u_now - plan_.point_contact().height(p))) return;
    plan_.point_contact().wake(points_, p, q_, d_);
    point_forecast_step_ = -1;  // (formed for the points awake then)
}

void Stepper::classify_exact_points() {
    // After start(): every point awake; those apart over both levels and far enough go to sleep.
    if (!screening_) return;
    const PointContact& points = plan_.point_contact();
    for (std::size_t p = 0; p < points.size(); ++p)
        if (points_.eta_prev[p] <= 0.0 && points_.eta_curr[p] <= 0.0 &&
            scheduler_.sleep(q_.size() + p, -points_.eta_curr[p]))
            points.rest(points_, p);
}

void Stepper::solve_contacts() {
    forces_.clear();
    touched_obstacle_ = false;
    psi_prev_ = psi_curr_;
    psi_curr_ = 0.0;
    stats_.points_solved += static_cast<double>(active_.size() + pad_points_ + points_.awake);
    loaded_ = false;
    if (!gestures_.empty()) load_gestures();
    std::fill(pluck_load_.begin(), pluck_load_.end(), 0.0);
    // The exact pluckers beside awake obstacle points of the grid or a finger: one solve with them.
    const bool pluck_with_grid = exact_plucks_act() && (!active_.empty() || fingers_on());
    // A single plucker with nothing beside it: its own scalar solve; several: solved together
    // (their pads move one another), with the exact points where any is awake.
    const bool pads_alone = points_.awake == 0 && !pluck_with_grid;
    if (pads_alone && acting_plucks_.size() == 1) solve_exact_pluck_alone();
    // Exact points (or the exact pluckers) beside awake obstacle points of the grid or a finger's
    // pad: all in one solve (see PointContact).
    const bool coupled_points = plan_.point_contact().grid_coupled() && points_.awake != 0;
    const bool fingers_with_points = (coupled_points || pluck_with_grid) && fingers_on();
    const bool joint = pluck_with_grid || (coupled_points && !active_.empty()) || fingers_with_points;
    points_pushed_ = (points_.awake != 0 || (pads_alone && acting_plucks_.size() > 1)) && !joint && solve_points();
    if (active_.empty() && pad_points_ == 0) {
        if (points_pushed_) ++stats_.contact_steps;
        return;
    }

    // The predicted height at every point to solve, into grid_: by one transform, or by rows.
    const bool use_transform = active_.size() + pad_points_ > plan_.transform_threshold();
    if (use_transform) {
        const ModalPropagator& prop = plan_.propagator();
        kernels::predict(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), predicted_.data(), q_.size());
        plan_.basis().to_grid(predicted_, grid_);
    } else {
        predict_points(active_);
    }
    if (loaded_)
        for (std::size_t i : active_) grid_[i] += gestures_at_grid(i);
    const std::vector<double>& g = plan_.obstacle();
    const PenaltyContact& law = plan_.contact();
    const double k = plan_.force_to_displacement();
    if (!parts_.empty()) solve_fingers(use_transform, fingers_with_points);
    // Many points (a string landing on a long obstacle): their equations together, the same
    // solutions (see PenaltyContact::solve_all).
    const bool together = use_transform || joint;
    // Raw pointers and local sums: the forces' emplace_back would otherwise make the compiler
    // reload every member at every point (503 points at the flat obstacle's onset).
    double* eta_prev = eta_prev_.data();
    double* eta_curr = eta_curr_.data();
    const double* grid = grid_.data();
    if (together) {
        const std::size_t count = active_.size();
        solve_a_.resize(count);  // within the reserved capacity: no allocation
        solve_b_.resize(count);
        solutions_.resize(count);
        for (std::size_t p = 0; p < count; ++p) {
            const std::size_t i = active_[p];
            solve_a_[p] = eta_prev[i];
            solve_b_[p] = g[i] - grid[i] - eta_prev[i];
        }
        if (joint)
            solve_points_with_grid(pluck_with_grid, fingers_with_points);
        else
            law.solve_all(solve_a_, solve_b_, k, solutions_);
    }
    double psi = psi_curr_;
    int most_iterations = stats_.max_newton_iterations;
    bool touched = touched_obstacle_;
    const auto take = [&](std::size_t i, double a, const ContactSolution& s) {
        const double eta_next = a + s.increment;
        eta_prev[i] = eta_curr[i];
        eta_curr[i] = eta_next;
        psi += law.potential(eta_next, s.root);  // sqrt(eta_next) as the solve left it
        most_iterations = std::max(most_iterations, s.iterations);
        if (s.force != 0.0) {
            forces_.emplace_back(i, s.force);
            touched = true;
        }
    };
    // Two loops: the batch's has no call to the solve in it (the compiler keeps more in registers).
    const std::size_t count = active_.size();
    const std::size_t* active = active_.data();
    if (together) {
        const ContactSolution* solutions = solutions_.data();
        for (std::size_t p = 0; p < count; ++p) take(active[p], eta_prev[active[p]], solutions[p]);
    } else {
        for (std::size_t p = 0; p < count; ++p) {
            const std::size_t i = active[p];
            const double a = eta_prev[i];
            take(i, a, law.solve(a, g[i] - grid[i] - a, k));
        }
    }
    psi_curr_ = psi;
    stats_.max_newton_iterations = most_iterations;
    touched_obstacle_ = touched;
    if (touched) ++stats_.contact_steps;
}

void Stepper::predict_points(std::span<const std::size_t> points) {
    // The last step's pass formed the prediction at the points it was given: most often these
    // very points, in this order (a string resting on a point or a bridge).
    const Forecast& f = forecast_;
    if (points.size() == f.count && std::equal(points.begin(), points.end(), f.points.begin())) {
        for (std::size_t r = 0; r < points.size(); ++r) grid_[points[r]] = f.values[r];
        return;
    }
    // The others (woken since, or no forecast): row products, the prediction formed on the fly
    // for a few, stored first for many (then read by each pass of rows).
    others_.clear();
    for (std::size_t i : points) {
        std::size_t r = 0;
        while (r < f.count && f.points[r] != i) ++r;
        if (r < f.count)
            grid_[i] = f.values[r];
        else
            others_.push_back(i);
    }
    if (others_.empty()) return;
    if (others_.size() <= kernels::kMaxRowsPerPass) {
        plan_.predicted_at(others_, {}, q_, d_, grid_);
        return;
    }
    const ModalPropagator& prop = plan_.propagator();
    kernels::predict(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), predicted_.data(), q_.size());
    plan_.predicted_at(others_, predicted_, q_, d_, grid_);
}

bool Stepper::fingers_on() const {
    for (std::size_t f = 0; f < parts_.fingers().size(); ++f)
        if (parts_.on(f)) return true;
    return false;
}

void Stepper::take_part(const PlayedPart& part, double obstacle_psi, std::span<const double> force) {
    psi_curr_ += obstacle_psi;
    stats_.max_newton_iterations = std::max(stats_.max_newton_iterations, part.max_iterations());
    touched_obstacle_ = touched_obstacle_ || part.touched_obstacle();
    for (std::size_t p = 0; p < force.size(); ++p)
        if (force[p] != 0.0) forces_.emplace_back(part.pad()[p], force[p]);
}

void Stepper::solve_fingers(bool use_transform, bool with_points) {
    bool acted = false;
    joint_pads_.clear();
    joint_w_.clear();
    const auto solve = [&](PlayedPart& part, std::size_t k) {
        // The pad's predicted heights: from the transform, or the forecast and rows (into grid_
        // at the pad's points, which are not active points: their values stay).
        if (!use_transform) predict_points(part.pad());
        pad_w_.clear();
        for (std::size_t i : part.pad()) pad_w_.push_back(loaded_ ? grid_[i] + gestures_at_grid(i) : grid_[i]);
        if (with_points && k < parts_.fingers().size()) {  // stepped in the points' solve
            parts_.finger(k).prepare(n_);
            joint_pads_.insert(joint_pads_.end(), part.pad().begin(), part.pad().end());
            joint_w_.insert(joint_w_.end(), pad_w_.begin(), pad_w_.end());
            return;
        }
        pad_f_.assign(pad_w_.size(), 0.0);
        take_part(part, part.step(n_, pad_w_, pad_f_), pad_f_);
        acted = acted || part.acted();
    };
    for (std::size_t k = 0; k < parts_.size(); ++k) {
        if (!parts_.on(k) || is_exact_pluck(k)) continue;  // (the exact pluckers have their own solve)
        if (parts_[k].left()) {
            // Its pad's points join this step's obstacle solve below: they need this step's
            // predicted heights (formed above for the active points only), loads included.
            const std::vector<std::size_t>& pad = parts_[k].pad();
            if (!use_transform) predict_points(pad);
            if (loaded_)
                for (std::size_t i : pad) grid_[i] += gestures_at_grid(i);
            retire(parts_[k]);
            parts_.set_on(k, false);
            continue;
        }
        solve(parts_[k], k);
    }
    if (acted && !loaded_) ++stats_.played_steps;  // (load_gestures counted a loaded step)
}

namespace {
// The fingers on the string as the points' solve sees them (GridPads): their pads one after the
// other, each finger's trial from its pad's predictions raised by the points' push.
class FingerPads final : public GridPads {
public:
    FingerPads(PlayedParts& parts, std::span<const std::size_t> points, std::span<const double> w, std::vector<double>& trial)
        : parts_(parts), points_(points), w_(w), trial_(trial) {
        each([&](Finger&, std::size_t, std::size_t, std::size_t) { ++count_; });
    }
    std::span<const std::size_t> points() const override { return points_; }
    std::size_t heights() const override { return count_; }
    std::size_t end(std::size_t f) const override {
        std::size_t last = 0;
        each([&](Finger&, std::size_t k, std::size_t at, std::size_t n) {
            if (k == f) last = at + n;
        });
        return last;
    }
    void solve(std::span<const double> shift, std::span<double> force, std::span<double> height, std::span<double> residual,
               std::span<double> size) override {
        raise(shift);
        each([&](Finger& f, std::size_t k, std::size_t at, std::size_t n) {
            f.trial(std::span<const double>(trial_).subspan(at, n), force.subspan(at, n));
            height[k] = f.height_step();
            residual[k] = f.residual();
            size[k] = f.residual_size();
        });
    }
    void guess(std::span<double> height) const override {
        each([&](Finger& f, std::size_t k, std::size_t, std::size_t) { height[k] = f.height_guess(); });
    }
    void trial(std::span<const double> shift, std::span<const double> height, std::span<double> force,
               std::span<double> residual, std::span<double> size) override {
        raise(shift);
        each([&](Finger& f, std::size_t k, std::size_t at, std::size_t n) {
            f.trial_at(std::span<const double>(trial_).subspan(at, n), height[k], force.subspan(at, n));
            residual[k] = f.residual();
            size[k] = f.residual_size();
        });
    }
    void slopes(std::span<double> response, std::span<double> lift, std::span<double> pull,
                std::span<double> slope) const override {
        each([&](Finger& f, std::size_t k, std::size_t at, std::size_t n) {
            for (std::size_t p = 0; p < n; ++p) {
                response[at + p] = f.response(p);
                lift[at + p] = f.lift(p);
                pull[at + p] = f.pull() * f.lift(p);
            }
            slope[k] = f.residual_slope();
        });
    }

    // f(finger, its index among those on, where its points start, how many).
    template <class F>
    void each(F&& f) const {
        std::size_t at = 0, index = 0;
        for (std::size_t k = 0; k < parts_.fingers().size(); ++k) {
            if (!parts_.on(k)) continue;
            Finger& finger = parts_.finger(k);
            f(finger, index++, at, finger.pad().size());
            at += finger.pad().size();
        }
    }

private:
    void raise(std::span<const double> shift) {
        trial_.resize(w_.size());  // (within the reserved capacity)
        for (std::size_t r = 0; r < w_.size(); ++r) trial_[r] = w_[r] + shift[r];
    }
    PlayedParts& parts_;
    std::span<const std::size_t> points_;
    std::span<const double> w_;
    std::vector<double>& trial_;
    std::size_t count_ = 0;
};
}  // namespace

void Stepper::load_gestures() {
    for (std::size_t g = 0; g < gestures_.size(); ++g) {
        gesture_load_[g] = gestures_[g].at_step(n_);
        loaded_ = loaded_ || gesture_load_[g] != 0.0;
    }
    if (loaded_) ++stats_.played_steps;
}

double Stepper::gestures_at_grid(std::size_t i) const {
    double u = 0.0;
    for (std::size_t g = 0; g < gestures_.size(); ++g) u += gesture_load_[g] * gestures_[g].on_grid(i);
    return plan_.force_to_displacement() * u;
}

double Stepper::gestures_at_point(std::size_t p) const {
    const std::size_t points = plan_.point_contact().size();
    double u = 0.0;
    for (std::size_t g = 0; g < gestures_.size(); ++g) u += gesture_load_[g] * gesture_at_points_[g * points + p];
    return plan_.force_to_displacement() * u;
}

bool Stepper::gestures_act_from(long n) const {
    return std::any_of(gestures_.begin(), gestures_.end(), [n](const ForceProfile& g) { return g.acts_from(n); });
}

void Stepper::advance_loaded() {
    for (std::size_t g = 0; g < gestures_.size(); ++g)
        if (gesture_load_[g] != 0.0) gestures_[g].begin_step(q_, d_);
    advance_modes();
    for (std::size_t g = 0; g < gestures_.size(); ++g)
        if (gesture_load_[g] != 0.0) gestures_[g].end_step(q_, gesture_load_[g]);
}

void Stepper::retire(const PlayedPart& part) {
    // The part has left the string (a plucker gone): its pad points go back to the obstacle's
    // own solve (the loop over active points that follows solves them in this same step).
    const std::vector<std::size_t>& pad = part.pad();
    for (std::size_t p = 0; p < pad.size(); ++p) {
        on_pad_[pad[p]] = 0;
        if (std::isfinite(plan_.obstacle()[pad[p]])) activate(pad[p], part.current()[p], part.previous()[p]);
    }
    pad_points_ -= pad.size();
}

std::size_t Stepper::awake_rows(std::size_t* which, const double** rows) const {
    const PointContact& points = plan_.point_contact();
    std::size_t m = 0;
    for (std::size_t p = 0; p < points.size(); ++p)
        if (points_.resting[p] == 0) {
            which[m] = p;
            rows[m++] = points.row(p).data();
        }
    return m;
}

void Stepper::predict_exact_points() {
    const ModalPropagator& prop = plan_.propagator();
    const PointContact& points = plan_.point_contact();
    if (point_forecast_step_ == n_) {  // the last step's pass formed it
        std::copy(point_forecast_.begin(), point_forecast_.end(), point_predicted_.begin());
    } else if (points_.awake <= kernels::kMaxPassRows) {  // the awake points' rows (resting ones need none)
        std::array<const double*, kernels::kMaxPassRows> rows{};
        std::array<std::size_t, kernels::kMaxPassRows> which{};
        std::array<double, kernels::kMaxPassRows> values{};
        const std::size_t m = awake_rows(which.data(), rows.data());
        kernels::predict_dot_rows(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), rows.data(), m,
                                  q_.size(), values.data());
        for (std::size_t r = 0; r < m; ++r) point_predicted_[which[r]] = values[r];
    } else {  // more points than a pass takes: the prediction stored once, then a product per point
        kernels::predict(prop.decay().data(), prop.beta().data(), q_.data(), d_.data(), predicted_.data(), q_.size());
        for (std::size_t p = 0; p < points.size(); ++p)
            if (points_.resting[p] == 0) point_predicted_[p] = kernels::dot(points.row(p).data(), predicted_.data(), q_.size());
    }
    if (loaded_)
        for (std::size_t p = 0; p < points.size(); ++p) point_predicted_[p] += gestures_at_point(p);
}

bool Stepper::solve_points() {
    predict_exact_points();
    const PointContact& points = plan_.point_contact();
    const double k = plan_.force_to_displacement();
    bool pushed = false;
    if (!acting_plucks_.empty()) {
        // Each plucker at its exact position presses on its u_s, which every point's row (and
        // every other pad) overlaps: one more unknown each in the points' system.
        pushed = points.solve(points_, point_predicted_, plan_.contact(), k, exact_pads(false));
        conclude_exact_pads();
    } else {
        pushed = points.solve(points_, point_predicted_, plan_.contact(), k);
    }
    stats_.max_newton_iterations = std::max(stats_.max_newton_iterations, points_.iterations);
    touched_obstacle_ = touched_obstacle_ || pushed;
    return pushed;
}

void Stepper::solve_points_with_grid(bool with_pluck, bool with_fingers) {
    const PointContact& points = plan_.point_contact();
    if (!points.empty()) predict_exact_points();
    PointContact::Grid grid{active_, solve_a_, solve_b_, solutions_, plan_.basis().grid_step()};
    FingerPads pads(parts_, joint_pads_, joint_w_, joint_trial_);
    if (with_fingers) grid.pads = &pads;
    const double k = plan_.force_to_displacement();
    if (with_pluck) {
        points_pushed_ = points.solve(points_, point_predicted_, plan_.contact(), k, grid, exact_pads(true));
        conclude_exact_pads();
    } else {
        points_pushed_ = points.solve(points_, point_predicted_, plan_.contact(), k, grid);
    }
    if (with_fingers) {
        // The fingers' last trial is the joint solution: their steps move on with it.
        bool acted = false;
        pads.each([&](Finger& finger, std::size_t, std::size_t at, std::size_t n) {
            take_part(finger, finger.commit(), std::span<const double>(points_.pad_force).subspan(at, n));
            acted = acted || finger.acted();
        });
        if (acted && !loaded_) ++stats_.played_steps;
    }
    if (points_.joint) ++stats_.joint_steps;
    stats_.max_newton_iterations = std::max(stats_.max_newton_iterations, points_.iterations);
    touched_obstacle_ = touched_obstacle_ || points_pushed_;
}

void Stepper::apply_point_impulse() {
    // With a point pushing, every force goes through one impulse vector (advance_modes' plain path).
    if (forces_.empty())
        std::fill(impulse_.begin(), impulse_.end(), 0.0);
    else
        plan_.forces_to_modes(forces_, grid_, impulse_);
    plan_.point_contact().add_impulse(points_, plan_.force_to_displacement(), impulse_);
}

void Stepper::report_force_at(double x, double force) {
    // As a force per length at the grid point nearest x, the same total force.
    const double dx = plan_.basis().grid_step();
    const double index = std::clamp(std::round(x / dx) - 1.0, 0.0, static_cast<double>(q_.size() - 1));
    forces_.emplace_back(static_cast<std::size_t>(index), force / dx);
}

void Stepper::report_point_forces() {
    const PointContact& points = plan_.point_contact();
    for (std::size_t p = 0; p < points.size(); ++p)
        if (points_.force[p] != 0.0) report_force_at(points.point(p).x_m, points_.force[p] * points.weight(p));
}

bool Stepper::points_by_rows() const {
    const std::size_t pushes = forces_.size() + points_.awake;  // (resting points push nothing)
    return points_.awake <= kernels::kMaxPassRows &&
           pushes <= Plan::kMaxInlinePushes && (forces_.empty() || plan_.pushes_inline(forces_.size()));
}

void Stepper::advance_with_points() {
    const PointContact& points = plan_.point_contact();
    kernels::StepPass pass;
    std::array<double, Plan::kMaxInlinePushes> coefficients;
    std::array<const double*, Plan::kMaxInlinePushes> push_rows;
    std::array<const double*, kernels::kMaxPassRows> predict_rows;
    std::size_t pushes = 0;
    if (points_pushed_)
        for (std::size_t p = 0; p < points.size(); ++p)
            if (points_.force[p] != 0.0) {
                coefficients[pushes] = plan_.force_to_displacement() * points.weight(p) * points_.force[p];
                push_rows[pushes++] = points.row(p).data();
            }
    for (const auto& [i, f] : forces_) {
        coefficients[pushes] = plan_.impulse_scale() * f;
        push_rows[pushes++] = plan_.basis().row(i).data();
    }
    pass.push_rows = push_rows.data();
    pass.push_coefficients = coefficients.data();
    pass.pushes = pushes;
    // The points' next prediction, the observation and the energy, formed in the same pass (the
    // reference path forms them in passes of their own).
    // The awake points' rows, then the grid's active points' where they fit in the pass.
    forecast_.count = 0;
    const bool fused = plan_.options().fused_step;
    std::array<std::size_t, kernels::kMaxPassRows> which;
    std::array<double, kernels::kMaxPassRows> values;
    std::size_t count = 0;
    if (fused) {
        count = awake_rows(which.data(), predict_rows.data());
        // (and the fingers' pads, solved again at the next step)
        const std::size_t solved = active_.size() + pad_points_;
        const bool grid_fits = solved != 0 && count + solved <= kernels::kMaxPassRows &&
                               solved <= plan_.transform_threshold();
        if (grid_fits) {
            const auto add = [&](std::size_t i) {
                forecast_.points[forecast_.count++] = i;
                predict_rows[count++] = plan_.basis().row(i).data();
            };
            for (std::size_t i : active_) add(i);
            parts_.each_on([&](const PlayedPart& part) {
                for (std::size_t i : part.pad()) add(i);
            });
        }
        pass.predict_rows = predict_rows.data();
        pass.predict_count = count;
        pass.predicted = values.data();
    }
    run_pass(pass);
    if (fused) {
        const std::size_t awake = count - forecast_.count;
        for (std::size_t r = 0; r < awake; ++r) point_forecast_[which[r]] = values[r];
        for (std::size_t r = 0; r < forecast_.count; ++r) forecast_.values[r] = values[awake + r];
    }
    point_forecast_step_ = fused ? n_ + 1 : -1;
}

void Stepper::run_pass(kernels::StepPass& pass) {
    const ModalPropagator& prop = plan_.propagator();
    // (at an audio rate every step: no integer division for it)
    const bool audited = audit_stride_ == 1 || (audit_stride_ > 1 && (n_ + 1) % audit_stride_ == 0);
    double energy = 0.0;
    if (plan_.options().fused_step) {
        if (observed_row_ != nullptr) {
            pass.observe_row = observed_row_;
            pass.observed = &observed_;
        }
        if (audited) pass.energy = &energy;
    }
    const double losses = plan_.step_kernel()(prop.decay().data(), prop.beta().data(),
                                              prop.lossless() ? nullptr : prop.loss().data(), pass, q_.data(),
                                              d_.data(), q_.size());
    dissipated_ += plan_.modal_loss_scale() * losses;
    if (pass.energy != nullptr) keep_modal_energy(n_ + 1, energy);
}

void Stepper::apply_impulse() {
    if (loaded_) {  // the gestures' loads with every force in one impulse vector (a few steps' work)
        if (points_pushed_)
            apply_point_impulse();
        else if (forces_.empty())
            std::fill(impulse_.begin(), impulse_.end(), 0.0);
        else
            plan_.forces_to_modes(forces_, grid_, impulse_);
        const double k = plan_.force_to_displacement();
        for (std::size_t g = 0; g < gestures_.size(); ++g)
            if (gesture_load_[g] != 0.0)
                kernels::axpy(k * gesture_load_[g], gestures_[g].shape().data(), impulse_.data(), impulse_.size());
        for (std::size_t j = 0; j < exact_plucks_; ++j)
            if (pluck_load_[j] != 0.0)
                kernels::axpy(k * pluck_load_[j], exact_pluck(j).shape().data(), impulse_.data(), impulse_.size());
        return;
    }
    if (points_pushed_) {
        if (!points_by_rows()) apply_point_impulse();
        return;
    }
    if (forces_.empty() || plan_.pushes_inline(forces_.size())) return;  // advance_modes adds the rows
    plan_.forces_to_modes(forces_, grid_, impulse_);
}

void Stepper::advance_modes() {
    if (!loaded_ && points_.awake != 0 && points_by_rows()) {
        advance_with_points();
        return;
    }
    const bool whole = points_pushed_ || loaded_;  // apply_impulse formed the whole impulse
    const std::size_t pushes = whole ? 0 : forces_.size();
    kernels::StepPass pass;
    // Not zeroed (GCC zeroes such arrays with rep stos, slow to start, at every step): only the
    // first entries are read.
    std::array<double, kernels::kMaxPassRows> coefficients;
    std::array<const double*, kernels::kMaxPassRows> push_rows, predict_rows;
    if (whole) {
        pass.impulse = impulse_.data();
    } else if (plan_.pushes_inline(pushes)) {  // the pass adds the rows; otherwise apply_impulse made the vector
        for (std::size_t r = 0; r < pushes; ++r) {
            coefficients[r] = plan_.impulse_scale() * forces_[r].second;
            push_rows[r] = plan_.basis().row(forces_[r].first).data();
        }
        pass.push_rows = push_rows.data();
        pass.push_coefficients = coefficients.data();
        pass.pushes = pushes;
    } else if (pushes != 0) {
        pass.impulse = impulse_.data();
    }
    // What the next step and the caller read of the state the pass leaves, formed while it holds
    // it (one pass over the modes instead of one per product): the next prediction at the points
    // solved now (a string resting on a bridge, a finger's pad: most are solved again), the
    // observation row, and the energy where the caller audits it.
    forecast_.count = 0;
    const bool fused = plan_.options().fused_step;
    const std::size_t solved = active_.size() + pad_points_;
    if (fused && solved != 0 && solved <= kernels::kMaxPassRows && solved <= plan_.transform_threshold()) {
        std::size_t count = 0;
        const auto add = [&](std::size_t i) {
            forecast_.points[count] = i;
            predict_rows[count++] = plan_.basis().row(i).data();
        };
        for (std::size_t i : active_) add(i);
        parts_.each_on([&](const PlayedPart& part) {
            for (std::size_t i : part.pad()) add(i);
        });
        forecast_.count = count;
        pass.predict_rows = predict_rows.data();
        pass.predict_count = count;
        pass.predicted = forecast_.values.data();
    }
    run_pass(pass);
}

void Stepper::put_points_to_sleep() {
    // A point out of contact over both recent levels, and far enough from the obstacle,
    // leaves the active set until the scheduler says it could be back.
    if (points_.awake != 0) {
        const PointContact& points = plan_.point_contact();
        for (std::size_t p = 0; p < points.size(); ++p)
            if (points_.resting[p] == 0 && points_.eta_curr[p] <= 0.0 && points_.eta_prev[p] <= 0.0) {
                scheduler_.refresh(q_, d_);
                if (scheduler_.sleep(q_.size() + p, -points_.eta_curr[p])) points.rest(points_, p);
            }
    }
    std::erase_if(active_, [this](std::size_t i) {
        if (!(eta_curr_[i] <= 0.0 && eta_prev_[i] <= 0.0)) return false;
        scheduler_.refresh(q_, d_);  // the speed bound is kept current only while some point sleeps
        return scheduler_.sleep(i, -eta_curr_[i]);
    });
}

std::span<const std::pair<std::size_t, double>> Stepper::rubbing_points() {
    // Friction along y acts where the string is pressed along z: on the obstacle, and under a
    // finger (which does not move along y) with the finger's push plus the obstacle's. Force
    // gestures and pluckers drag nothing sideways.
    if (pad_points_ == 0) return forces_;
    rubbing_.clear();
    for (const auto& [i, f] : forces_)
        if (on_pad_[i] == 0) rubbing_.emplace_back(i, f);
    parts_.each_on([&](const PlayedPart& part) {
        for (std::size_t p = 0; p < part.pad().size(); ++p)
            if (const double f = part.rubbing_force(p); f > 0.0) rubbing_.emplace_back(part.pad()[p], f);
    });
    return rubbing_;
}

}  // namespace fretbuzz
