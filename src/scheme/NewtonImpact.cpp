#include "fretbuzz/scheme/NewtonImpact.hpp"

#include <algorithm>
#include <cmath>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {
std::vector<std::size_t> obstacle_points_of(const Plan& plan) {
    std::vector<std::size_t> points = plan.obstacle_points();
    for (std::size_t p = 0; p < plan.point_contact().size(); ++p) points.push_back(plan.mode_count() + p);
    return points;
}
}  // namespace

NewtonImpact::NewtonImpact(const Plan& plan, std::span<const double> q0, std::span<const double> v0)
    : plan_(&plan),
      modes_(plan.propagator(), q0, v0),
      gestures_(plan),
      screening_(plan),
      // The joint problem holds at most every obstacle point; only exact points need it.
      lemke_(plan.point_contact().size() > 0 ? obstacle_points_of(plan).size() : 0),
      step_(&NewtonImpact::first_step),
      restitution_(plan.restitution()),
      screen_(plan.options().screen_contacts) {
    if (plan.law() != ContactLawKind::impact)
        throw InputError("contact.law: the impact scheme was asked to step a case planned with the penalty law");
    if (!plan.fingers().empty() || !plan.plucks().empty() || plan.two_polarisations())
        throw InputError("contact.law = \"impact\" steps a string in one polarisation, with force gestures at most: "
                         "no fingers, pluckers or second polarisation (use contact.law = \"penalty\")");
    plan.prepare_rows();
    const std::size_t points = plan.screened_points(), n = plan.mode_count();
    is_awake_.assign(points, 0);
    for (auto* v : {&awake_, &due_, &active_}) v->reserve(2 * points + 16);
    active_rows_.reserve(points);
    for (auto* v : {&predicted_, &before_, &free_step_, &lambda_, &lcp_q_, &after_}) v->reserve(points);
    forces_.reserve(points);
    delassus_.reserve(lemke_.capacity() * lemke_.capacity());
    impulse_.assign(n, 0.0);
}

void NewtonImpact::first_step() {
    modes_.first_step();
    n_ = 1;
    // Every obstacle point is looked at once, then sleeps where the screening allows.
    screening_.start(modes_, n_);
    for (std::size_t i : obstacle_points_of(*plan_)) {
        awake_.push_back(i);
        is_awake_[i] = 1;
    }
    step_ = &NewtonImpact::contact_step;
    predicted_.clear();
    for (std::size_t i : awake_) predicted_.push_back(modes_.at(plan_->screened_row(i).data()));
    put_to_sleep();
}

long NewtonImpact::free_flight(const FreeFlight& flight, std::size_t head, std::span<const std::vector<double>> probes,
                               std::vector<double>& rows) {
    if (n_ < 1 || !screen_ || !awake_.empty() || gestures_.act_from(n_)) return 0;
    ContactScheduler& scheduler = screening_.scheduler();
    scheduler.refresh_amplitudes(modes_.q(), modes_.d());  // the head changes below: the tail is summed anew
    const double before = energy();
    const long flown = screening_.fly_head(modes_, flight.steps(), head, probes, rows, nullptr);
    if (flown == flight.steps()) {
        flight.jump(modes_.q(), modes_.d(), head);
    } else {
        for (long m = 0; m < flown; ++m) modes_.step_modes(head, modes_.size() - head);  // cut short
    }
    scheduler.set_head_modes(0);
    if (flown == 0) return 0;
    // Free motion loses only to damping: what the energy lost over the flight.
    damping_ += before - energy();
    n_ += flown;
    forces_.clear();
    screening_.refresh_after_flight(modes_, n_);
    return flown;
}

void NewtonImpact::look_at_points() {
    if (screen_) {
        due_.clear();
        screening_.scheduler().pop_due(due_);
        for (std::size_t i : due_) {
            if (is_awake_[i]) continue;
            is_awake_[i] = 1;
            awake_.push_back(i);
        }
    }
    active_rows_.clear();
    for (std::size_t i : awake_) active_rows_.push_back(plan_->screened_row(i).data());
    predicted_.resize(awake_.size());
    modes_.predict_at(active_rows_.data(), awake_.size(), predicted_.data());
    points_checked_ += static_cast<long>(awake_.size());
}

