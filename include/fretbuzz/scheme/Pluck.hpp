#pragma once
// A plucker (a fingertip or a plectrum) on a prescribed path, pressing on the string over a
// pad at its exact position and width (whatever the grid), as one rigid pad touching the pad's
// mean displacement u_s = s . q (s_j the pad's mean of phi_j, pad_mean_shapes): a penalty
// contact of its own, F = K [y]_+^alpha on the whole pad (spread evenly over it: modal impulse
// (dt^2/mu) F s), y = s (p - u_s) its penetration, s = +1 when it pulls away from the
// fretboard (a pop, "up": it sits between the string and the fretboard) and -1 when it pushes
// toward it ("down"), with a Hunt-Crossley contact loss (ImpactLaw). Heights are in the
// solve's orientation (the fretboard below).
//
// Its path: it appears at start time beside the string (gap away from u_s at levels n - 1 and
// n, so its contact energy starts at 0), moves along s at a constant speed, and lets go when
// its contact force reaches the release force or its height from the string's rest line
// reaches the release displacement, whichever comes first: it then withdraws (moves back at
// the withdraw speed), so the contact ends through the contact law, and once it touches the
// string at neither level it leaves: no energy jumps at any stage.
//
// Discretisation as the obstacle's and the finger's: the force is the discrete gradient of
// the potential between levels n - 1 and n + 1, so that, with p prescribed,
//     E^{n+1/2} - E^{n-1/2} = (Q + rho r) s (p^{n+1} - p^{n-1}) / 2 - rho r^2 / 2,
// r = y^{n+1} - y^{n-1}, E the string's energy plus (Psi(y^{n+1}) + Psi(y^n)) / 2: the first
// term is the work of the prescribed motion, the second the contact loss (>= 0). Alone on the
// string its step is one scalar increasing equation in u_s^{n+1} = w_s + (dt^2/mu) (s . s) F,
// w_s the free step's u_s. Where obstacle points, fingers or other pluckers push in the same
// step the pad is one more unknown in their system (PointContact, beside the fingers'
// heights), for any number of pluckers (the solve's room is planned for the case's).
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/ImpactLaw.hpp"
#include "fretbuzz/scheme/PlayedPart.hpp"
#include "fretbuzz/scheme/PointContact.hpp"

namespace fretbuzz {

class Pluck final : public PlayedPart, public PadPress {
public:
    enum class Stage { waiting, pulling, withdrawing, gone };

    // shape = s (pad_mean_shapes); k = dt^2/mu. step() takes the pad's mean free prediction
    // w_s and writes the force on the string (N) as its one entry.
    Pluck(const PluckSpec& spec, std::vector<double> shape, double dt, double k);
    bool exact() const { return true; }  // (every plucker acts at its exact position)
    std::span<const double> shape() const { return shape_; }  // s
    double shape_square() const { return shape_square_; }      // s . s

    const std::vector<std::size_t>& pad() const override { return pad_; }  // (none on the grid)
    // Levels n - 1 and n of u_s (one entry each).
    void start(std::span<const double> u0, std::span<const double> u1) override;
    // Step n -> n + 1 alone from w_s (one entry): writes its force on the string (N); returns 0
    // (no obstacle's potential under it).
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
    void read_obstacle(const std::vector<double>&) override {}  // (the obstacle is solved beside it)
    bool left() const override { return stage_ == Stage::gone; }

    Stage stage() const { return stage_; }
    // u_s^n and u_s^{n-1}.
    std::span<const double> current() const override { return u_curr_; }
    std::span<const double> previous() const override { return u_prev_; }
    double height() const { return p_curr_; }                  // p^n (solve orientation)
    // p^n while it is on the string (pulling or withdrawing), NaN before and after.
    double body_height() const override;
    double contact_energy() const { return 0.5 * (psi_curr_ + psi_prev_); }
    double energy() const override { return contact_energy(); }
    double work() const override { return work_; }             // work of the prescribed motion so far
    double loss() const override { return loss_; }             // contact loss so far (>= 0)
    double contact_force() const { return contact_force_; }    // on the string, N (last step)
    long release_step() const { return release_step_; }        // -1 until it lets go
    int max_iterations() const override { return max_iterations_; }
    // In the last step: whether the obstacle pushed under it (never: it has no grid pad), and
    // whether the plucker touched.
    bool touched_obstacle() const override { return false; }
    bool acted() const override { return contact_force_ != 0.0; }

private:
    struct Sums {
        double psi_next = 0.0, lost = 0.0, pushed = 0.0;
    };
    // Its solution x (u_s^{n+1}) and its push there into the step's sums.
    void take(double x, double push, Sums& sums);
    void finish(long n, const Sums& sums);
    double solve_point(double w, double p_next, double& push);
    void appear();

    PluckSpec spec_;
    double s_, dt_, k_;
    double shape_square_ = 0.0;
    long start_step_;
    ImpactLaw law_;
    std::vector<std::size_t> pad_;  // empty
    std::vector<double> u_curr_, u_prev_;  // u_s^n, u_s^{n-1} (one entry each)
    double rho_ = 0.0;                     // the step's Hunt-Crossley coefficient
    std::vector<double> shape_;            // s
    Stage stage_ = Stage::waiting;
    double p_curr_ = 0.0, p_prev_ = 0.0;       // p^n, p^{n-1}
    double p_next_ = 0.0;                      // p^{n+1} of the step being taken
    double psi_curr_ = 0.0, psi_prev_ = 0.0;   // Psi(y) at n and n - 1
    double work_ = 0.0, loss_ = 0.0, contact_force_ = 0.0;
    long release_step_ = -1;
    int max_iterations_ = 0;
};

}  // namespace fretbuzz
