#pragma once
// Every contact of one string, and the step's joint solve of them: the obstacle's points on the
// grid (GridContact), the point obstacles at their exact positions (ExactPoints), and the played
// parts at pads (PlayedParts: fingers on grid points, solved by PadContacts; pluckers at their
// exact positions, ExactPluckers). Each step it decides once, as a value (StepRoute), which
// solve applies (each point alone, the points together, or everything coupled through the modes
// in one Newton solve with the grid's own equations eliminated: PointContact) and how the pushes
// reach the modes; the parts after the solve read that route: the free prediction and its
// forecasts (FreePrediction), the pushes in the pass and to the screening (ModalPushes), the
// forces reported (ContactForces).
#include <cstddef>
#include <span>
#include <utility>

#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/ContactForces.hpp"
#include "fretbuzz/scheme/ExactPluckers.hpp"
#include "fretbuzz/scheme/ExactPoints.hpp"
#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/FreePrediction.hpp"
#include "fretbuzz/scheme/GridContact.hpp"
#include "fretbuzz/scheme/ModalPushes.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/PadContacts.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/Screening.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"
#include "fretbuzz/scheme/StepRoute.hpp"

namespace fretbuzz {

class SecondPolarisation;

class ContactSet {
public:
    ContactSet(const Plan& plan, const ForceGestures& gestures);

    PlayedParts& parts() { return parts_; }
    const PlayedParts& parts() const { return parts_; }

    // n = 0 -> 1: the modes take their exact free step; every contact starts from levels 0 and 1.
    void first_step(ModalState& modes, Screening& screening);
    // What the passes formed forgotten; past the first step, everything looked at again for the
    // state as it is (after it or the plan changed).
    void restart(const ModalState& modes, Screening& screening, long n);
    // The points the screening finds due woken (begin of a step).
    void wake_due(Screening& screening, const ModalState& modes) {
        screening.wake_due(modes, grid_, points_, prediction_.field());
    }

    // Step n's contacts solved from the free prediction of `modes`, shifted by the gestures' loads
    // where record.loaded; the step's route decided.
    void solve(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);
    // The step's pushes and the forecasts the route asks for into `pass` (end_step keeps them).
    void fill_pass(kernels::StepPass& pass, const ForceGestures& gestures);
    // Friction along y from this step's normal forces (the grid's, the pads' and the exact points').
    void step_friction(SecondPolarisation& y, long n);
    // After the pass into step `next`: the forecasts it formed kept, the screening told of the
    // pushes (the motion is a new free motion), points apart put to sleep; the forces off the
    // grid reported.
    void end_step(Screening& screening, const ModalState& modes, long next);
    void forget_forces() {  // (and the forecasts, formed for points now asleep, before a flight)
        forces_.list().clear();
        prediction_.forget();
    }

    // No contact can act: nothing awake, no pad held, no contact energy (a flight may start).
    bool quiet() const {
        return parts_.pad_points() == 0 && !pluckers_.any_on(parts_) && points_.awake() == 0 && grid_.active().empty() &&
               grid_.at_rest();
    }
    // Nothing can ever touch the string: no obstacle point, no exact point, no played part.
    bool none() const {
        return parts_.empty() && plan_->obstacle_points().empty() && plan_->point_contact().size() == 0;
    }
    // dx (Psi^n + Psi^{n-1}) / 2 of the grid's obstacle points, plus the exact points'.
    double energy() const { return grid_.energy(plan_->basis().grid_step()) + points_.energy(plan_->contact()); }
    // Points with a non-zero force in the last step and that force (N/m).
    std::span<const std::pair<std::size_t, double>> forces() const { return forces_.list(); }

    // Fingers at run time (see Stepper); place_finger needs restart() between it and land().
    bool lift_finger(std::size_t f);
    bool place_finger(std::size_t f, double centre_m, double width_m);
    void land(std::size_t f);

private:
    // The grid's active points and the fingers' pads, by the route (with the exact points where it joins them).
    void solve_on_grid(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);
    // The exact points and the acting pluckers' pads, apart from the grid or (OffGrid::with_grid)
    // with its active points and (fingers_joint) the fingers' pads, in one solve.
    void solve_exact(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record);

    const Plan* plan_;
    PlayedParts parts_;
    ExactPluckers pluckers_;
    GridContact grid_;
    ExactPoints points_;
    FreePrediction prediction_;
    PadContacts pads_;
    ContactForces forces_;
    ModalPushes pushes_;  // (its impulse is a restart's scratch for u^{n-1}, which land() reads)
    StepRoute route_{};
};

}  // namespace fretbuzz