void NewtonImpact::contact_step() {
    const bool loaded = !gestures_.empty() && gestures_.load(n_);
    look_at_points();
    if (loaded) {  // the loads shift the free prediction, as the penalty's field
        const std::size_t n = plan_->mode_count();
        for (std::size_t k = 0; k < awake_.size(); ++k)
            predicted_[k] += awake_[k] < n ? gestures_.at_grid(awake_[k]) : gestures_.at_point(awake_[k] - n);
    }
    active_.clear();
    active_rows_.clear();
    before_.clear();
    free_step_.clear();
    for (std::size_t k = 0; k < awake_.size(); ++k) {
        const std::size_t i = awake_[k];
        if (predicted_[k] - plan_->screened_height(i) > 0.0) continue;
        const double* row = plan_->screened_row(i).data();
        double now = 0.0, previous = 0.0;
        modes_.at_both(row, now, previous);
        active_.push_back(i);
        active_rows_.push_back(row);
        before_.push_back(now - previous);         // u^-: the point's displacement over the last step
        free_step_.push_back(predicted_[k] - now);  // its free displacement over this one
    }
    forces_.clear();
    kernels::StepPass pass;
    if (!active_.empty()) {
        solve_impulses();
        // Only the points that push: their rows and impulses, inline up to a pass's rows.
        std::size_t pushing = 0;
        for (std::size_t c = 0; c < active_.size(); ++c) {
            if (!(lambda_[c] > 0.0)) continue;
            active_rows_[pushing] = active_rows_[c];
            lambda_[pushing] = lambda_[c];
            before_[pushing] = before_[c];
            active_[pushing] = active_[c];
            ++pushing;
        }
        active_rows_.resize(pushing);
        if (pushing <= kernels::kMaxPassRows && !loaded) {
            pass.push_rows = active_rows_.data();
            pass.push_coefficients = lambda_.data();
            pass.pushes = pushing;
        } else {
            std::fill(impulse_.begin(), impulse_.end(), 0.0);
            for (std::size_t c = 0; c < pushing; ++c)
                for (std::size_t j = 0; j < impulse_.size(); ++j) impulse_[j] += lambda_[c] * active_rows_[c][j];
            pass.impulse = impulse_.data();
        }
    }
    if (loaded) {  // the loads' impulse, with the impacts' where there are any (formed above)
        if (pass.impulse == nullptr) std::fill(impulse_.begin(), impulse_.end(), 0.0);
        gestures_.add_impulse(plan_->force_to_displacement(), impulse_);
        pass.impulse = impulse_.data();
        gestures_.begin_step(modes_);
    }
    damping_ += plan_->modal_loss_scale() * modes_.advance(plan_->step_kernel(), pass);
    if (loaded) gestures_.end_step(modes_);
    ++n_;
    const std::size_t pushed = active_rows_.size();
    if (pushed > 0) {
        // The impulses' work, mu/(2 dt^2) sum_c lambda_c (u_c^+ + u_c^-), from the state itself.
        const double force_scale = plan_->linear_density() / (plan_->dt() * plan_->dt() * plan_->basis().grid_step());
        double work = 0.0;
        for (std::size_t c = 0; c < pushed; ++c) {
            const double after = kernels::dot(active_rows_[c], modes_.d().data(), modes_.size());
            work += lambda_[c] * (after + before_[c]);
            forces_.emplace_back(active_[c], force_scale * lambda_[c]);
        }
        impact_loss_ -= plan_->modal_energy_scale() * work;
        ++contact_steps_;
    }
    if (screen_ && (pushed > 0 || loaded)) screening_.scheduler().motion_changed(modes_.q(), modes_.d());
    if (!screen_) return;
    screening_.scheduler().end_step();
    screening_.refresh_after_step(modes_, n_);  // the modes decay: from time to time a tighter bound
    // The gaps at n + 1: the predictions plus the pushes. On the grid a push moves its own point
    // only, by lambda / dx (S S^T = I / dx); exact points couple, so there they are formed again.
    // After a loaded step too: the loads move every point.
    if (loaded || (pushed > 0 && plan_->point_contact().size() > 0)) {
        for (std::size_t k = 0; k < awake_.size(); ++k) predicted_[k] = modes_.at(plan_->screened_row(awake_[k]).data());
    } else if (pushed > 0) {
        const double dx = plan_->basis().grid_step();
        for (std::size_t k = 0, c = 0; k < awake_.size() && c < pushed; ++k)
            if (awake_[k] == active_[c]) predicted_[k] += lambda_[c++] / dx;
    }
    put_to_sleep();
}

void NewtonImpact::solve_impulses() {
    const std::size_t m = active_.size();
    const std::size_t n = plan_->mode_count();
    const double e = restitution_;
    lcp_q_.resize(m);
    lambda_.resize(m);
    // e_c = e where the point approached (u^- <= 0), 1 where it moved away: max(e u^-, u^-).
    // A pushing impulse's work is lambda (1 - e_c) u^-, so none gains energy (the header).
    for (std::size_t c = 0; c < m; ++c) lcp_q_[c] = free_step_[c] + std::max(e * before_[c], before_[c]);
    const bool all_on_grid = std::all_of(active_.begin(), active_.end(), [n](std::size_t i) { return i < n; });
    if (all_on_grid) {
        // Rows of S are orthogonal, S S^T = I / dx: one scalar problem per point.
        const double dx = plan_->basis().grid_step();
        for (std::size_t c = 0; c < m; ++c) lambda_[c] = std::max(0.0, -lcp_q_[c] * dx);
        return;
    }
    delassus_.resize(m * m);
    for (std::size_t a = 0; a < m; ++a)
        for (std::size_t b = a; b < m; ++b)
            delassus_[a * m + b] = delassus_[b * m + a] = kernels::dot(active_rows_[a], active_rows_[b], n);
    if (!lemke_.solve(delassus_, lcp_q_, m, lambda_))
        throw SolverError("the impact law's complementarity problem at t = " + std::to_string(time()) +
                          " s has no solution by Lemke's method (" + std::to_string(m) + " points in contact)");
    max_pivots_ = std::max(max_pivots_, lemke_.pivots());
}

void NewtonImpact::put_to_sleep() {
    if (!screen_) return;
    ContactScheduler& scheduler = screening_.scheduler();
    scheduler.refresh(modes_.q(), modes_.d());
    std::size_t kept = 0;
    for (std::size_t k = 0; k < awake_.size(); ++k) {
        const std::size_t i = awake_[k];
        const double gap = predicted_[k] - plan_->screened_height(i);
        if (gap > 0.0 && scheduler.sleep(i, gap)) {
            is_awake_[i] = 0;
            continue;
        }
        awake_[kept++] = i;
    }
    awake_.resize(kept);
}

}  // namespace fretbuzz
