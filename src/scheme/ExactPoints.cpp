#include "fretbuzz/scheme/ExactPoints.hpp"

#include <algorithm>
#include <array>

namespace fretbuzz {

ExactPoints::ExactPoints(const Plan& plan)
    : contact_(&plan.point_contact()),
      state_(plan.point_contact().make_state(plan.plucks().size())),
      predicted_(plan.point_contact().size(), 0.0),
      forecast_(plan.point_contact().size(), 0.0) {}

void ExactPoints::wake(std::size_t p, const ModalState& modes) {
    contact_->wake(state_, p, modes.q(), modes.d());
    forecast_step_ = -1;  // (formed for the points awake then)
}

void ExactPoints::put_to_sleep(ContactScheduler& scheduler, const ModalState& modes, bool refresh) {
    if (state_.awake == 0) return;
    const std::size_t n = modes.size();
    for (std::size_t p = 0; p < contact_->size(); ++p)
        if (state_.resting[p] == 0 && state_.eta_curr[p] <= 0.0 && state_.eta_prev[p] <= 0.0) {
            if (refresh) scheduler.refresh(modes.q(), modes.d());
            if (scheduler.sleep(n + p, -state_.eta_curr[p])) contact_->rest(state_, p);  // (screened as point N + p)
        }
}

std::size_t ExactPoints::awake_rows(std::size_t* which, const double** rows) const {
    std::size_t m = 0;
    for (std::size_t p = 0; p < contact_->size(); ++p)
        if (state_.resting[p] == 0) {
            which[m] = p;
            rows[m++] = contact_->row(p).data();
        }
    return m;
}

void ExactPoints::predict(const ModalState& modes, long n, std::span<double> scratch, const ForceGestures* loads) {
    if (forecast_step_ == n) {  // the last step's pass formed it
        std::copy(forecast_.begin(), forecast_.end(), predicted_.begin());
    } else if (state_.awake <= kernels::kMaxPassRows) {  // the awake points' rows (resting ones need none)
        std::array<const double*, kernels::kMaxPassRows> rows{};
        std::array<std::size_t, kernels::kMaxPassRows> which{};
        std::array<double, kernels::kMaxPassRows> values{};
        const std::size_t m = awake_rows(which.data(), rows.data());
        modes.predict_at(rows.data(), m, values.data());
        for (std::size_t r = 0; r < m; ++r) predicted_[which[r]] = values[r];
    } else {  // more points than a pass takes: the prediction stored once, then a product per point
        modes.predict(scratch);
        for (std::size_t p = 0; p < contact_->size(); ++p)
            if (state_.resting[p] == 0)
                predicted_[p] = kernels::dot(contact_->row(p).data(), scratch.data(), modes.size());
    }
    if (loads != nullptr)
        for (std::size_t p = 0; p < contact_->size(); ++p) predicted_[p] += loads->at_point(p);
}

}  // namespace fretbuzz
