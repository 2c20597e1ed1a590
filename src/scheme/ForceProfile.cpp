#include "fretbuzz/scheme/ForceProfile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/scheme/SecondPolarisation.hpp"

namespace fretbuzz {

ForceProfile::ForceProfile(const ForceSpec& spec, double dx, const std::vector<double>& obstacle,
                           const PenaltyContact& law, double dt, double k)
    : force_(spec.force_profile),
      direction_(spec.direction * polarisation_share(spec.angle_deg, false)),  // its z part
      dx_(dx),
      dt_(dt),
      k_(k),
      law_(law),
      pad_(pad_points(spec.position_m, spec.width_m, dx, obstacle.size())) {
    for (std::size_t i : pad_) g_.push_back(obstacle[i]);
    u_curr_.assign(pad_.size(), 0.0);
    u_prev_.assign(pad_.size(), 0.0);
}

void ForceProfile::read_obstacle(const std::vector<double>& obstacle) {
    for (std::size_t p = 0; p < pad_.size(); ++p) g_[p] = obstacle[pad_[p]];
}

double ForceProfile::body_height() const { return std::numeric_limits<double>::quiet_NaN(); }

void ForceProfile::start(std::span<const double> u0, std::span<const double> u1) {
    u_prev_.assign(u0.begin(), u0.end());
    u_curr_.assign(u1.begin(), u1.end());
}

double ForceProfile::step(long n, std::span<const double> predicted, std::span<double> force) {
    const double applied = -direction_ * force_.at(static_cast<double>(n) * dt_) / (static_cast<double>(pad_.size()) * dx_);
    double psi = 0.0, work = 0.0;
    acted_ = applied != 0.0;
    touched_obstacle_ = false;
    for (std::size_t p = 0; p < pad_.size(); ++p) {
        const double w = predicted[p] + k_ * applied;
        double u_next = w, obstacle_force = 0.0;
        if (std::isfinite(g_[p])) {
            const double a = g_[p] - u_prev_[p];
            const ContactSolution s = law_.solve(a, g_[p] - w - a, k_);
            const double eta_next = a + s.increment;
            u_next = g_[p] - eta_next;
            obstacle_force = s.force;
            touched_obstacle_ = touched_obstacle_ || s.force != 0.0;
            psi += law_.potential(eta_next);
            max_iterations_ = std::max(max_iterations_, s.iterations);
        }
        force[p] = applied + obstacle_force;
        work += applied * (u_next - u_prev_[p]);
        u_prev_[p] = u_curr_[p];
        u_curr_[p] = u_next;
    }
    work_ += 0.5 * dx_ * work;
    return psi;
}

}  // namespace fretbuzz
