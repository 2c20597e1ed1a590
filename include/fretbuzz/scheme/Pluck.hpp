#pragma once
// A plucker (a fingertip or a plectrum) on a prescribed path: a pad of grid points whose
// height p(t) is given, touching the string from one side through a penalty contact of its
// own, f_i = K [y_i]_+^alpha per unit length (K = K_p / pad length), y_i = s (p - u_i) its
// penetration, s = +1 when it pulls away from the fretboard (a pop, "up": it sits between
// the string and the fretboard) and -1 when it pushes toward it ("down"), with a
// Hunt-Crossley contact loss rho_i (y_i^{n+1} - y_i^{n-1}), rho_i = lambda K [y_i^n]_+^alpha / (2 dt).
// Heights are in the solve's orientation (the fretboard below).
//
// Its path: it appears at start time beside the string (gap away from the pad's nearest
// point at levels n - 1 and n, so its contact energy starts at 0), moves along s at a
// constant speed, and lets go when its contact force reaches the release force or its
// height from the string's rest line reaches the release displacement, whichever comes
// first: it then withdraws (moves back at the withdraw speed), so the contact ends through
// the contact law, and once it touches the string at neither level it leaves (its pad
// points go back to the obstacle's solve): no energy jumps at any stage.
//
// Discretisation as the obstacle's and the finger's: the force is the discrete gradient of
// the potential between levels n - 1 and n + 1, so that, with p prescribed,
//     E^{n+1/2} - E^{n-1/2} = dx sum_i (Q_i + rho_i r_i) s (p^{n+1} - p^{n-1}) / 2 - dx sum_i rho_i r_i^2 / 2,
// r_i = y_i^{n+1} - y_i^{n-1}, E the string's energy plus dx sum_i (Psi(y_i^{n+1}) + Psi(y_i^n)) / 2:
// the first term is the work of the prescribed motion, the second the contact loss (>= 0).
// Each pad point is one scalar increasing equation in u_i^{n+1} (the plucker's and the
// obstacle's terms both increase with it): no global solve.
//
// At its exact position and width (whatever the grid) the plucker is one rigid pad touching
// the pad's mean displacement u_s = s . q, s_j the pad's mean of phi_j (pad_mean_shapes): the
// same law with y = s (p - u_s), force F = K_p [y]_+^alpha (+ its Hunt-Crossley term) on the
// whole pad, spread evenly over it (modal impulse (dt^2/mu) F s). The stages and the scalar
// solve above then act on one entry of weight 1 (dx -> 1, K -> K_p) whose step factor is
// (dt^2/mu) (s . s): u_s^{n+1} = w_s + (dt^2/mu) (s . s) F with w_s the free step's u_s. Where
// obstacle points, fingers or other pluckers push in the same step the pad is one more unknown
// in their system (PointContact, beside the fingers' heights): the stepper uses it for up to
// PointContact::kMaxPads pluckers.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"
#include "fretbuzz/scheme/PlayedPart.hpp"
#include "fretbuzz/scheme/PointContact.hpp"

namespace fretbuzz {

class Pluck final : public PlayedPart, public PadPress {
public:
    enum class Stage { waiting, pulling, withdrawing, gone };

    // obstacle: heights at every grid point in the solve's orientation (-inf: none); k = dt^2/mu.
    Pluck(const PluckSpec& spec, double dx, const std::vector<double>& obstacle, const PenaltyContact& obstacle_law,
          double dt, double k);
    // At its exact position: shape = s (pad_mean_shapes), no grid pad; step() takes the pad's
    // mean free prediction w_s and writes the force on the string (N) as its one entry.
    Pluck(const PluckSpec& spec, std::vector<double> shape, const PenaltyContact& obstacle_law, double dt, double k);
    bool exact() const { return !shape_.empty(); }
    std::span<const double> shape() const { return shape_; }  // s (exact only)
    double shape_square() const { return shape_square_; }      // s . s (exact only)

    const std::vector<std::size_t>& pad() const override { return pad_; }
    void start(std::span<const double> u0, std::span<const double> u1) override;
    // Step n -> n + 1 from the pad points' free predictions w (pad order): writes the total
    // force per unit length at each pad point (plucker and obstacle) and returns
    // sum_i Psi_obstacle(eta_i^{n+1}) over the pad.
    double step(long n, std::span<const double> predicted, std::span<double> force) override;
    // At its exact position, solved with other contacts (PointContact): step() in three parts.
    // prepare(n) sets the step's stage, p^{n+1} and loss coefficient; force_and_slope gives the
    // force F on the string (N, solve orientation) at u_s^{n+1} = x and dF/dx (<= 0);
    // solve_alone(w) is u_s^{n+1} with nothing else acting; conclude(n, x) takes the solution
    // (energy, work, loss, stage) and returns F.
    void prepare(long n);
    void force_and_slope(double x, double& force, double& slope) const override;
    double solve_alone(double w);
    double conclude(long n, double x);
    void read_obstacle(const std::vector<double>& obstacle) override;
    bool left() const override { return stage_ == Stage::gone; }

    Stage stage() const { return stage_; }
    // u^n and u^{n-1} at the pad points (pad order; exact: u_s): where the obstacle's solve takes over.
    std::span<const double> current() const override { return u_curr_; }
    std::span<const double> previous() const override { return u_prev_; }
    double height() const { return p_curr_; }                  // p^n (solve orientation)
    // p^n while it is on the string (pulling or withdrawing), NaN before and after.
    double body_height() const override;
    double contact_energy() const { return 0.5 * dx_ * (psi_curr_ + psi_prev_); }
    double energy() const override { return contact_energy(); }
    double work() const override { return work_; }             // work of the prescribed motion so far
    double loss() const override { return loss_; }             // contact loss so far (>= 0)
    double contact_force() const { return contact_force_; }    // on the string, N (last step)
    long release_step() const { return release_step_; }        // -1 until it lets go
    int max_iterations() const override { return max_iterations_; }
    // In the last step: whether the obstacle pushed on a pad point, and whether the plucker touched.
    bool touched_obstacle() const override { return touched_obstacle_; }
    bool acted() const override { return contact_force_ != 0.0; }

private:
    struct Sums {
        double psi_next = 0.0, lost = 0.0, pushed = 0.0;
    };
    // Entry p's solution x (u^{n+1}) and the plucker's push there into the step's sums.
    void take(std::size_t p, double x, double push, Sums& sums);
    void finish(long n, const Sums& sums);
    double solve_point(std::size_t p, double w, double p_next, double& obstacle_force, double& push);
    void appear();

    PluckSpec spec_;
    double s_, dx_, dt_, k_;
    double shape_square_ = 0.0;
    long start_step_;
    PenaltyContact law_;
    const PenaltyContact& obstacle_law_;
    std::vector<std::size_t> pad_;
    std::vector<double> g_, u_curr_, u_prev_, rho_;
    std::vector<double> shape_;  // s where it acts at its exact position, else empty
    Stage stage_ = Stage::waiting;
    double p_curr_ = 0.0, p_prev_ = 0.0;       // p^n, p^{n-1}
    double p_next_ = 0.0;                      // p^{n+1} of the step being taken
    double psi_curr_ = 0.0, psi_prev_ = 0.0;   // sum_i Psi(y_i) at n and n - 1
    double work_ = 0.0, loss_ = 0.0, contact_force_ = 0.0;
    long release_step_ = -1;
    int max_iterations_ = 0;
    bool touched_obstacle_ = false;
};

}  // namespace fretbuzz
