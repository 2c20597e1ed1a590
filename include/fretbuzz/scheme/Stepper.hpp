#pragma once
// Advances the string one time step with the scheme of Issanchou et al. 2017 (eq. 4),
// in modal coordinates:
//     q^{n+1} = C q^n - C~ q^{n-1} + (dt^2/mu) dx S^T f^n,
// where f^n_i = (Psi(eta_i^{n+1}) - Psi(eta_i^{n-1})) / (eta_i^{n+1} - eta_i^{n-1}) is found by a
// scalar solve at each grid point that can touch (ContactScheduler says which). It also keeps
// the discrete energy H^{n+1/2} and the energy dissipated by damping, every step, so that
// H + dissipated is constant to round-off. Fingers (see Finger) and pluckers (Pluck) are
// advanced with the string: their pad points are solved every step (a plucker's until it has
// left). Force gestures (ForceProfile) load the modes at their exact positions, explicitly,
// the contacts of the step being solved with their load. The balance becomes
// H - work + dissipated = constant (work: done by the pressing forces, the gestures and the
// pluckers' motions). Nothing here does I/O.
#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fretbuzz/scheme/CacheAligned.hpp"

#include "fretbuzz/scheme/ContactScheduler.hpp"
#include "fretbuzz/scheme/Finger.hpp"
#include "fretbuzz/scheme/ForceProfile.hpp"
#include "fretbuzz/scheme/FreeFlight.hpp"
#include "fretbuzz/scheme/Kernels.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedPart.hpp"
#include "fretbuzz/scheme/Pluck.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"

namespace fretbuzz {

// The parts playing the string at pads of grid points (the case's fingers and pluckers, in that
// order) as one collection of PlayedPart, each with whether it is on the string (a finger
// lifted, a plucker gone: off). Finger f is part f. A copy links to its own parts.
class PlayedParts {
public:
    PlayedParts() = default;
    PlayedParts(std::vector<Finger> fingers, std::vector<Pluck> plucks);
    PlayedParts(const PlayedParts& other);
    PlayedParts(PlayedParts&& other) noexcept = default;  // (the parts stay where they are)
    PlayedParts& operator=(const PlayedParts&) = delete;
    PlayedParts& operator=(PlayedParts&&) = delete;

    std::size_t size() const { return parts_.size(); }
    bool empty() const { return parts_.empty(); }
    PlayedPart& operator[](std::size_t k) { return *parts_[k]; }
    const PlayedPart& operator[](std::size_t k) const { return *parts_[k]; }
    bool on(std::size_t k) const { return on_[k] != 0; }
    void set_on(std::size_t k, bool on) { on_[k] = on ? 1 : 0; }
    // f(part) for every part on the string.
    template <class F>
    void each_on(F&& f) {
        for (std::size_t k = 0; k < parts_.size(); ++k)
            if (on_[k] != 0) f(*parts_[k]);
    }
    template <class F>
    void each_on(F&& f) const {
        for (std::size_t k = 0; k < parts_.size(); ++k)
            if (on_[k] != 0) f(static_cast<const PlayedPart&>(*parts_[k]));
    }

    const std::vector<Finger>& fingers() const { return fingers_; }
    Finger& finger(std::size_t f) { return fingers_.at(f); }
    const std::vector<Pluck>& plucks() const { return plucks_; }

private:
    void link();

    std::vector<Finger> fingers_;
    std::vector<Pluck> plucks_;
    std::vector<PlayedPart*> parts_;
    std::vector<char> on_;
};

struct StepStatistics {
    long contact_steps = 0;            // steps with a non-zero obstacle contact force somewhere
    long played_steps = 0;             // steps where a finger, plucker or force gesture acted on the string
    int max_newton_iterations = 0;
    double points_solved = 0;          // sum over steps of the points solved
    long free_flight_steps = 0;        // steps jumped over by FreeFlight
    long joint_steps = 0;              // steps whose exact points and grid points were solved together
};

class Stepper {
public:
    // Starts at n = 0 from modal displacement q0 and velocity v0 (dq/dt).
    Stepper(const Plan& plan, std::span<const double> q0, std::span<const double> v0);

