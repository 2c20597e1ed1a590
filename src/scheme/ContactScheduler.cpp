#include "fretbuzz/scheme/ContactScheduler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/scheme/Kernels.hpp"

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
}

void ContactScheduler::clear() {
    while (!queue_.empty()) queue_.pop();
}

void ContactScheduler::update_speed(std::span<const double> q, std::span<const double> d) {
    const ModalPropagator& prop = plan_.propagator();
    const std::size_t n = q.size();
    amplitude_.resize(n);
    prop.free_amplitudes(q, d, amplitude_);
    // One pass each, vectorised; the tail beyond the head modes is summed when the head is set.
    const double speed = kernels::dot(prop.speed_factor().data(), amplitude_.data(), n);
    const double reach = kernels::sum(amplitude_.data(), n);
    stale_ = false;
    set_head_modes(head_);
    speed_ = std::isfinite(speed) ? norm_ * speed * (1.0 + kSlack) : std::numeric_limits<double>::infinity();
    slack_ = std::isfinite(reach) ? kSlack * norm_ * reach : std::numeric_limits<double>::infinity();
}

void ContactScheduler::motion_changed(std::span<const double> q, std::span<const double> d) {
    // Asleep points are keyed by budget, which grows with the speed: it must hold from now on.
    if (queue_.empty())
        stale_ = true;
    else
        update_speed(q, d);
}

void ContactScheduler::set_head_modes(std::size_t head) {
    head_ = std::min(head == 0 ? kHeadModes : head, plan_.mode_count());
    tail_ = head_ < amplitude_.size()
                ? norm_ * kernels::sum(amplitude_.data() + head_, amplitude_.size() - head_) * (1.0 + kSlack)
                : 0.0;
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
