#include "fretbuzz/scheme/FreePrediction.hpp"

#include <algorithm>

namespace fretbuzz {

FreePrediction::FreePrediction(const Plan& plan)
    : plan_(&plan), field_(plan.mode_count(), 0.0), predicted_(plan.mode_count(), 0.0) {
    others_.reserve(plan.mode_count());  // (a running string never allocates)
}

void FreePrediction::at(std::span<const std::size_t> points, const ModalState& modes) {
    // The last step's pass formed the prediction at the points it was given: most often these
    // very points, in this order (a string resting on a point or a bridge).
    const Forecast& f = forecast_;
    if (points.size() == f.count && std::equal(points.begin(), points.end(), f.points.begin())) {
        for (std::size_t r = 0; r < points.size(); ++r) field_[points[r]] = f.values[r];
        return;
    }
    // The others (woken since, or no forecast): row products, the prediction formed on the fly
    // for a few, stored first for many (then read by each pass of rows).
    others_.clear();
    for (std::size_t i : points) {
        std::size_t r = 0;
        while (r < f.count && f.points[r] != i) ++r;
        if (r < f.count)
            field_[i] = f.values[r];
        else
            others_.push_back(i);
    }
    if (others_.empty()) return;
    if (others_.size() <= kernels::kMaxRowsPerPass) {
        plan_->predicted_at(others_, {}, modes.q(), modes.d(), field_);
        return;
    }
    modes.predict(predicted_);
    plan_->predicted_at(others_, predicted_, modes.q(), modes.d(), field_);
}

void FreePrediction::ask(kernels::StepPass& pass, const StepRoute& route, const ExactPoints& points,
                         const GridContact& grid, const PlayedParts& parts) {
    // The awake exact points' forecasts, then the grid's active points and pads.
    std::size_t count = route.forecast_points ? points.awake_rows(rows_.which.data(), rows_.predict.data()) : 0;
    rows_.awake = count;
    forecast_.count = 0;
    if (route.forecast_grid) {
        const auto add = [&](std::size_t i) {
            forecast_.points[forecast_.count++] = i;
            rows_.predict[count++] = plan_->basis().row(i).data();
        };
        for (std::size_t i : grid.active()) add(i);
        parts.each_on([&](const PlayedPart& part) {
            for (std::size_t i : part.pad()) add(i);
        });
    }
    pass.predict_rows = rows_.predict.data();
    pass.predict_count = count;
    pass.predicted = rows_.values.data();
}

}  // namespace fretbuzz