    // n -> n + 1. The first step is the exact free motion; the others are the scheme.
    void step();
    // Free flight over the next M = flight.steps() steps while no point can touch: only the
    // first `head` modes are stepped (the probes, mode shapes used up to `head`, are sampled
    // at every step into `u`, and `v` for velocities if not null: one row of probes.size()
    // values per step); the other modes jump in closed form at the end, and checks of
    // sleeping points use the head modes plus a bound on the rest. Stops early if a point
    // might touch (the state is then complete at that step). Returns the steps flown
    // (0 if a flight cannot start). Energy and dissipation stay exact. step_head: the head
    // modes step one by one even with no probe, as they would for probes (a caller that makes
    // the per-step signal elsewhere, from the flight's start, and wants the same steps, bit for
    // bit; otherwise a flight with no point due is one jump of every mode).
    long free_flight(const FreeFlight& flight, std::size_t head, std::span<const std::vector<double>> probes,
                     std::vector<double>& u, std::vector<double>* v, bool step_head = false);

    // Gives the string its second polarisation y (plan.two_polarisations() must hold), from
    // modal displacement and velocity at n = 0; before the first step. Without it the
    // stepper runs z alone, exactly as it always has.
    void add_second_polarisation(std::span<const double> q0, std::span<const double> v0);
    const SecondPolarisation* second_polarisation() const { return y_ ? &*y_ : nullptr; }

    // Adds a displacement and a velocity (modal, dq/dt) to the current state, as an external
    // impulse between two steps would: q^n += dq, q^{n-1} += dq - dv dt. The energy H^{n-1/2}
    // changes by the work done; the caller reads it with energy() before and after.
    void perturb(std::span<const double> displacement, std::span<const double> velocity);
    // Takes the state and the plan as they are now (after perturb, or after the plan's contact
    // law or damping changed): every obstacle point is looked at again and the contact energy
    // recomputed. Allocates nothing.
    void restart();
    // Puts the string at rest (q = d = 0), keeping the step count and the losses so far.
    void silence();
    // Fingers at run time (a real-time engine), after the first step; none allocates, and the
    // caller counts the energy each adds or removes (the finger's own, and the restart's).
    // lift_finger: finger f leaves the string at once (its motion and contact are forgotten,
    // its pad points go back to the obstacle's solve, it is no longer stepped).
    void lift_finger(std::size_t f);
    // place_finger: finger f (lifted first if it was on) lands at rest on the string with its
    // pad centred at centre_m (width at most its spec's). False, and the finger stays off, if
    // the pad would overlap another finger's or a plucker's (a force gesture claims no pad).
    bool place_finger(std::size_t f, double centre_m, double width_m);
    // press_finger: from this step on, its pressing force ramps to force_n over ramp_steps steps.
    void press_finger(std::size_t f, double force_n, long ramp_steps);
    bool finger_on(std::size_t f) const;  // (std::out_of_range for no finger f)

    long step_index() const { return n_; }
    double time() const { return static_cast<double>(n_) * plan_.dt(); }
    std::span<const double> modal_displacement() const { return q_; }  // q^n
    std::span<const double> modal_difference() const { return d_; }    // q^n - q^{n-1}
    // u(x, t_n) = phi(x) . q^n
    double displacement(std::span<const double> mode_shapes) const;
    // (u(x, t_n) - u(x, t_{n-1})) / dt
    double velocity(std::span<const double> mode_shapes) const;
    // An observation row (a pickup's mode shapes, kept by the caller, which may change its
    // values and then calls observe again): observation() is displacement(mode_shapes), formed
    // by the step's own pass over the modes (one pass fewer).
    void observe(std::span<const double> mode_shapes);
    double observation() const;
    // Rows read after free flights (an output row's probes and bridge, kept by the caller, which
    // calls observe_rows again after changing their values): out[r] = displacement(rows[r]),
    // formed by a flight's closing jump in its own pass over the modes when it can.
    void observe_rows(std::span<const double* const> rows);
    void row_displacements(std::span<double> out) const;
    // The caller reads energy() after every step that is a multiple of `steps` (its audit at
    // each output row; 0: no such promise): the pass that steps the modes into such a step
    // forms the modal energy too (one pass fewer at an audio rate).
    void audit_every(long steps) { audit_stride_ = steps; }

