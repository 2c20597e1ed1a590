#pragma once
// The rigid limit of the penalty contact: Newton's impact law with restitution e, discretised
// by Moreau-Jean time stepping over the exact modal propagator (Issanchou, Acary, Perignon,
// Touze, Le Carrou, "Nonsmooth contact dynamics for the numerical simulation of collisions in
// musical string instruments", JASA 143, 2018; Jean, CMAME 177, 1999). Between contacts each
// mode steps exactly (ModalPropagator). At the obstacle points whose free prediction ends the
// step at or below the obstacle, the impulses lambda_c >= 0 and the normal velocities after the
// step are complementary:
//     u_c^+ + e_c u_c^- >= 0,   lambda_c >= 0,   lambda_c (u_c^+ + e_c u_c^-) = 0,
// e_c = e where the point approached the obstacle over the last step (u_c^- <= 0), 1 where it
// moved away (its free step then reverses into the obstacle: no approach for e to act on),
// u_c^- = phi_c . d^n and u_c^+ = phi_c . d^{n+1} the point's displacements over the step before
// and after (d = q^n - q^{n-1}), with u_c^+ = u_c^free + sum_k W_ck lambda_k, W = Phi Phi^T the
// Delassus matrix in modal coordinates (modal mass mu, impulse mu lambda / dt). On the grid the
// rows of S are orthogonal (W = I / dx), so each grid point is one scalar problem; exact points
// off the grid couple, and every point in contact is then solved in one LCP (LemkeSolver).
//
// Energy: an impulse's work over the step is mu/(2 dt^2) lambda_c (u_c^+ + u_c^-), which
// complementarity makes mu/(2 dt^2) lambda_c (1 - e_c) u_c^-: exactly zero at e = 1 or where
// the point moved away, a loss otherwise ((1 - e^2) times the normal kinetic energy for one
// point). With e_c = e everywhere an impulse on a point that moved away would gain
// lambda_c (1 - e) u_c^- > 0 (at 15.68 kHz on the Music neck, e = 0: 0.89 H(0) over 0.4 s). The
// ledger keeps the loss, so that H + damping + impact losses is constant to round-off.
// Penetration is not corrected at the position level (the Moreau-Jean scheme's O(dt) drift
// into the obstacle at e < 1).
//
// Force gestures (a prescribed F(t) on a pad) load the free prediction and the step's impulse
// as they do the penalty's; their work is work(), so that H - W + D stays H^{1/2}. While one
// may act the string does not fly, and after a loaded step the screening's bound is recomputed.
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/numerics/Lcp.hpp"
#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Screening.hpp"

namespace fretbuzz {

class NewtonImpact {
public:
    // Starts at n = 0 from modal displacement q0 and velocity v0 (the solve's orientation, as
    // Stepper's). Refuses (InputError naming the key) a plan whose law is not the impact law.
    NewtonImpact(const Plan& plan, std::span<const double> q0, std::span<const double> v0);

    // n -> n + 1 (the first step is the exact free motion, as the penalty scheme's).
    void step() { (this->*step_)(); }

    // Free flight over at most flight.steps() steps, while no point is awake and the screening
    // proves none can touch (Screening::fly_head: the points it wakes are looked at on the
    // first `head` >= kMinimumFlightModes modes plus a bound on the rest): the head modes step
    // one by one, each step's row products probes . q over them going to `rows` (probes.size()
    // values a step), the others jump in closed form at the end (flight maps them from mode 0;
    // a flight cut short steps them). Returns the steps flown.
    long free_flight(const FreeFlight& flight, std::size_t head, std::span<const std::vector<double>> probes,
                     std::vector<double>& rows);

    const Plan& plan() const { return *plan_; }
    long step_index() const { return n_; }
    double time() const { return static_cast<double>(n_) * plan_->dt(); }
    std::span<const double> modal_displacement() const { return modes_.q(); }  // q^n
    std::span<const double> modal_difference() const { return modes_.d(); }    // q^n - q^{n-1}
    double displacement(std::span<const double> mode_shapes) const { return modes_.at(mode_shapes.data()); }

    // H^{n-1/2} (the string's: a rigid obstacle stores nothing), the damping's losses and the
    // impacts' since H^{1/2}, and the force gestures' work; energy() - work() + dissipated()
    // stays H^{1/2} to round-off.
    double energy() const { return plan_->modal_energy_scale() * modes_.scaled_energy(); }
    double damping_dissipated() const { return damping_; }
    double impact_loss() const { return impact_loss_; }
    double dissipated() const { return damping_ + impact_loss_; }
    double work() const { return gestures_.add_work(0.0); }

    // The points that took an impulse in the last step (screened index: grid i, exact point
    // N + p) and its mean force per unit length over the step, mu lambda / (dt^2 dx) (N/m, what
    // the penalty reports at a grid point).
    std::span<const std::pair<std::size_t, double>> forces() const { return forces_; }
    bool touched_obstacle() const { return !forces_.empty(); }
    long contact_steps() const { return contact_steps_; }
    long points_checked() const { return points_checked_; }  // predictions formed at obstacle points
    int max_pivots() const { return max_pivots_; }            // of the joint solves so far

private:
    using StepFunction = void (NewtonImpact::*)();
    void first_step();
    void contact_step();
    // The points that might end the step in contact: the awake ones and those the screening
    // wakes; their predicted gaps into predicted_.
    void look_at_points();
    // lambda for the active points, scalar on the grid or one LCP with exact points.
    void solve_impulses();
    void put_to_sleep();

    const Plan* plan_;
    ModalState modes_;
    ForceGestures gestures_;
    Screening screening_;  // its scheduler wakes the points; its flights step the head modes
    LemkeSolver lemke_;
    StepFunction step_;
    double restitution_;
    bool screen_;
    long n_ = 0;
    std::vector<std::size_t> awake_;          // points looked at every step
    std::vector<unsigned char> is_awake_;
    std::vector<std::size_t> due_;
    std::vector<double> predicted_;           // free u^{n+1} at awake_ points
    std::vector<std::size_t> active_;         // points in contact this step
    std::vector<const double*> active_rows_;
    std::vector<double> before_, free_step_, lambda_, delassus_, lcp_q_, after_;
    std::vector<double> impulse_;             // modal, when more points push than a pass holds
    std::vector<std::pair<std::size_t, double>> forces_;
    double damping_ = 0.0, impact_loss_ = 0.0;
    long contact_steps_ = 0, points_checked_ = 0;
    int max_pivots_ = 0;
};

}  // namespace fretbuzz
