#include "fretbuzz/scheme/Pluck.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "MonotoneRoot.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/Kernels.hpp"
#include "fretbuzz/scheme/TimeProfile.hpp"

namespace fretbuzz {

namespace {
constexpr int kMaxIterations = 100;
}  // namespace

Pluck::Pluck(const PluckSpec& spec, double dx, const std::vector<double>& obstacle, const PenaltyContact& obstacle_law,
             double dt, double k)
    : spec_(spec),
      s_(-spec.direction),  // +1: pulls away from the fretboard
      dx_(dx),
      dt_(dt),
      k_(k),
      start_step_(std::max(1L, std::lround(spec.start_s / dt))),
      law_(1.0, 1.0),
      obstacle_law_(obstacle_law),
      pad_(pad_points(spec.position_m, spec.width_m, dx, obstacle.size())) {
    law_ = PenaltyContact(spec.stiffness / (static_cast<double>(pad_.size()) * dx), spec.exponent);
    for (std::size_t i : pad_) g_.push_back(obstacle[i]);
    u_curr_.assign(pad_.size(), 0.0);
    u_prev_.assign(pad_.size(), 0.0);
    rho_.assign(pad_.size(), 0.0);
}

Pluck::Pluck(const PluckSpec& spec, std::vector<double> shape, const PenaltyContact& obstacle_law, double dt, double k)
    : spec_(spec),
      s_(-spec.direction),
      dx_(1.0),  // one entry standing for the whole pad: its force is the pad's, in N
      dt_(dt),
      k_(0.0),
      start_step_(std::max(1L, std::lround(spec.start_s / dt))),
      law_(spec.stiffness, spec.exponent),
      obstacle_law_(obstacle_law),
      g_(1, -std::numeric_limits<double>::infinity()),
      u_curr_(1, 0.0),
      u_prev_(1, 0.0),
      rho_(1, 0.0),
      shape_(std::move(shape)) {
    // u_s moves by (dt^2/mu) F (s . s) for a force F spread over the pad.
    shape_square_ = kernels::dot(shape_.data(), shape_.data(), shape_.size());
    k_ = k * shape_square_;
}

void Pluck::read_obstacle(const std::vector<double>& obstacle) {
    if (exact()) return;  // (the obstacle's points are solved beside it: see Stepper)
    for (std::size_t p = 0; p < pad_.size(); ++p) g_[p] = obstacle[pad_[p]];
}

double Pluck::body_height() const {
    const bool there = stage_ == Stage::pulling || stage_ == Stage::withdrawing;
    return there ? p_curr_ : std::numeric_limits<double>::quiet_NaN();
}

void Pluck::start(std::span<const double> u0, std::span<const double> u1) {
    u_prev_.assign(u0.begin(), u0.end());
    u_curr_.assign(u1.begin(), u1.end());
}

void Pluck::appear() {
    // Beside the pad's nearest point over both levels, gap away: y <= 0 at n - 1 and n.
    double nearest = s_ * u_curr_[0];
    for (std::size_t p = 0; p < u_curr_.size(); ++p) nearest = std::min({nearest, s_ * u_curr_[p], s_ * u_prev_[p]});
    p_curr_ = p_prev_ = s_ * (nearest - spec_.gap_m);
    stage_ = Stage::pulling;
}

double Pluck::solve_point(std::size_t p, double w, double p_next, double& obstacle_force, double& push) {
    // h(x) = (x - w) - k Q_obstacle(x) - k s push(x), x = u^{n+1}: increasing, slope >= 1.
    const double g = g_[p];
    const bool obstacle = std::isfinite(g);
    const double a_o = g - u_prev_[p];
    const bool touching = stage_ == Stage::pulling || stage_ == Stage::withdrawing;
    const double c = s_ * (p_prev_ - u_prev_[p]);  // y^{n-1}
    // Fixed over the iteration: the laws' powers of them, once.
    const PenaltyContact::Anchored obstacle_at = obstacle_law_.anchored(obstacle ? a_o : 0.0);
    const PenaltyContact::Anchored plucker_at = law_.anchored(touching ? c : 0.0);
    double x_root = w;
    const auto evaluate = [&](double x) {
        x_root = x;
        detail::MonotoneValue v{x - w, std::abs(x) + std::abs(w), 1.0};
        obstacle_force = 0.0;
        if (obstacle) {
            const double r_o = u_prev_[p] - x;
            const auto [quotient, slope] = obstacle_law_.quotient_and_slope(obstacle_at, r_o);
            obstacle_force = quotient;
            v.slope += k_ * slope;
            v.h -= k_ * obstacle_force;
            v.scale += k_ * obstacle_force;
        }
        push = 0.0;
        if (touching) {
            const double r = s_ * (p_next - x) - c;
            const auto [q, quotient_slope] = law_.quotient_and_slope(plucker_at, r);
            push = q + rho_[p] * r;
            v.h -= k_ * s_ * push;
            v.scale += k_ * std::abs(push);
            v.slope += k_ * (quotient_slope + rho_[p]);
        }
        return v;
    };
    const int iterations = detail::monotone_root(evaluate, w, kMaxIterations);
    if (iterations < 0) {
        std::ostringstream msg;
        msg.precision(17);
        msg << spec_.key << ": the plucker's contact solve did not converge (pad point, " << x_root
            << "); reduce its stiffness or the time step";
        throw SolverError(msg.str());
    }
    max_iterations_ = std::max(max_iterations_, iterations + 1);
    return x_root;
}

void Pluck::prepare(long n) {
    if (stage_ == Stage::waiting && n >= start_step_) appear();
    p_next_ = p_curr_;
    if (stage_ == Stage::pulling) p_next_ += s_ * spec_.speed * dt_;
    if (stage_ == Stage::withdrawing) p_next_ -= s_ * spec_.withdraw_speed * dt_;
    // Hunt-Crossley coefficient at level n: each step's loss is >= 0 exactly.
    for (std::size_t p = 0; p < u_curr_.size(); ++p)
        rho_[p] = spec_.loss * law_.force(s_ * (p_curr_ - u_curr_[p])) / (2.0 * dt_);
}

void Pluck::take(std::size_t p, double x, double push, Sums& sums) {
    if (stage_ != Stage::waiting) {
        const double y = s_ * (p_next_ - x);
        const double r = y - s_ * (p_prev_ - u_prev_[p]);
        sums.psi_next += law_.potential(y);
        sums.lost += rho_[p] * r * r;
        sums.pushed += push;
    }
    u_prev_[p] = u_curr_[p];
    u_curr_[p] = x;
}

void Pluck::finish(long n, const Sums& sums) {
    contact_force_ = dx_ * sums.pushed;
    work_ += 0.5 * dx_ * sums.pushed * s_ * (p_next_ - p_prev_);
    loss_ += 0.5 * dx_ * sums.lost;
    psi_prev_ = psi_curr_;
    psi_curr_ = sums.psi_next;
    p_prev_ = p_curr_;
    p_curr_ = p_next_;
    if (stage_ == Stage::pulling) {
        const bool slipped = spec_.release_force_n > 0.0 && contact_force_ >= spec_.release_force_n;
        const bool reached = spec_.release_displacement_m > 0.0 && s_ * p_curr_ >= spec_.release_displacement_m;
        if (slipped || reached) {
            stage_ = Stage::withdrawing;
            release_step_ = n + 1;
        }
    } else if (stage_ == Stage::withdrawing && psi_curr_ == 0.0 && psi_prev_ == 0.0) {
        stage_ = Stage::gone;  // clear of the string at both levels: it leaves with no energy
    }
}

double Pluck::step(long n, std::span<const double> predicted, std::span<double> force) {
    prepare(n);
    double obstacle_psi = 0.0;
    Sums sums;
    touched_obstacle_ = false;
    for (std::size_t p = 0; p < u_curr_.size(); ++p) {
        double obstacle_force = 0.0, push = 0.0;
        const double x = solve_point(p, predicted[p], p_next_, obstacle_force, push);
        if (std::isfinite(g_[p])) obstacle_psi += obstacle_law_.potential(g_[p] - x);
        force[p] = obstacle_force + s_ * push;
        touched_obstacle_ = touched_obstacle_ || obstacle_force != 0.0;
        take(p, x, push, sums);
    }
    finish(n, sums);
    return obstacle_psi;
}

void Pluck::force_and_slope(double x, double& force, double& slope) const {
    force = slope = 0.0;
    if (stage_ != Stage::pulling && stage_ != Stage::withdrawing) return;
    // push(r), r = y^{n+1} - y^{n-1} = s (p^{n+1} - x) - y^{n-1}: F = s push, dF/dx = -(push'(r)).
    const double c = s_ * (p_prev_ - u_prev_[0]);
    const double r = s_ * (p_next_ - x) - c;
    const auto [q, quotient_slope] = law_.quotient_and_slope(law_.anchored(c), r);
    force = s_ * (q + rho_[0] * r);
    slope = -(quotient_slope + rho_[0]);
}

double Pluck::solve_alone(double w) {
    double obstacle_force = 0.0, push = 0.0;
    return solve_point(0, w, p_next_, obstacle_force, push);
}

double Pluck::conclude(long n, double x) {
    double force = 0.0, slope = 0.0;
    force_and_slope(x, force, slope);
    Sums sums;
    touched_obstacle_ = false;
    take(0, x, s_ * force, sums);
    finish(n, sums);
    return force;
}

}  // namespace fretbuzz
