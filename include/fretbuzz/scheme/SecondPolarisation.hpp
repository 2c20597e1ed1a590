#pragma once
// The string's second transverse polarisation y (parallel to the fretboard), on the same
// modal basis and grid as z, with a mode table of its own (Plan::propagator_y), advanced by
// its exact modal update
//     y-modes: q^{n+1} = C q^n - C~ q^{n-1} + (dt^2/mu) dx S^T f_y^n.
// The obstacle acts along z only: the Stepper solves the normal contact from z exactly as
// with one polarisation, then hands the normal forces here. At each obstacle point with a
// non-zero normal force F_n, a friction force f_y opposes the sliding (see Friction): a
// scalar solve per point, since S dx S^T = I makes the force at point i move y at point i
// only. At point obstacles held at their exact positions (Plan::point_contact) friction acts
// on each point's row over its width, and the points in contact solve together, with the grid's
// points rubbing beside them (PointFriction).
// Its work per step, dx sum_i f_y (y^{n+1} - y^{n-1}) / 2 (c_p for width at an exact point), is
// never positive and is kept as the friction dissipation, so that
//     H_z + H_y + contact - work + damping(z) + damping(y) + friction = constant
// to round-off. Nothing here does I/O; a one-polarisation run never creates this object.
#include <cstddef>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/scheme/ForceProfile.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PointFriction.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz {

class SecondPolarisation {
public:
    // Starts at n = 0 from modal displacement q0 and velocity v0 of y.
    SecondPolarisation(const Plan& plan, std::span<const double> q0, std::span<const double> v0);

    // n = 0 -> 1: the exact free motion (no contact acts on the first step, as along z).
    void first_step();
    // n -> n + 1 after the normal solve of the same step: `normal` holds (grid point, F_n)
    // of every point that rubs, with its normal force per unit length (the obstacle's, or
    // under a finger the finger's push plus the obstacle's).
    // `point_normal`: the exact points' normal forces per unit length (PointContact's, 0 where a
    // point does not push; empty when none pushes), solved with the grid's where both rub.
    // Force gestures with an angle push y too (known at step n, explicit as along z).
    void step(long n, std::span<const std::pair<std::size_t, double>> normal, std::span<const double> point_normal = {});
    // Free flight over `flown` steps of a flight planned for `planned` (no contact meanwhile):
    // with probes, the first `head` modes are stepped one by one and u_y at the probes kept
    // per step (flight_rows()); the other modes jump in closed form when flown == planned.
    void fly(long flown, long planned, std::size_t head, std::span<const std::vector<double>> probes);
    const std::vector<double>& flight_rows() const { return rows_; }
    // Puts y at rest, keeping the losses so far.
    void silence();

    std::span<const double> modal_displacement() const { return q_; }
    // Coordinates (q, d, v0) that are subnormal (ModalState::subnormal_coordinates).
    std::size_t subnormal_coordinates() const {
        return subnormal_count(q_) + subnormal_count(d_) + subnormal_count(v0_);
    }
    double displacement(std::span<const double> mode_shapes) const;
    double velocity(std::span<const double> mode_shapes) const;
    // Energy terms of the interval (t_{n-1}, t_n) (J), n >= 1.
    double energy() const;               // H_y^{n-1/2}: the y modes' discrete energy
    double damping_dissipated() const { return damping_; }
    double friction_dissipated() const { return friction_; }
    double work() const {  // of the gestures' y parts so far
        double w = 0.0;
        for (const ForceProfile& g : gestures_) w += g.work();
        return w;
    }
    // Points with a non-zero friction force in the last step and that force (N/m); an exact
    // point's at its nearest grid point, as a force per grid step (the same total force).
    std::span<const std::pair<std::size_t, double>> forces() const { return forces_; }
    int max_iterations() const { return max_iterations_; }

private:
    // The gestures' y loads of step n into impulse_ (with the friction's); whether any acts.
    bool add_gesture_loads(long n, bool pushed);
    void spread_forces();
    // Friction at the exact points (with the grid points of joint_index_ if `joint`: their
    // forces then join forces_); predicted_ holds the free step already if `joint`.
    void solve_points(long n, std::span<const double> point_normal, bool joint);
    // Their impulse into impulse_ (added to the grid's if `pushed`); whether anything pushed.
    bool add_point_impulse(bool pushed);
    void report_point_forces();

    const Plan& plan_;
    std::vector<double> q_, d_, v0_;
    std::vector<double> predicted_, impulse_, grid_, before_;
    std::vector<std::pair<std::size_t, double>> forces_;
    std::vector<double> rows_;
    std::optional<FreeFlight> flight_;
    double damping_ = 0.0;
    double friction_ = 0.0;
    std::vector<ForceProfile> gestures_;  // the y parts of the force gestures with an angle
    std::vector<double> gesture_load_;
    PointFriction point_friction_;
    std::vector<double> point_v0_, point_force_;
    std::vector<std::size_t> joint_index_;  // grid points rubbing beside exact points: their solve's data
    std::vector<double> joint_v0_, joint_normal_, joint_force_, joint_velocity_;
    std::vector<double> gesture_at_points_;  // s_g . phi(x_p), gesture by gesture, point by point
    int max_iterations_ = 0;
};

// The initial modal displacement or velocity of a case along one polarisation: cos(angle) v
// along z, sin(angle) v along y (v itself along z with one polarisation, untouched).
std::vector<double> along_polarisation(const std::vector<double>& v, double angle_deg, bool y);
// The same for case c's own polarisations and angle: with one polarisation, all of v along z.
std::vector<double> along_polarisation(const std::vector<double>& v, const Case& c, bool y);
// cos(angle) (z) or sin(angle) (y), exact (0 or +-1) at multiples of 90 degrees.
double polarisation_share(double angle_deg, bool y);

}  // namespace fretbuzz
