#pragma once
// A lumped finger (or a thumb) touching the string from the side away from the fretboard:
// a mass M with height z, a penalty contact of its own along a pad of grid points,
//     f_i = K [u_i - z]_+^alpha  (per unit length, K = K_f / (pad length)),
// a Hunt-Crossley contact loss r_i (du_i/dt - dz/dt), r_i = lambda K [u_i - z]_+^alpha,
// and a force F(t) pressing it toward the fretboard (finger models with a mass, a power-law
// contact and a loss: Bilbao and Torin, "Numerical modeling and sound synthesis for
// articulated string/fretboard interactions", JAES 2015; Desvages and Bilbao, Appl. Sci.
// 2016, for the fingers of a bowed string). The solve sees the fretboard below (u -> -u
// when the case's obstacle is above), so the finger is always above and pushes down.
//
// Discretisation (the obstacle's, Issanchou et al. 2017): the contact force is the discrete
// gradient of the potential between levels n-1 and n+1, velocities are centred, and
//     M (z^{n+1} - 2 z^n + z^{n-1}) / dt^2 = dx sum_i [Q_i + rho_i (y_i - c_i)] - F^n,
// with y_i = u_i^{n+1} - z^{n+1}, c_i = u_i^{n-1} - z^{n-1}, Q_i the difference quotient and
// rho_i = r_i^n / (2 dt). Then, exactly (to round-off),
//     E^{n+1/2} - E^{n-1/2} = -F^n (z^{n+1} - z^{n-1}) / 2 - dx sum_i rho_i (y_i - c_i)^2 / 2,
// E = the string's energy + M/2 ((z^{n+1} - z^n)/dt)^2 + dx sum_i (Psi(y^{n+1}) + Psi(y^n))/2:
// the pressing force's work in, the contact loss out (>= 0).
//
// The solve stays local. At a pad point u_i^{n+1} = w_i + (dt^2/mu) f_i (S S^T = I/dx), so for
// a given z^{n+1} each point is a scalar monotone equation (finger and obstacle terms both
// increasing in u_i^{n+1}); the finger's own equation G(z^{n+1}) = 0 is then increasing in
// z^{n+1} (the contact force on it can only fall as it rises). Both are solved by Newton's
// method inside a bracket (the slopes are at least 1 and M/dt^2), with the finger's slope
// from the inner solutions: a nested scalar solve, no global system. Failure throws. Beside
// exact points (PointContact::GridPads) s = z^{n+1} - z^n is instead one unknown of their Newton
// solve: trial_at() solves each pad point at a given s, and G(s) is one more row.
#include <algorithm>
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/ImpactLaw.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"
#include "fretbuzz/scheme/PlayedPart.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"

namespace fretbuzz {

class Finger final : public PlayedPart {
public:
    // obstacle: heights at every grid point, in the solve's orientation (-inf: none);
    // k = dt^2 / mu.
    Finger(const FingerSpec& spec, double dx, const std::vector<double>& obstacle, const PenaltyContact& obstacle_law,
           double dt, double k);

    // Grid points of the pad, in increasing order.
    const std::vector<std::size_t>& pad() const override { return pad_; }
    // Levels 0 and 1 of the string at the pad points (the string's first step is free): the
    // finger starts spec.initial_gap_m above the highest pad point with its initial velocity.
    void start(std::span<const double> u0, std::span<const double> u1) override;
    // Step n -> n + 1 given the pad points' free predictions w (pad order). Writes the total
    // force per unit length on the string at each pad point (finger and obstacle) into
    // `force` and returns sum_i Psi_obstacle(eta_i^{n+1}) over the pad.
    double step(long n, std::span<const double> predicted, std::span<double> force) override;
    // The same step in parts, for a solve that tries several predictions of the pad (exact
    // points beside it, whose forces move the pad through the modes): prepare(n), then any
    // number of trials (nothing moves on), then commit() with the last trial's solution.
    void prepare(long n);
    // The pad's forces per unit length for predictions w (pad order), as step() writes them,
    // the finger's height solved (height_step(): its s = z^{n+1} - z^n).
    void trial(std::span<const double> predicted, std::span<double> force);
    // A trial at a given s, the finger's height one more unknown of a larger Newton solve: each
    // pad point's own equation only. residual() is then the finger's equation at s.
    void trial_at(std::span<const double> predicted, double s, std::span<double> force);
    double height_step() const { return s_; }
    // s carried on from the last two steps (a start for a solve of the next).
    double height_guess() const { return 2.0 * dz_ - dz_before_; }
    // The finger's equation at the last trial, G(s) / (M/dt^2) (m; G = 0 at trial()'s s), the
    // size its round-off is relative to, and its slope in s.
    double residual() const { return residual_; }
    double residual_size() const { return residual_size_; }
    double residual_slope() const { return g_slope_ / m_; }
    // The last trial's slopes at pad point p: its force per unit length against its prediction
    // at a fixed s, and against s; the residual's against p's prediction is pull() * lift(p).
    double response(std::size_t p) const { return points_[p].response; }
    double lift(std::size_t p) const { return points_[p].push_response; }
    double pull() const { return -dx_ / m_; }
    // Moves the state on with the last trial; returns step()'s sum of Psi_obstacle.
    double commit();
    std::span<const double> current() const override { return u_curr_; }
    std::span<const double> previous() const override { return u_prev_; }

