#include "fretbuzz/scheme/Pluck.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "../numerics/MonotoneRoot.hpp"
#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {
constexpr int kMaxIterations = 100;
}  // namespace

Pluck::Pluck(const PluckSpec& spec, std::vector<double> shape, double dt, double k)
    : spec_(spec),
      s_(-spec.direction),  // +1: pulls away from the fretboard
      dt_(dt),
      k_(0.0),
      start_step_(std::max(1L, std::lround(spec.start_s / dt))),
      law_(spec.stiffness, spec.exponent, spec.loss, dt),
      u_curr_(1, 0.0),
      u_prev_(1, 0.0),
      shape_(std::move(shape)) {
    // u_s moves by (dt^2/mu) F (s . s) for a force F spread over the pad.
    shape_square_ = kernels::dot(shape_.data(), shape_.data(), shape_.size());
    k_ = k * shape_square_;
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
    // Beside u_s over both levels, gap away: y <= 0 at n - 1 and n.
    const double nearest = std::min(s_ * u_curr_[0], s_ * u_prev_[0]);
    p_curr_ = p_prev_ = s_ * (nearest - spec_.gap_m);
    stage_ = Stage::pulling;
}

double Pluck::solve_point(double w, double p_next, double& push) {
    // h(x) = (x - w) - k s push(x), x = u_s^{n+1}: increasing, slope >= 1.
    const bool touching = stage_ == Stage::pulling || stage_ == Stage::withdrawing;
    const double c = s_ * (p_prev_ - u_prev_[0]);  // y^{n-1}
    // Fixed over the iteration: the law's powers of c, once.
    const ImpactLaw::Push pusher = law_.push(touching ? c : 0.0, rho_);
    double x_root = w;
    const auto evaluate = [&](double x) {
        x_root = x;
        detail::MonotoneValue v{x - w, std::abs(x) + std::abs(w), 1.0};
        push = 0.0;
        if (touching) {
            const double r = s_ * (p_next - x) - c;
            const ForceSlope f = pusher(r);  // Q + rho r and its slope
            push = f.force;
            v.h -= k_ * s_ * push;
            v.scale += k_ * std::abs(push);
            v.slope += k_ * f.slope;
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
    rho_ = law_.damping(s_ * (p_curr_ - u_curr_[0]));
}

void Pluck::take(double x, double push, Sums& sums) {
    if (stage_ != Stage::waiting) {
        const double y = s_ * (p_next_ - x);
        const double r = y - s_ * (p_prev_ - u_prev_[0]);
        sums.psi_next += law_.potential(y);
        sums.lost += rho_ * r * r;
        sums.pushed += push;
    }
    u_prev_[0] = u_curr_[0];
    u_curr_[0] = x;
}

void Pluck::finish(long n, const Sums& sums) {
    contact_force_ = sums.pushed;
    work_ += 0.5 * sums.pushed * s_ * (p_next_ - p_prev_);
    loss_ += 0.5 * sums.lost;
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
    Sums sums;
    double push = 0.0;
    const double x = solve_point(predicted[0], p_next_, push);
    force[0] = s_ * push;
    take(x, push, sums);
    finish(n, sums);
    return 0.0;
}

void Pluck::force_and_slope(double x, double& force, double& slope) const {
    force = slope = 0.0;
    if (stage_ != Stage::pulling && stage_ != Stage::withdrawing) return;
    // push(r), r = y^{n+1} - y^{n-1} = s (p^{n+1} - x) - y^{n-1}: F = s push, dF/dx = -(push'(r)).
    const double c = s_ * (p_prev_ - u_prev_[0]);
    const double r = s_ * (p_next_ - x) - c;
    const ForceSlope f = law_.push(c, rho_)(r);
    force = s_ * f.force;
    slope = -f.slope;
}

double Pluck::solve_alone(double w) {
    double push = 0.0;
    return solve_point(w, p_next_, push);
}

double Pluck::conclude(long n, double x) {
    double force = 0.0, slope = 0.0;
    force_and_slope(x, force, slope);
    Sums sums;
    take(x, s_ * force, sums);
    finish(n, sums);
    return force;
}

}  // namespace fretbuzz
