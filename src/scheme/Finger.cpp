#include "fretbuzz/scheme/Finger.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <tuple>

#include "../numerics/MonotoneRoot.hpp"
#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr int kMaxIterations = 100;

[[noreturn]] void fail(const FingerSpec& spec, const char* what, double detail) {
    std::ostringstream msg;
    msg.precision(17);
    msg << spec.key << ": the finger's contact solve did not converge (" << what << ", " << detail
        << "); reduce its stiffness or the time step";
    throw SolverError(msg.str());
}
}  // namespace

Finger::Finger(const FingerSpec& spec, double dx, const std::vector<double>& obstacle,
               const PenaltyContact& obstacle_law, double dt, double k)
    : spec_(spec),
      dx_(dx),
      dt_(dt),
      k_(k),
      m_(spec.mass_kg / (dt * dt)),
      law_(1.0, 1.0, spec.loss, dt),
      obstacle_law_(obstacle_law),
      pad_(pad_points(spec.position_m, spec.width_m, dx, obstacle.size())),
      pressing_(spec.force_profile) {
    // The pad's stiffness K_f is shared by its points: per unit length K_f / (n dx).
    law_.set(spec.stiffness / (static_cast<double>(pad_.size()) * dx), spec.exponent);
    for (std::size_t i : pad_) g_.push_back(obstacle[i]);
    const std::size_t n = pad_.size();
    // Room for a pad of the same width anywhere on the grid (place() must not allocate).
    const auto room = std::max(n, static_cast<std::size_t>(spec.width_m / dx) + 2);
    for (auto* v : {&u_curr_, &u_prev_, &guess_, &c_, &rho_, &g_}) v->reserve(room);
    pad_.reserve(room);
    points_.reserve(room);
    u_curr_.assign(n, 0.0);
    u_prev_.assign(n, 0.0);
    guess_.assign(n, 0.0);
    c_.assign(n, 0.0);
    rho_.assign(n, 0.0);
}

double Finger::pressing_force(double t) const { return pressing_.at(t); }

double Finger::pressing_force_at_step(long n) const {
    if (!live_) return pressing_force(static_cast<double>(n) * dt_);
    if (n >= ramp_end_) return ramp_to_;
    if (n <= ramp_start_) return ramp_from_;
    return ramp_from_ + (ramp_to_ - ramp_from_) * static_cast<double>(n - ramp_start_) /
                            static_cast<double>(ramp_end_ - ramp_start_);
}

void Finger::place(double centre_m, double width_m, const std::vector<double>& obstacle) {
    const double width = std::min(width_m, spec_.width_m);
    pad_points(centre_m, width, dx_, obstacle.size(), pad_);
    spec_.position_m = centre_m;
    law_.set(spec_.stiffness / (static_cast<double>(pad_.size()) * dx_), spec_.exponent);
    const std::size_t n = pad_.size();
    for (auto* v : {&u_curr_, &u_prev_, &guess_, &c_, &rho_}) v->assign(n, 0.0);
    read_obstacle(obstacle);
}

void Finger::read_obstacle(const std::vector<double>& obstacle) {
    g_.clear();
    for (std::size_t i : pad_) g_.push_back(obstacle[i]);
}

void Finger::press(double force_n, long from, long ramp_steps) {
    ramp_from_ = pressing_force_at_step(from);
    ramp_to_ = force_n;
    ramp_start_ = from;
    ramp_end_ = from + std::max(ramp_steps, 1L);
    live_ = true;
}

void Finger::rest() {
    z_ = dz_ = dz_before_ = 0.0;
    psi_curr_ = psi_prev_ = 0.0;
    contact_force_ = 0.0;
    touched_obstacle_ = false;
}

double Finger::energy() const {
    const double v = dz_ / dt_;
    return 0.5 * spec_.mass_kg * v * v + contact_energy();
}

