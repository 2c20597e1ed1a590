#pragma once
// Everything that stays fixed during a run, computed and checked once (the FFTW idea
// of planning before executing): the modal basis and its transform, the exact per-mode
// propagator, the obstacle on the grid, the contact law and the step size. The obstacle
// is held as the contact solve sees it: below the string (an obstacle above is mirrored).
// Planning refuses a sampling rate at which modes alias onto low frequencies under contact.
#include <cstddef>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/scheme/Friction.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/numerics/ModalBasis.hpp"
#include "fretbuzz/scheme/ModalPropagator.hpp"
#include "fretbuzz/scheme/PenaltyContact.hpp"
#include "fretbuzz/scheme/PointContact.hpp"

namespace fretbuzz {

struct PlanOptions {
    // Skip grid points that provably cannot touch the obstacle (see ContactScreen).
    // false gives the straightforward path: every point is solved at every step.
    bool screen_contacts = true;
    // Let a run turn screening off where it cannot pay (see choose_screening); the run's
    // summary says which way it went and why.
    bool choose_screening = true;
    // Above this many points to evaluate, use the fast sine transform instead of rows of S.
    std::size_t transform_threshold = 0;  // 0: chosen from the grid size
    // Let FFTW time its candidate algorithms when planning (worth it for long runs).
    bool measure_transform = false;
    // Closed-form contact quotients for alpha = 1, 3/2, 2, 3; false: pow/expm1/log1p for
    // every exponent (the reference they are tested against).
    bool closed_form_contact = true;
    // One pass over the modes per step: the step also forms the next step's prediction at the
    // points it solves, the observation row's displacement (Stepper::observe) and the energy
    // it is audited for; false: a pass for each (the reference it is tested against).
    bool fused_step = true;
    // Point obstacles that all lie on grid points, one grid step wide, are solved as grid points
    // (screening, free flight, the grid's kernels); false: by PointContact like any other
    // points (the reference the grid's path is tested against).
    bool grid_points_on_grid = true;
};

// Screening pays by skipping points that cannot touch and by free flight between contacts.
// With an obstacle of a few points, a string resting on it (or a run that cannot fly free,
// its outputs coming every step) gains nothing from free flight and skips few points, so
// keeping the speed bound costs more than solving them all.
struct ScreeningChoice {
    bool screen = true;
    std::string reason;
};
ScreeningChoice choose_screening(const Case& c, const PlanOptions& options, bool can_fly);

class Plan {
public:
    Plan(const Case& c, double dt, PlanOptions options = {});

