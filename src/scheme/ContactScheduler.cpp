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
    default_head_ = head_;
    const std::size_t n = plan.mode_count();
    unit_amplitude_.resize(n);
    for (auto* v : {&point_speed_, &point_reach_, &point_tail_}) v->resize(n);
    clear();
}

void ContactScheduler::clear() {
    while (!queue_.empty()) queue_.pop();
    // The damping may have changed with the state (a real-time engine restarts after it).
    const ModalPropagator& prop = plan_.propagator();
    for (std::size_t j = 0; j < unit_amplitude_.size(); ++j) unit_amplitude_[j] = prop.free_amplitude(j, 1.0, 1.0);
    for (auto* v : {&point_speed_, &point_reach_, &point_tail_})
        std::fill(v->begin(), v->end(), std::numeric_limits<double>::quiet_NaN());
}

void ContactScheduler::compute_point(std::size_t i) {
    const std::span<const double> row = plan_.basis().row(i);
    const std::span<const double> w = plan_.propagator().speed_factor();
    double speed = 0.0, reach = 0.0, tail = 0.0;
    for (std::size_t j = 0; j < row.size(); ++j) {
        const double a = unit_amplitude_[j] * std::abs(row[j]);
        speed += w[j] * a;
        reach += a;
        if (j >= default_head_) tail += a;
    }
    point_speed_[i] = speed;
    point_reach_[i] = reach;
    point_tail_[i] = tail;
}

void ContactScheduler::pushed(std::span<const std::pair<std::size_t, double>> forces, double coefficient,
                              std::span<const double> q, std::span<const double> d) {
    if (queue_.empty()) {
        stale_ = true;  // as motion_changed: nobody asleep needs the bound yet
        return;
    }
    if (stale_ || head_ != default_head_ || forces.size() > plan_.transform_threshold()) {
        update_speed(q, d);
        return;
    }
    double speed = 0.0, reach = 0.0, tail = 0.0;
    for (const auto& [i, f] : forces) {
        if (std::isnan(point_speed_[i])) compute_point(i);
        const double c = std::abs(coefficient * f);
        speed += c * point_speed_[i];
        reach += c * point_reach_[i];
        tail += c * point_tail_[i];
    }
    const double grown = speed_ + norm_ * speed * (1.0 + kSlack);
    if (!(grown <= 1.5 * computed_speed_)) {  // too loose (or not finite): start afresh
        update_speed(q, d);
        return;
    }
    speed_ = grown;
    slack_ += kSlack * norm_ * reach;
    tail_ += norm_ * tail * (1.0 + kSlack);
    loose_ = true;
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
    loose_ = false;
    set_head_modes(head_);
    speed_ = std::isfinite(speed) ? norm_ * speed * (1.0 + kSlack) : std::numeric_limits<double>::infinity();
    computed_speed_ = speed_;
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
    if (loose_) {  // amplitude_ is behind the bound: claim nothing (callers refresh first)
        tail_ = std::numeric_limits<double>::infinity();
        return;
    }
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
