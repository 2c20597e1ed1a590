#include "fretbuzz/scheme/ContactScreen.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace fretbuzz {

namespace {
// Relative slack on every bound, far above round-off in u and q, far below anything physical.
constexpr double kSlack = 1e-9;
constexpr long kMinLength = 4;
constexpr long kMaxLength = 1L << 16;
}  // namespace

ContactScreen::ContactScreen(const Plan& plan)
    : plan_(plan),
      norm_(std::sqrt(2.0 / plan.basis().length())),
      gain_(plan.mode_count()),
      distance_(plan.mode_count()),
      order_(plan.obstacle_points()),
      is_candidate_(plan.mode_count(), 0) {}

void ContactScreen::begin(long n0, std::span<const double> q, std::span<const double> d, std::span<const double> u,
                          std::span<const std::size_t> always_include) {
    const ModalPropagator& prop = plan_.propagator();
    const double tau = static_cast<double>(length_) * prop.dt();
    window_end_ = n0 + length_;
    double deviation = 0.0, amplitude = 0.0;
    for (std::size_t j = 0; j < prop.size(); ++j) {
        deviation += prop.free_deviation(j, q[j], d[j], tau);
        amplitude += std::abs(q[j]);
        gain_[j] = prop.impulse_gain(j, tau + prop.dt());
    }
    unbounded_ = !std::isfinite(deviation) || !plan_.options().screen_contacts;
    if (!plan_.options().screen_contacts) window_end_ = std::numeric_limits<long>::max();
    bound_ = norm_ * (deviation * (1.0 + kSlack) + kSlack * amplitude);

    for (std::size_t i : candidates_) is_candidate_[i] = 0;
    candidates_.clear();
    const std::vector<double>& g = plan_.obstacle();
    for (std::size_t i : plan_.obstacle_points()) distance_[i] = u[i] - g[i];
    if (!unbounded_)
        std::sort(order_.begin(), order_.end(),
                  [&](std::size_t a, std::size_t b) { return distance_[a] < distance_[b]; });
    prefix_ = 0;
    for (std::size_t i : always_include) {
        if (!is_candidate_[i]) {
            is_candidate_[i] = 1;
            candidates_.push_back(i);
        }
    }
    extend_prefix();
}

std::size_t ContactScreen::extend_prefix() {
    const std::size_t before = candidates_.size();
    while (prefix_ < order_.size() && (unbounded_ || distance_[order_[prefix_]] <= bound_)) {
        const std::size_t i = order_[prefix_++];
        if (!is_candidate_[i]) {
            is_candidate_[i] = 1;
            candidates_.push_back(i);
        }
    }
    return candidates_.size() - before;
}

std::size_t ContactScreen::widen(std::span<const double> impulse) {
    double growth = 0.0;
    for (std::size_t j = 0; j < impulse.size(); ++j)
        if (impulse[j] != 0.0) growth += gain_[j] * std::abs(impulse[j]);
    if (!std::isfinite(growth)) unbounded_ = true;
    bound_ += norm_ * growth * (1.0 + kSlack);
    return extend_prefix();
}

void ContactScreen::finish_window(double mean_candidates) {
    // A window costs about one transform plus a sort, i.e. some tens of row products;
    // lengthen windows while the candidates they bring cost less than that, shorten otherwise.
    const double window_cost = static_cast<double>(plan_.transform_threshold());
    const double candidate_cost = mean_candidates * static_cast<double>(length_);
    if (candidate_cost < window_cost)
        length_ = std::min(kMaxLength, 2 * length_);
    else if (candidate_cost > 4.0 * window_cost)
        length_ = std::max(kMinLength, length_ / 2);
}

}  // namespace fretbuzz