void Finger::start(std::span<const double> u0, std::span<const double> u1) {
    const double z0 = *std::max_element(u0.begin(), u0.end()) + spec_.initial_gap_m;
    dz_ = -spec_.initial_velocity * dt_;  // toward the fretboard: down in the solve's orientation
    dz_before_ = dz_;
    z_ = z0 + dz_;
    psi_prev_ = psi_curr_ = 0.0;
    for (std::size_t p = 0; p < pad_.size(); ++p) {
        u_prev_[p] = u0[p];
        u_curr_[p] = u1[p];
        guess_[p] = u1[p];
        psi_prev_ += law_.potential(u0[p] - z0);
        psi_curr_ += law_.potential(u1[p] - z_);
    }
}

Finger::Point Finger::solve_point(std::size_t p, double w, double s, double guess) const {
    // h(x) = (x - w) - k Q_obstacle(x) + k P(x - z^{n+1}), increasing with slope >= 1.
    const double g = g_[p];
    const bool obstacle = std::isfinite(g);
    const double a_o = g - u_prev_[p];
    const double c = c_[p];
    // Fixed over the iteration: the laws' powers of them, once.
    const PenaltyContact::Gradient obstacle_at = obstacle_law_.gradient(obstacle ? a_o : 0.0);
    const ImpactLaw::Push finger_at = law_.push(c, rho_[p]);
    const double z_next_minus_z = s;
    Point pt;
    const auto evaluate = [&](double x) {
        pt.x = x;
        pt.y = (x - z_) - z_next_minus_z;
        detail::MonotoneValue v{x - w, std::abs(x) + std::abs(w), 1.0};
        pt.obstacle_force = 0.0;
        double obstacle_slope = 0.0;
        if (obstacle) {
            const double r_o = u_prev_[p] - x;
            const ForceSlope o = obstacle_at(r_o);
            pt.obstacle_force = o.force;
            obstacle_slope = o.slope;
            v.slope += k_ * o.slope;
            v.h -= k_ * pt.obstacle_force;
            v.scale += k_ * pt.obstacle_force;
        }
        const double psi_slope = v.slope;
        const double r_f = pt.y - c;
        const ForceSlope push = finger_at(r_f);  // Q + rho r_f and its slope
        const double push_slope = push.slope;
        pt.push = push.force;
        v.h += k_ * pt.push;
        // y and r_f carry the rounding of z and c, however far the finger is: through the push's
        // slope it is round-off in h too.
        v.scale += k_ * (std::abs(pt.push) + push_slope * (std::abs(z_) + std::abs(s) + std::abs(c)));
        v.slope = psi_slope + k_ * push_slope;
        pt.slope = -push_slope * psi_slope / v.slope;  // d(push)/dZ: dy/dZ = -psi'/h'
        pt.response = -(obstacle_slope + push_slope) / v.slope;  // dF/dw = (1/h' - 1) / k, h' = 1 + k (...)
        pt.push_response = push_slope / v.slope;
        return v;
    };
    if (detail::monotone_root(evaluate, guess, kMaxIterations) < 0) fail(spec_, "pad point", pt.x);
    if (obstacle) pt.obstacle_psi = obstacle_law_.potential(g - pt.x);
    return pt;
}

double Finger::step(long n, std::span<const double> predicted, std::span<double> force) {
    prepare(n);
    trial(predicted, force);
    return commit();
}

void Finger::prepare(long n) {
    const std::size_t count = pad_.size();
    press_ = pressing_force_at_step(n);
    const double z_prev = z_ - dz_;
    for (std::size_t p = 0; p < count; ++p) {
        c_[p] = u_prev_[p] - z_prev;
        guess_[p] = 2.0 * u_curr_[p] - u_prev_[p];  // u^{n+1} carried on at its last rate
        // Hunt-Crossley loss, its coefficient taken at level n so the step stays exactly lossy.
        rho_[p] = law_.damping(u_curr_[p] - z_);
    }
}

