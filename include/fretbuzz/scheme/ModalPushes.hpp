#pragma once
// The step's pushes on the modes, as the step's route says they reach them (StepRoute::Push):
// the forces' rows added by the pass (the exact points' first where they pushed), or one modal
// impulse vector formed before it (many forces; the gestures' and pluckers' loads with them);
// and the same pushes told to the screening as the pass took them, so that its bounds grow by
// what moved the modes.
#include <array>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/numerics/CacheAligned.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/ContactScheduler.hpp"
#include "fretbuzz/scheme/ExactPluckers.hpp"
#include "fretbuzz/scheme/ExactPoints.hpp"
#include "fretbuzz/scheme/ForceGestures.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/StepRoute.hpp"

namespace fretbuzz {

class ModalPushes {
public:
    using Forces = std::span<const std::pair<std::size_t, double>>;

    explicit ModalPushes(const Plan& plan);

    // The impulse vector; scratch of the modes' size between its steps (a restart's u^{n-1}).
    std::span<double> impulse() { return impulse_; }

    // The step's pushes (`forces` on the grid, the points' where they pushed) into `pass`, by
    // `push`; grid: scratch of the grid's size.
    void fill(kernels::StepPass& pass, StepRoute::Push push, Forces forces, std::span<double> grid,
              const ExactPoints& points, const ForceGestures& gestures, const ExactPluckers& pluckers,
              PlayedParts& parts);
    // The scheduler told of the pushes the pass took (the motion from here on is a new free motion).
    void tell(ContactScheduler& scheduler, StepRoute::Push push, const ModalState& modes, Forces forces,
              const ExactPoints& points);

private:
    // The grid's forces and the points' (where they pushed) as one modal impulse.
    void form(Forces forces, std::span<double> grid, const ExactPoints& points);

    const Plan* plan_;
    AlignedVector impulse_;
    // The pass's rows (not zeroed each step: only the first entries are read).
    std::array<double, kernels::kMaxPassRows> coefficients_{};
    std::array<const double*, kernels::kMaxPassRows> rows_{};
    std::vector<std::pair<std::size_t, double>> screened_;  // scratch: the grid's pushes and the exact points' (as N + p)
};

}  // namespace fretbuzz