    double pressing_force(double t) const;

    // Run-time use (a real-time engine); none of these allocates.
    // Moves the pad to the grid points within width/2 of centre_m (width at most the spec's: the
    // pad's room is reserved for it) and reads the obstacle there again. start() must follow.
    void place(double centre_m, double width_m, const std::vector<double>& obstacle);
    // Reads the obstacle at the pad again (after its heights changed).
    void read_obstacle(const std::vector<double>& obstacle) override;
    // From step `from` on, the pressing force goes linearly from its value then to force_n over
    // `ramp_steps` steps and stays there (the spec's profile no longer counts).
    void press(double force_n, long from, long ramp_steps);
    // Forgets the finger's motion and contact (off the string); its work and loss so far stay.
    void rest();
    double height() const { return z_; }                     // z^n (solve orientation)
    double body_height() const override { return z_; }
    double energy() const override;                          // kinetic + contact, (n-1, n)
    double contact_energy() const { return 0.5 * dx_ * (psi_curr_ + psi_prev_); }
    double work() const override { return work_; }           // pressing force's work so far
    double loss() const override { return loss_; }           // contact loss so far (>= 0)
    double contact_force() const { return contact_force_; }  // total force on the finger, N (last step)
    int max_iterations() const override { return max_iterations_; }
    // In the last step: whether the obstacle pushed on a pad point, and whether the finger touched.
    bool touched_obstacle() const override { return touched_obstacle_; }
    bool acted() const override { return contact_force_ != 0.0; }

    // Normal force per unit length on pad point p in the last step: the finger's push plus the
    // obstacle's (friction along y, with two polarisations, acts on their sum).
    double normal_force(std::size_t p) const { return std::max(points_[p].push, 0.0) + points_[p].obstacle_force; }
    double rubbing_force(std::size_t p) const override { return normal_force(p); }

private:
    struct Point {
        double x = 0.0;      // u^{n+1}
        double y = 0.0;      // u^{n+1} - z^{n+1}
        double push = 0.0;   // Q + rho (y - c): force per unit length on the finger
        double slope = 0.0;  // d(push)/dZ through this point's inner solution
        double obstacle_force = 0.0, obstacle_psi = 0.0;
        double response = 0.0;       // dF/dw at a fixed finger height: (1/h' - 1) / k
        double push_response = 0.0;  // d(push)/dw at a fixed finger height
    };
    Point solve_point(std::size_t p, double w, double s, double guess) const;
    // Every pad point's solution at s (into points_); returns G(s), its slope into `slope`.
    double sweep(std::span<const double> predicted, double s, double& slope);
    void set_residual(double s, double G, double slope);
    // The last sweep's force per unit length on the string at each pad point (finger and obstacle).
    void forces(std::span<double> force) const;
    double pressing_force_at_step(long n) const;

    FingerSpec spec_;
    double dx_, dt_, k_, m_;  // m_ = M / dt^2
    ImpactLaw law_;  // the pad's contact with the string (its Hunt-Crossley loss: spec.loss)
    const PenaltyContact& obstacle_law_;
    std::vector<std::size_t> pad_;
    TimeProfile pressing_;
    std::vector<double> g_;                       // obstacle height at the pad points
    std::vector<double> u_curr_, u_prev_, guess_;  // u^n, u^{n-1}, last u^{n+1} (pad order)
    std::vector<double> c_, rho_;                  // per step: u^{n-1} - z^{n-1}, loss coefficient
    double z_ = 0.0, dz_ = 0.0;                    // z^n and z^n - z^{n-1} (difference form keeps digits)
    double dz_before_ = 0.0;                       // z^{n-1} - z^{n-2}
    double psi_curr_ = 0.0, psi_prev_ = 0.0;       // sum_i Psi_f(u_i - z) at n and n-1
    std::vector<Point> points_;                    // scratch: the inner solutions
    double press_ = 0.0, s_ = 0.0, g_slope_ = 0.0;  // the step's pressing force; the last trial's s and dG/ds
    double residual_ = 0.0, residual_size_ = 0.0;   // the last trial's G / m_ and its size
    double work_ = 0.0, loss_ = 0.0, contact_force_ = 0.0;
    int max_iterations_ = 0;
    bool touched_obstacle_ = false;
    // The run-time pressing force (press): a ramp over steps [ramp_start_, ramp_end_].
    bool live_ = false;
    long ramp_start_ = 0, ramp_end_ = 0;
    double ramp_from_ = 0.0, ramp_to_ = 0.0;
};

}  // namespace fretbuzz