    // Energy terms of the interval (t_{n-1}, t_n), defined for n >= 1 (joules).
    double energy() const;          // H^{n-1/2}: string, obstacle contact and fingers
    double contact_energy() const;  // dx (Psi(eta^n) + Psi(eta^{n-1})) / 2
    // Losses since H^{1/2}: modal damping plus the fingers' contact losses (and with two
    // polarisations the y modes' damping and the friction).
    double dissipated() const { return y_ ? dissipated_ + finger_loss() + y_losses() : dissipated_ + finger_loss(); }
    double damping_dissipated() const { return dissipated_; }
    double finger_energy() const;  // kinetic and contact energy of the fingers
    double finger_loss() const;    // their contact losses so far (>= 0)
    double work() const;           // work of the external forces (pressing forces, gestures) so far
    const std::vector<Finger>& fingers() const { return parts_.fingers(); }
    // Whether fingers, gestures or pluckers act (the balance then counts their work).
    bool played() const { return !parts_.empty() || !gestures_.empty(); }
    const std::vector<Pluck>& plucks() const { return parts_.plucks(); }
    // Every part playing the string at a pad, fingers first, then pluckers (the case's order).
    const PlayedParts& played_parts() const { return parts_; }
    // The force gestures along z (the case's order).
    const std::vector<ForceProfile>& gestures() const { return gestures_; }

