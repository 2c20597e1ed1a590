#include "fretbuzz/scheme/ContactScheduler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fretbuzz {

namespace {
// Relative slack on the bounds: far above round-off in u and q, far below anything physical.
constexpr double kSlack = 1e-9;
// A point sleeps only if it is at least this many steps of travel away.
constexpr double kMinimumSteps = 2.0;
// Modes used by a cheap look at a point (the low modes carry most of the motion).
constexpr std::size_t kHeadModes = 48;
}  // namespace

ContactScheduler::ContactScheduler(const Plan& plan)
    : plan_(plan), norm_(std::sqrt(2.0 / plan.basis().length())), head_(std::min(kHeadModes, plan.mode_count())) {
    // Room for every point twice (asleep and just woken), so that stepping never allocates.
    std::vector<Entry> storage;
    storage.reserve(2 * plan.mode_count() + 16);
    queue_ = decltype(queue_)(std::greater<>(), std::move(storage));
    amplitude_.reserve(plan.mode_count());
    tail_sums_.reserve(plan.mode_count() + 1);
}

void ContactScheduler::clear() {
    while (!queue_.empty()) queue_.pop();
}

void ContactScheduler::update_speed(std::span<const double> q, std::span<const double> d) {
    const ModalPropagator& prop = plan_.propagator();
    amplitude_.resize(q.size());
    prop.free_amplitudes(q, d, amplitude_);
    tail_sums_.assign(q.size() + 1, 0.0);
    for (std::size_t j = q.size(); j-- > 0;) tail_sums_[j] = tail_sums_[j + 1] + amplitude_[j];
    const auto factor = prop.speed_factor();
    double speed = 0.0;
    for (std::size_t j = 0; j < q.size(); ++j) speed += factor[j] * amplitude_[j];
    const double reach = tail_sums_[0];
    set_head_modes(head_);
    speed_ = std::isfinite(speed) ? norm_ * speed * (1.0 + kSlack) : std::numeric_limits<double>::infinity();
    slack_ = std::isfinite(reach) ? kSlack * norm_ * reach : std::numeric_limits<double>::infinity();
}

void ContactScheduler::set_head_modes(std::size_t head) {
    head_ = std::min(head == 0 ? kHeadModes : head, plan_.mode_count());
    tail_ = head_ < tail_sums_.size() ? norm_ * tail_sums_[head_] * (1.0 + kSlack) : 0.0;
}

void ContactScheduler::pop_due(std::vector<std::size_t>& out) {
    const double horizon = budget_ + speed_ * plan_.dt();
    while (!queue_.empty() && queue_.top().first <= horizon) {
        out.push_back(queue_.top().second);
        queue_.pop();
    }
}

bool ContactScheduler::sleep(std::size_t i, double gap) {
    const double usable = gap - slack_;
    if (!(usable > kMinimumSteps * speed_ * plan_.dt())) return false;
    queue_.emplace(budget_ + usable, i);
    return true;
}

void ContactScheduler::end_steps(long steps) { budget_ += speed_ * static_cast<double>(steps) * plan_.dt(); }

bool ContactScheduler::quiet_for(long steps) const {
    return queue_.empty() || queue_.top().first > budget_ + speed_ * static_cast<double>(steps) * plan_.dt();
}

}  // namespace fretbuzz
