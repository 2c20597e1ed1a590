#pragma once
// Every contact of one string, and the step's joint solve of them: the obstacle's points on the
// grid (GridContact), the point obstacles at their exact positions (ExactPoints), and the played
// parts at pads (PlayedParts: fingers on grid points, pluckers at their exact positions,
// ExactPluckers). Each step it decides once, as a value (StepRoute), which solve applies (each
// point alone, the points together, or everything coupled through the modes in one Newton solve
// with the grid's own equations eliminated: PointContact) and how the pushes reach the modes
// (their rows in the pass, or one impulse vector); the pass and the screening follow that route.
// It forms the forecasts the next step reads, and reports its forces.
#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fretbuzz/scheme/ExactPluckers.hpp"
#include "fretbuzz/scheme/ExactPoints.hpp"
#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/GridContact.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/Screening.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"
#include "fretbuzz/scheme/StepRoute.hpp"

namespace fretbuzz {

class ContactSet {
public:
    ContactSet(const Plan& plan, const ForceGestures& gestures);

    PlayedParts& parts() { return parts_; }
    const PlayedParts& parts() const { return parts_; }
    const ExactPluckers& pluckers() const { return pluckers_; }
    GridContact& grid() { return grid_; }
    ExactPoints& points() { return points_; }
    const ExactPoints& points() const { return points_; }

    // n = 0 -> 1: the modes take their exact free step; every contact starts from levels 0 and 1.
    void first_step(ModalState& modes, Screening& screening);
    // Everything looked at again for the state as it is (after it or the plan changed); the
    // string's u^n and u^{n-1} are then in field() and previous() where they were read.
    void restart(const ModalState& modes, Screening& screening, long n);
    std::span<const double> field() const { return field_; }
    std::span<const double> previous() const { return impulse_; }
    std::span<double> field_scratch() { return field_; }  // (its values are formed before they are read)
    void forget_forecasts();  // the state changed from outside

    // Step n's contacts solved from the free prediction of `modes`, shifted by the gestures' loads
    // where record.loaded; the step's route decided.
    void solve(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);
    // The step's pushes (the impulse vector formed where the route says, the gestures' loads with
    // it) and the next step's forecasts into `pass`; keep_forecasts after it ran.
    void fill_pass(kernels::StepPass& pass, const ForceGestures& gestures);
    void keep_forecasts(long next) {  // (here: every step runs it)
        const std::size_t awake = rows_.awake;
        if (awake != 0) points_.keep_forecast(rows_.which.data(), rows_.values.data(), awake, next);
        for (std::size_t r = 0; r < forecast_.count; ++r) forecast_.values[r] = rows_.values[awake + r];
    }
    // After the pass: the screening told of the pushes (the motion is a new free motion), points
    // apart put to sleep; the forces reported.
    void tell_screening(Screening& screening, const ModalState& modes, long next);
    void report_forces() {  // the forces off the grid added to forces()
        if (points_.pushed() || pluckers_.size() != 0) report_off_grid();  // (most steps: nothing off the grid)
    }
    void forget_forces() {
        forces_.clear();
        forecast_.count = 0;
    }

    // No contact can act: nothing awake, no pad held, no contact energy (a flight may start).
    bool quiet() const;
    // Nothing can ever touch the string: no obstacle point, no exact point, no played part.
    bool none() const {
        return parts_.empty() && plan_->obstacle_points().empty() && plan_->point_contact().size() == 0;
    }
    // dx (Psi^n + Psi^{n-1}) / 2 of the grid's obstacle points, plus the exact points'.
    double energy() const;
    // Points with a non-zero force in the last step and that force (N/m).
    std::span<const std::pair<std::size_t, double>> forces() const { return forces_; }
    std::span<const double> point_forces() const;  // the exact points' (empty where none pushed)
    // Where friction along y acts, with the normal force per unit length there.
    std::span<const std::pair<std::size_t, double>> rubbing_points();

    // Fingers at run time (see Stepper); place_finger needs restart() between it and land().
    bool lift_finger(std::size_t f);
    bool place_finger(std::size_t f, double centre_m, double width_m);
    void land(std::size_t f);

private:
    // The free prediction at `points` into field_: the forecast where it has them, row products otherwise.
    void predict_points(std::span<const std::size_t> points, const ModalState& modes);
    // The route's solve part, from the state at the top of the step (pluckers: some act).
    StepRoute route_of(bool pluckers) const;
    // The route's pushes and forecasts, from the solve's forces.
    void route_pushes(bool loaded);
    void solve_on_grid(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);
    void solve_fingers(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);
    void take_part(const PlayedPart& part, double obstacle_psi, std::span<const double> force, StepRecord& record);
    void retire(const PlayedPart& part);
    void start_part(PlayedPart& part, std::span<const double> u_before, std::span<const double> u_now);
    void pad_values(const std::vector<std::size_t>& pad, std::span<const double> field);
    // The exact points (and the acting pluckers' pads) solved apart from the grid; whether any pushed.
    bool solve_points(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);
    // The exact points, the acting pluckers and (route_.fingers_joint) the fingers with the grid's
    // active points (their equations gathered), all in one solve.
    void solve_with_grid(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);
    // The step's impulse vector: the grid's forces and the points' (where they pushed).
    void form_impulse();
    // A force (N) at x off the grid, reported as a force per length at the nearest grid point.
    void report_force_at(double x, double force);
    void report_off_grid();

    const Plan* plan_;
    PlayedParts parts_;
    ExactPluckers pluckers_;
    GridContact grid_;
    ExactPoints points_;
    AlignedVector predicted_;  // scratch: q^{n+1} without contact force
    AlignedVector impulse_;    // the step's modal impulse where it is one vector (scratch in a restart)
    std::vector<double> field_;  // scratch: a field on the grid (predictions at the points solved)
    std::vector<std::pair<std::size_t, double>> forces_;
    std::vector<std::pair<std::size_t, double>> pushes_;  // scratch: forces_ and the exact points' (as N + p)
    std::vector<std::pair<std::size_t, double>> rubbing_;  // scratch: where friction acts, F_n
    std::vector<double> pad_w_, pad_f_;  // scratch: predictions and forces at one pad
    // The fingers solved with the exact points: their pads' grid points, one after the other, and
    // their predictions; scratch for a trial's.
    std::vector<std::size_t> joint_pads_;
    std::vector<double> joint_w_, joint_trial_;
    // The next step's free prediction at the points solved now (active, pads), formed by the
    // pass while it holds q^{n+1}; the next solve reads it. Whatever else changes the state (a
    // restart, a flight) empties it. Without it a string resting on a bridge or held by a finger
    // would make a pass more per step.
    struct Forecast {
        std::size_t count = 0;
        std::array<std::size_t, kernels::kMaxPassRows> points{};
        std::array<double, kernels::kMaxPassRows> values{};
    };
    Forecast forecast_;
    std::vector<std::size_t> others_;  // scratch: points predict_points finds no forecast for
    // The pass's rows (not zeroed each step: only the first entries are read). The awake exact
    // points' forecasts come first (`awake` of them, which[]), then the grid's.
    struct PassRows {
        std::array<double, kernels::kMaxPassRows> coefficients;
        std::array<const double*, kernels::kMaxPassRows> push, predict;
        std::array<std::size_t, kernels::kMaxPassRows> which;
        std::array<double, kernels::kMaxPassRows> values;
        std::size_t awake = 0;
    };
    PassRows rows_{};
    StepRoute route_{};
};

}  // namespace fretbuzz