    // Whether the obstacle pushed on the string in the last step (forces() also holds the
    // fingers' and pluckers' forces at their pads, a plucker at its exact position at its
    // nearest grid point; a gesture's load is not a force there).
    bool touched_obstacle() const { return touched_obstacle_; }
    // Points with a non-zero force in the last step and that force (N/m).
    std::span<const std::pair<std::size_t, double>> forces() const { return forces_; }
    const StepStatistics& statistics() const { return stats_; }
    const ContactScheduler& scheduler() const { return scheduler_; }

private:
    double modal_energy() const;  // H^{n-1/2} without the contact part, cached per step
    double y_losses() const { return y_->damping_dissipated() + y_->friction_dissipated(); }
    void first_step();
    // Looks at every obstacle point for the state with u^n, u^{n-1} on the grid.
    void classify_points(std::span<const double> u_now, std::span<const double> u_before);
    void wake_due_points();
    // Exact point p, due (screened as point N + p): back to the solve, or asleep again.
    void wake_exact_point(std::size_t p, std::size_t head, double tail);
    void classify_exact_points();  // puts the exact points apart from the string to sleep
    void activate(std::size_t i, double u_now, double u_before);
    bool sleeps_on_low_modes(std::size_t i, std::size_t head, double tail);
    // The flight's closing jump of modes [first, N) after `flown` steps: the modal energy and the
    // observed rows' products of the state it leaves come from the same pass.
    void land(const FreeFlight& flight, std::size_t first, long flown);
    long end_flight(long flown, double energy_before);  // the bookkeeping after `flown` steps
    void keep_modal_energy(long step, double scaled) const;  // caches modal_energy() at `step`
    void solve_contacts();
    // Into grid_ at `points`: the forecast where it has them, row products otherwise.
    void predict_points(std::span<const std::size_t> points);
    void keep_observation();  // observed_ from the state as it is
    void landing_rows();      // the rows a flight's closing jump forms: flight_rows_, then the observed one
    void apply_impulse();
    // The exact point obstacles (Plan::point_contact): their step, their impulse with the grid's
    // forces, and their forces reported at their nearest grid points (forces()).
    bool solve_points();
    void predict_exact_points();  // point_predicted_: the free step's u at each exact point
    // The awake exact points (which) and their rows, in order, into room for kMaxPassRows; how many.
    std::size_t awake_rows(std::size_t* which, const double** rows) const;
    // The exact points with the grid's active points (solve_a_, solve_b_ formed): into solutions_.
    void solve_points_with_grid(bool with_pluck, bool with_fingers);  // (and the exact plucker's pad, if with_pluck)
    void apply_point_impulse();
    void report_point_forces();
    // A force (N) acting at x off the grid, in forces() as a force per length at the nearest grid point.
    void report_force_at(double x, double force);
    // Whether the step pushes with the points' rows (and the grid's) on the fly, in the pass that
    // also forms the next prediction at every point where the step is fused (else through
    // apply_point_impulse's vector).
    bool points_by_rows() const;
    void advance_with_points();
    // Runs the plan's step kernel on `pass`, adding (fused) the observation and, where audited, the
    // energy of the state it leaves; counts its losses.
    void run_pass(kernels::StepPass& pass);
    void advance_modes();
    void put_points_to_sleep();
    // use_transform: the predictions are in grid_ already. with_points: the fingers are solved
    // with the exact points (solve_points_with_grid): their pads' predictions only, and prepare().
    void solve_fingers(bool use_transform, bool with_points);
    bool fingers_on() const;
    // A part's step done (its obstacle potential and its forces on the pad): into the step's sums.
    void take_part(const PlayedPart& part, double obstacle_psi, std::span<const double> force);
    // The gestures' loads of step n_ (gesture_load_, loaded_), and each one's prediction shift
    // at grid point i / exact point p.
    void load_gestures();
    double gestures_at_grid(std::size_t i) const;
    double gestures_at_point(std::size_t p) const;
    bool gestures_act_from(long n) const;
    void advance_loaded();  // advance_modes with the gestures' loads in impulse_, and their work
    // The pluckers at their exact positions (every plucker of a case with at most
    // PointContact::kMaxPads): each one's solve from its pad's mean free prediction, its force a
    // load on the modes as a gesture's. Plucker j is part first_pluck_ + j.
    bool exact_pluck_on(std::size_t j) const { return j < exact_plucks_ && parts_.on(first_pluck_ + j); }
    bool any_exact_pluck_on() const;
    bool is_exact_pluck(std::size_t part) const { return part >= first_pluck_ && part < first_pluck_ + exact_plucks_; }
    Pluck& exact_pluck(std::size_t j) { return static_cast<Pluck&>(parts_[first_pluck_ + j]); }
    void start_exact_pluck(std::size_t j, double u_before, double u_now);
    // Gathers the exact pluckers on the string now into acting_plucks_ (off for good once one has
    // left); whether there are any.
    bool exact_plucks_act();
    double exact_pluck_prediction(std::size_t j) const;
    void take_pluck_force(std::size_t j, double force);
    void solve_exact_pluck_alone();  // the one acting plucker, nothing beside it
    // The acting pluckers as PointContact's pads, each prepared for this step (with_grid: their
    // couplings to the grid points too); then each one's solution taken.
    std::span<PointContact::Pad> exact_pads(bool with_grid);
    void conclude_exact_pads();
    std::span<const std::pair<std::size_t, double>> rubbing_points();
    void claim_pad(const std::vector<std::size_t>& pad, const std::string& key);
    void retire(const PlayedPart& part);
    void pad_values(const std::vector<std::size_t>& pad, std::span<const double> field);
    // Starts a played part from the string under its pad at two levels (n-1 and n).
    void start_part(PlayedPart& part, std::span<const double> u_before, std::span<const double> u_now);