    std::size_t mode_count() const { return basis_.mode_count(); }
    double dt() const { return dt_; }
    double linear_density() const { return mu_; }
    // rho / (2 dt^2) and rho / (4 dt^2): what scales the modal energy and the losses the
    // kernels sum (scaled_modal_energy, advance's return), divided once for every stepper.
    double modal_energy_scale() const { return energy_scale_; }
    double modal_loss_scale() const { return loss_scale_; }
    const ModalBasis& basis() const { return basis_; }
    const ModalPropagator& propagator() const { return propagator_; }
    // The kernel every step of a run calls (Stepper): chosen when planning, with losses or
    // lossless as the propagator is (set_damping chooses again), never by a step: like the
    // codelets of an FFTW plan.
    kernels::StepKernel step_kernel() const { return step_kernel_; }
    const PenaltyContact& contact() const { return contact_; }
    // The law at the obstacle (the case's contact.law), chosen once for the run: the penalty
    // (Stepper) or Newton's impact law with restitution e (NewtonImpact).
    ContactLawKind law() const { return law_; }
    double restitution() const { return restitution_; }
    // The second polarisation (y), planned only for a case with two: its exact per-mode
    // propagator and the friction law at the contacts (see SecondPolarisation).
    bool two_polarisations() const { return propagator_y_.has_value(); }
    const ModalPropagator& propagator_y() const { return *propagator_y_; }
    const Friction& friction() const { return friction_; }
    const std::vector<double>& obstacle() const { return obstacle_; }
    // The solve sees every obstacle below the string: where the case's obstacle is above, it
    // runs the mirror image u -> -u (orientation -1, else +1). What enters the solve from the
    // case (initial state, plucks, forces) or leaves it for the case (displacements, forces,
    // heights) passes through oriented(), its own inverse; a row of mode shapes through it
    // reads the case's displacement off the solve's state.
    double orientation() const { return orientation_; }
    double oriented(double u) const { return orientation_ * u; }
    std::vector<double> oriented(std::vector<double> v) const {
        for (double& x : v) x *= orientation_;
        return v;
    }
    void orient(std::span<double> v) const {
        for (double& x : v) x *= orientation_;
    }
    const PlanOptions& options() const { return options_; }
    std::size_t transform_threshold() const { return transform_threshold_; }
    // Points beyond which one sine transform is cheaper than rows of S, for N modes and a
    // transform FFTW plans at `transform_flops` operations.
    static std::size_t default_transform_threshold(std::size_t modes, double transform_flops);
    // The modal impulse (dt^2/mu) dx S^T f of forces per unit length f at grid points (i, f_i),
    // by rows of S or, for many points, one sine transform (grid: scratch of the grid's size).
    void forces_to_modes(std::span<const std::pair<std::size_t, double>> forces, std::span<double> grid,
                         std::span<double> impulse) const;
    // dt^2 / mu: the factor from force per length to displacement in one step.
    double force_to_displacement() const { return dt_ * dt_ / mu_; }
    // (dt^2/mu) dx: a force per unit length f at grid point i gives the modal impulse
    // impulse_scale() f S_i (S_i: row i of S).
    double impulse_scale() const { return force_to_displacement() * basis_.grid_step(); }
    // Up to this many forces, the step adds their rows itself (no impulse vector to fill).
    static constexpr std::size_t kMaxInlinePushes = kernels::kMaxPassRows;
    // True if `forces` forces are applied by rows inside the step rather than through
    // forces_to_modes (which uses a transform above transform_threshold()).
    bool pushes_inline(std::size_t forces) const {
        return forces >= 1 && forces <= kMaxInlinePushes && forces <= transform_threshold_;
    }
    // grid[i] = sum_j S_ij p_j at each of `points` (row products, kernels::kMaxRowsPerPass rows
    // per pass): p = `predicted`, or, if it is empty, the free prediction of (q, d) formed on
    // the fly (kernels::predict's, not stored).
    void predicted_at(std::span<const std::size_t> points, std::span<const double> predicted,
                      std::span<const double> q, std::span<const double> d, std::span<double> grid) const;
    // What planning found doubtful but allowed (modes above fs/2, see SamplingCheck).
    const std::vector<std::string>& warnings() const { return warnings_; }
    // Point obstacles at their exact positions, off the grid (those on a grid point, with the
    // grid step as their width, are grid obstacle points: the scalar solve, screening and all).
    const PointContact& point_contact() const { return point_contact_; }
    // Grid points where an obstacle exists at all (g > -inf).
    const std::vector<std::size_t>& obstacle_points() const { return obstacle_points_; }
    // What the contact screening watches (ContactScheduler): grid points i < N, then the exact
    // points p as N + p; each one's row of mode shapes (a grid row not kept by the basis goes
    // to `scratch`) and obstacle height in the solve's coordinate.
    std::size_t screened_points() const { return mode_count() + point_contact_.size(); }
    std::span<const double> screened_row(std::size_t i) const {
        return i < mode_count() ? basis_.row(i) : point_contact_.row(i - mode_count());
    }
    std::span<const double> screened_row(std::size_t i, std::span<double> scratch) const {
        return i < mode_count() ? basis_.row(i, scratch) : point_contact_.row(i - mode_count());
    }
    double screened_height(std::size_t i) const {
        return i < mode_count() ? obstacle_[i] : point_contact_.height(i - mode_count());
    }
    // The fingers of the case (they press toward the obstacle side, see Finger).
    const std::vector<FingerSpec>& fingers() const { return fingers_; }
    // Prescribed forces on the string (force gestures).
    const std::vector<ForceSpec>& forces() const { return forces_; }
    // Plucks and pops (pluckers on prescribed paths).
    const std::vector<PluckSpec>& plucks() const { return plucks_; }

    // Changes while a string sounds (a real-time instrument's controls). Neither allocates;
    // a Stepper on this plan must be told with Stepper::restart() before its next step.
    void set_contact_law(double stiffness, double exponent) { contact_.set(stiffness, exponent); }
    void set_damping(std::span<const double> sigma_per_s);
    // Raises the whole obstacle by `offset` metres above its planned height (toward the string:
    // more buzz), in the contact solve's coordinate, but no point above the string's rest line
    // (0): an obstacle raised into the string at rest would push it away with all the energy
    // of the penetration. Points planned above the line stay where they are.
    void set_obstacle_offset(double offset);
    // Makes every row of S the contact solve may read, so that stepping never allocates.
    void prepare_rows() const;

private:
    void place_points(const Case& c);  // the case's exact points: onto the grid, or into point_contact_

    double dt_;
    double orientation_;
    double mu_;
    double energy_scale_, loss_scale_;
    ModalBasis basis_;
    ModalPropagator propagator_;
    kernels::StepKernel step_kernel_;
    PenaltyContact contact_;
    ContactLawKind law_;
    double restitution_;
    std::optional<ModalPropagator> propagator_y_;
    Friction friction_;
    std::vector<double> obstacle_;
    std::vector<double> planned_obstacle_;  // obstacle_ at zero offset
    std::vector<std::size_t> obstacle_points_;
    PointContact point_contact_;
    std::vector<FingerSpec> fingers_;
    std::vector<ForceSpec> forces_;
    std::vector<PluckSpec> plucks_;
    PlanOptions options_;
    std::size_t transform_threshold_;
    std::vector<std::string> warnings_;
};

}  // namespace fretbuzz