double Finger::sweep(std::span<const double> predicted, double s, double& slope) {
    // G(s) = m (s - dz) + F - dx sum push(s), s = z^{n+1} - z^n: increasing, slope >= m.
    const std::size_t count = pad_.size();
    points_.resize(count);  // (within the reserved room)
    double push = 0.0, push_slope = 0.0;
    for (std::size_t p = 0; p < count; ++p) {
        points_[p] = solve_point(p, predicted[p], s, guess_[p]);
        guess_[p] = points_[p].x;
        push += points_[p].push;
        push_slope += points_[p].slope;
    }
    contact_force_ = dx_ * push;
    slope = m_ - dx_ * push_slope;
    return m_ * (s - dz_) + press_ - contact_force_;
}

void Finger::set_residual(double s, double G, double slope) {
    s_ = s;
    g_slope_ = slope;
    residual_ = G / m_;
    // Round-off in G: its terms', and its slope times the rounding of z^{n+1} = z^n + s, which
    // every pad point's contact sees (a stiff pad: the pad's terms dominate).
    residual_size_ = (m_ * (std::abs(s) + std::abs(dz_)) + std::abs(press_) + std::abs(contact_force_) +
                      slope * (std::abs(z_) + std::abs(s))) / m_;
}

void Finger::trial(std::span<const double> predicted, std::span<double> force) {
    double s = dz_ + (contact_force_ - press_) / m_;
    double slope = m_;
    double G = sweep(predicted, s, slope);
    double lo = s, hi = s;
    (G > 0.0 ? lo : hi) = s - G / m_;
    int it = 0;
    for (; it < kMaxIterations; ++it) {
        set_residual(s, G, slope);
        if (std::abs(residual_) <= 8.0 * kEps * residual_size_ ||
            hi - lo <= 2.0 * kEps * std::max(std::abs(lo), std::abs(hi)))
            break;
        double next = s - G / slope;
        const bool newton = next > lo && next < hi;
        if (!newton) next = 0.5 * (lo + hi);
        const double previous = s, g_before = G;
        s = next;
        G = sweep(predicted, s, slope);
        (G > 0.0 ? hi : lo) = s;
        if (std::abs(s - previous) <= kEps * std::abs(s)) break;
        // A Newton step of a few ulps of z that does not halve G: G is at the round-off of
        // the pad points' solves (as in detail::monotone_root).
        if (newton && std::abs(G) > 0.5 * std::abs(g_before) &&
            std::abs(s - previous) <= 64.0 * kEps * (std::abs(z_) + std::abs(s)))
            break;
    }
    if (it == kMaxIterations) fail(spec_, "finger height", s);
    max_iterations_ = std::max(max_iterations_, it + 1);
    set_residual(s, G, slope);
    forces(force);
}

void Finger::trial_at(std::span<const double> predicted, double s, std::span<double> force) {
    double slope = m_;
    const double G = sweep(predicted, s, slope);
    set_residual(s, G, slope);
    forces(force);
}

void Finger::forces(std::span<double> force) const {
    for (std::size_t p = 0; p < points_.size(); ++p) force[p] = points_[p].obstacle_force - points_[p].push;
}

double Finger::commit() {
    const std::size_t count = pad_.size();
    const std::vector<Point>& pts = points_;
    const double press = press_, s = s_;
    double obstacle_psi = 0.0, psi_next = 0.0, lost = 0.0;
    touched_obstacle_ = false;
    for (std::size_t p = 0; p < count; ++p) {
        const Point& pt = pts[p];
        touched_obstacle_ = touched_obstacle_ || pt.obstacle_force != 0.0;
        obstacle_psi += pt.obstacle_psi;
        psi_next += law_.potential(pt.y);
        const double r = pt.y - c_[p];
        lost += rho_[p] * r * r;
        u_prev_[p] = u_curr_[p];
        u_curr_[p] = pt.x;
    }
    loss_ += 0.5 * dx_ * lost;
    work_ -= 0.5 * press * (s + dz_);
    psi_prev_ = psi_curr_;
    psi_curr_ = psi_next;
    z_ += s;
    dz_before_ = dz_;
    dz_ = s;
    return obstacle_psi;
}

}  // namespace fretbuzz