    const Plan& plan_;
    ContactScheduler scheduler_;
    const bool screening_;
    long n_ = 0;
    AlignedVector q_, d_;            // q^n and q^n - q^{n-1}
    std::vector<double> v0_;               // initial modal velocity (first step only)
    AlignedVector predicted_;        // q^{n+1} without contact force
    AlignedVector impulse_;          // contact contribution to q^{n+1}
    std::vector<double> grid_;             // scratch: a field on the grid
    std::vector<double> eta_prev_, eta_curr_;  // eta^{n-1}, eta^n at active points
    std::vector<std::size_t> active_;      // points solved every step
    // Many active points are solved together (PenaltyContact::solve_all): their equations' a and b.
    std::vector<double> solve_a_, solve_b_;
    std::vector<ContactSolution> solutions_;
    std::vector<std::size_t> due_;         // scratch: sleeping points to check now
    std::vector<std::pair<std::size_t, double>> forces_;
    std::vector<std::pair<std::size_t, double>> pushes_;  // scratch: forces_ and the exact points' (as N + p)
    PlayedParts parts_;
    std::vector<ForceProfile> gestures_;
    std::vector<double> gesture_load_;       // f^n of each gesture in the step being taken
    std::vector<double> gesture_at_points_;  // s_g . phi(x_p), gesture by gesture, point by point
    bool loaded_ = false;                    // a gesture or the exact plucker loads the step being taken
    std::size_t first_pluck_ = 0, exact_plucks_ = 0;  // the exact pluckers' parts
    std::vector<double> pluck_load_;         // each exact plucker's force on the string in this step (N)
    std::vector<double> gesture_at_pluck_;   // s_g . s_j, gesture by gesture, plucker by plucker
    std::vector<double> pluck_at_points_;    // s_j . phi(x_p), plucker by plucker, point by point
    std::vector<double> pluck_at_grid_;      // s_j . S_i, plucker by plucker (beside an obstacle or a finger on the grid)
    std::vector<double> pluck_cross_;        // s_j . s_b, plucker by plucker
    std::vector<std::size_t> acting_plucks_; // scratch: the exact pluckers on the string in this step
    std::vector<PointContact::Pad> pads_;    // scratch: them as PointContact's pads
    std::vector<double> pad_cross_;          // scratch: their s_a . s_b, pad by pad
    std::vector<char> on_pad_;             // grid points under a finger: solved with it, never asleep
    std::size_t pad_points_ = 0;
    std::vector<double> pad_w_, pad_f_;    // scratch: predictions and forces at one pad
    // The fingers solved with the exact points: their pads' grid points, one after the other, and
    // their predictions; scratch for a trial's.
    std::vector<std::size_t> joint_pads_;
    std::vector<double> joint_w_, joint_trial_;
    std::vector<std::pair<std::size_t, double>> rubbing_;  // scratch: where friction acts, F_n
    double psi_curr_ = 0.0, psi_prev_ = 0.0;  // sum_i Psi(eta_i^n), sum_i Psi(eta_i^{n-1})
    PointContact::State points_;            // the exact point obstacles' state
    std::vector<double> point_predicted_;   // scratch: u at each point after a free step
    bool points_pushed_ = false;            // a point pushed in the step being taken
    std::vector<double> point_forecast_;    // the free prediction at each point, formed by the last step
    long point_forecast_step_ = -1;         // the step it belongs to
    double dissipated_ = 0.0;
    bool touched_obstacle_ = false;
    long next_speed_refresh_ = 0;
    // The modal energy of step energy_step_, formed by the pass into an audited step (audit_every)
    // or a flight's closing jump, else by modal_energy() when asked. Kept because it pays: without
    // it, a run stepping at an audio rate makes a pass more per step (the sitar bridge at 48 kHz,
    // fretbuzz_bench --contact: 13 % slower).
    mutable long energy_step_ = -1;
    mutable double modal_energy_ = 0.0;
    StepStatistics stats_;
    // The next step's free prediction at the points solved now (active, pads), formed by
    // advance_modes while it holds q^{n+1}; the next solve_contacts reads it. Whatever else
    // changes the state (restart, a flight) empties it. Without it, a string resting on a
    // bridge or held by a finger makes a pass more per step (fretbuzz_bench: the fretted pop
    // 9 % slower, the bass pop's contact window 5.5 %, the sitar bridge 4.7 %).
    struct Forecast {
        std::size_t count = 0;
        std::array<std::size_t, kernels::kMaxPassRows> points{};
        std::array<double, kernels::kMaxPassRows> values{};
    };
    Forecast forecast_;
    std::vector<std::size_t> others_;       // scratch: points predict_points finds no forecast for
    const double* observed_row_ = nullptr;  // observe(): one row, or none
    double observed_ = 0.0;                 // its displacement in the current state (fused_step)
    std::vector<const double*> flight_rows_;    // observe_rows()
    std::vector<const double*> landing_rows_;   // flight_rows_, then observed_row_ if any
    // Their products, formed by the closing jump of the flight that ended at step
    // flight_rows_step_. Kept because it pays: without it, every output row after a flight takes
    // a pass of its own (fretbuzz_bench: Outputs/bass-pop-3s 16 % slower, Fast/bass-pop 6 %).
    std::vector<double> landing_values_;
    long flight_rows_step_ = -1;
    long audit_stride_ = 0;                   // audit_every()
    std::optional<SecondPolarisation> y_;  // empty with one polarisation (a stepper stays copyable)
};

}  // namespace fretbuzz
