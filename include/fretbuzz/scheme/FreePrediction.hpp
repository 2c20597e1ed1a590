#pragma once
// The free step's prediction (q^{n+1} without contact force) at the grid points a step solves:
// by one transform where they are many, else from the forecast the last step's pass formed
// while it held that state, and row products for the points it did not forecast. It asks the
// pass for the next step's forecasts (the awake exact points' first, then the grid's active
// points and pads, as the route says) and keeps them. Whatever else changes the state (a
// restart, a flight) forgets them: without them a string resting on a bridge or held by a
// finger would make a pass more per step.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/numerics/CacheAligned.hpp"
#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/ExactPoints.hpp"
#include "fretbuzz/scheme/GridContact.hpp"
#include "fretbuzz/scheme/ModalState.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"
#include "fretbuzz/scheme/StepRoute.hpp"

namespace fretbuzz {

class FreePrediction {
public:
    explicit FreePrediction(const Plan& plan);

    // A field on the grid: the predictions at the points solved (scratch elsewhere: its values
    // are formed before they are read).
    std::span<double> field() { return field_; }
    AlignedVector& modal() { return predicted_; }  // scratch: q^{n+1} without contact force

    // The prediction at `points` into field(): the forecast where it has them, row products otherwise.
    void at(std::span<const std::size_t> points, const ModalState& modes);
    // At every grid point, by one transform.
    void everywhere(const ModalState& modes) {
        modes.predict(predicted_);
        plan_->basis().to_grid(predicted_, field_);
    }

    // The next step's forecasts the route asks of `pass`.
    void ask(kernels::StepPass& pass, const StepRoute& route, const ExactPoints& points, const GridContact& grid,
             const PlayedParts& parts);
    // After the pass into step `next`: the awake exact points' forecasts to them, the rest kept here.
    void keep(ExactPoints& points, long next) {
        const std::size_t awake = rows_.awake;
        if (awake != 0) points.keep_forecast(rows_.which.data(), rows_.values.data(), awake, next);
        for (std::size_t r = 0; r < forecast_.count; ++r) forecast_.values[r] = rows_.values[awake + r];
    }
    void forget() { forecast_.count = 0; }

private:
    const Plan* plan_;
    std::vector<double> field_;
    AlignedVector predicted_;
    // The next step's free prediction at the grid points solved now (active, pads).
    struct Forecast {
        std::size_t count = 0;
        std::array<std::size_t, kernels::kMaxPassRows> points{};
        std::array<double, kernels::kMaxPassRows> values{};
    };
    Forecast forecast_;
    std::vector<std::size_t> others_;  // scratch: points at() finds no forecast for
    // The pass's rows (not zeroed each step: only the first entries are read). The awake exact
    // points' come first (`awake` of them, which[]), then the grid's.
    struct Rows {
        std::array<const double*, kernels::kMaxPassRows> predict;
        std::array<std::size_t, kernels::kMaxPassRows> which;
        std::array<double, kernels::kMaxPassRows> values;
        std::size_t awake = 0;
    };
    Rows rows_{};
};

}  // namespace fretbuzz
