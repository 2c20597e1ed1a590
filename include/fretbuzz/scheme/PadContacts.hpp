#pragma once
// The played parts' pads on the grid as a step solves them: each part's pad predictions (the
// step's loads on them), its own solve, or (the route's fingers_joint) its place in the exact
// points' joint solve, whose solution its step then takes; a part that left the string hands
// its pad points back to the obstacle's solve. Its lists are reserved once for any pad, even
// one moved at run time.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/scheme/ContactForces.hpp"
#include "fretbuzz/scheme/ExactPluckers.hpp"
#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/FreePrediction.hpp"
#include "fretbuzz/scheme/GridContact.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"
#include "fretbuzz/scheme/StepRoute.hpp"

namespace fretbuzz {

class FingerPads;

class PadContacts {
public:
    explicit PadContacts(const Plan& plan);

    // Step n of every part on the string but the exact pluckers (their own solve): the fingers
    // joining the joint solve prepared and gathered (joint()), the others solved, their forces
    // into `forces`; a part that left retired (its pad's predictions formed for the grid's solve).
    void solve(PlayedParts& parts, const ExactPluckers& pluckers, const StepRoute& route, FreePrediction& prediction,
               GridContact& grid, ContactForces::List& forces, const ModalState& modes, const ForceGestures& gestures,
               long n, StepRecord& record);
    // The fingers gathered by solve() as the joint solve sees them, and their steps moved on with
    // its solution (`force`: each pad point's, in their order).
    FingerPads joint(PlayedParts& parts);
    void take_joint(const FingerPads& fingers, std::span<const double> force, GridContact& grid,
                    ContactForces::List& forces, StepRecord& record);
    // A part starting from the string as it is (u^{n-1}, u^n on the grid, read at its pad).
    void start(PlayedPart& part, std::span<const double> u_before, std::span<const double> u_now);

private:
    // A part's step taken: its Psi, its iterations, its non-zero forces.
    static void take(const PlayedPart& part, double obstacle_psi, std::span<const double> force, GridContact& grid,
                     ContactForces::List& forces, StepRecord& record);
    // The part has left the string (a plucker gone): its pad points go back to the obstacle's own
    // solve (the loop over active points that follows solves them in this same step).
    void retire(PlayedParts& parts, const PlayedPart& part, GridContact& grid) const;
    void pad_values(const std::vector<std::size_t>& pad, std::span<const double> field);

    const Plan* plan_;
    std::vector<double> pad_w_, pad_f_;  // scratch: predictions and forces at one pad
    // The fingers solved with the exact points: their pads' grid points, one after the other, and
    // their predictions; scratch for a trial's.
    std::vector<std::size_t> joint_pads_;
    std::vector<double> joint_w_, joint_trial_;
};

}  // namespace fretbuzz
