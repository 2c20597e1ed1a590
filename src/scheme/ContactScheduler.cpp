#include "fretbuzz/scheme/ContactScheduler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

namespace {
// Relative slack on the bounds: far above round-off in u and q, far below anything physical.
constexpr double kSlack = 1e-9;
// A point sleeps only if it is at least this many steps of travel away.
constexpr double kMinimumSteps = 2.0;
// Modes used by a cheap look at a point (the low modes carry most of the motion).
constexpr std::size_t kHeadModes = 48;
// A grown speed bound is recomputed in full once it exceeds the last full one by this factor
// (a loose bound wakes sleeping points early: more checks, same results).
constexpr double kLooseness = 1.25;
// The same after an impulse taken in modal form (hundreds of points pushed at once, step after
// step): a bound 25 % loose let many more points fail to sleep through a flat obstacle's long
// contact (docs/performance.md); 5 % keeps its onset's saving.
constexpr double kImpulseLooseness = 1.05;
// At most this many points get their push weight computed in one step (else a full update).
constexpr std::size_t kNewPointsPerPush = 2;
// Up to this many new points (a finger's pad) their weights are learnt a few per step; more (a
// flat obstacle's onset, hundreds of points) would take hundreds of steps of extra passes.
constexpr std::size_t kLearntPointsAtMost = 16;
}  // namespace

ContactScheduler::ContactScheduler(const Plan& plan)
    : plan_(plan), norm_(std::sqrt(2.0 / plan.basis().length())), head_(std::min(kHeadModes, plan.mode_count())) {
    // Room for every point twice (asleep and just woken), so that stepping never allocates.
    std::vector<Entry> storage;
    const std::size_t points = plan.screened_points();
    storage.reserve(2 * points + 16);
    queue_ = decltype(queue_)(std::greater<>(), std::move(storage));
    amplitude_.reserve(plan.mode_count());
    parked_.reserve(points);
    envelope_.assign(points, 0.0);
    held_.reserve(2 * points + 16);
    park_amplitude_.reserve(plan.mode_count());
    tested_with_.assign(points, -1);
    retry_reach_.assign(points, std::numeric_limits<double>::infinity());
    row_scratch_.assign(plan.mode_count(), 0.0);  // sized here: parking runs in real-time audio paths
    compute_push_weights();
}

void ContactScheduler::clear() {
    while (!queue_.empty()) queue_.pop();
    parked_.clear();
    park_epoch_ = -1;
    std::fill(retry_reach_.begin(), retry_reach_.end(), std::numeric_limits<double>::infinity());
    compute_push_weights();
}

void ContactScheduler::compute_push_weights() {
    const ModalPropagator& prop = plan_.propagator();
    const std::size_t n = plan_.mode_count();
    push_speed_.assign(n, 1.0);  // the unit state (1, 1), then its amplitudes
    push_reach_.assign(n, 0.0);
    prop.free_amplitudes(push_speed_, push_speed_, push_reach_);
    for (std::size_t j = 0; j < n; ++j) push_speed_[j] = prop.speed_factor()[j] * push_reach_[j];
    const double unknown = std::numeric_limits<double>::quiet_NaN();
    point_weight_.assign(plan_.screened_points(), {unknown, unknown, unknown});
}

const ContactScheduler::PointWeight& ContactScheduler::point_weight(std::size_t i) {
    PointWeight& w = point_weight_[i];
    if (std::isnan(w.reach)) {
        const std::span<const double> row = plan_.screened_row(i);
        const std::size_t n = row.size(), head = std::min(kHeadModes, n);
        double reach_head = 0.0, speed_head = 0.0, speed_tail = 0.0;
        kernels::weighted_abs_sums(push_reach_.data(), push_speed_.data(), row.data(), head, reach_head, speed_head);
        kernels::weighted_abs_sums(push_reach_.data() + head, push_speed_.data() + head, row.data() + head, n - head,
                                   w.tail, speed_tail);
        w.speed = speed_head + speed_tail;
        w.reach = reach_head + w.tail;
    }
    return w;
}

void ContactScheduler::pushed(std::span<const double> q, std::span<const double> d,
                              std::span<const std::pair<std::size_t, double>> forces, double scale) {
    if (!bound_needed_after_push()) return;
    // The cached tails are beyond the default head (the only one while contact steps run).
    // A point's weight costs one pass over its row the first time: with many new points
    // (a flat obstacle's onset) the four passes of a full update are cheaper for this step,
    // but with a pad's worth of them a few are learnt at each push all the same, so that points
    // pushed again and again (a finger's pad) soon take the cheap path.
    std::size_t unknown = 0;
    for (const auto& force : forces) unknown += std::isnan(point_weight_[force.first].reach) ? 1 : 0;
    if (unknown > kNewPointsPerPush && unknown <= kLearntPointsAtMost)
        for (std::size_t learnt = 0; const auto& force : forces)
            if (std::isnan(point_weight_[force.first].reach) && learnt++ < kNewPointsPerPush) point_weight(force.first);
    if (stale_ || unknown > kNewPointsPerPush || head_ != std::min(kHeadModes, plan_.mode_count())) {
        update_speed(q, d);
        return;
    }
    double speed = 0.0, reach = 0.0, tail = 0.0;
    for (const auto& [i, f] : forces) {
        const PointWeight& w = point_weight(i);
        const double push = std::abs(scale * f);
        speed += push * w.speed;
        reach += push * w.reach;
        tail += push * w.tail;
    }
    grow_bounds(speed, reach, tail, q, d, kLooseness);
}

void ContactScheduler::pushed(std::span<const double> q, std::span<const double> d, std::span<const double> impulse) {
    if (!bound_needed_after_push()) return;
    const std::size_t n = impulse.size(), head = std::min(kHeadModes, n);
    if (stale_ || head_ != head) {
        update_speed(q, d);
        return;
    }
    double reach_head = 0.0, speed_head = 0.0, tail = 0.0, speed_tail = 0.0;
    kernels::weighted_abs_sums(push_reach_.data(), push_speed_.data(), impulse.data(), head, reach_head, speed_head);
    kernels::weighted_abs_sums(push_reach_.data() + head, push_speed_.data() + head, impulse.data() + head, n - head,
                               tail, speed_tail);
    grow_bounds(speed_head + speed_tail, reach_head + tail, tail, q, d, kImpulseLooseness);
}

bool ContactScheduler::bound_needed_after_push() {
    unpark();  // the envelope was the old motion's
    if (!queue_.empty()) return true;
    stale_ = true;  // as motion_changed: nothing asleep needs the bound yet
    return false;
}

void ContactScheduler::grow_bounds(double speed, double reach, double tail, std::span<const double> q,
                                   std::span<const double> d, double looseness) {
    speed_ += norm_ * speed * (1.0 + kSlack);
    slack_ += kSlack * norm_ * reach;
    tail_ += norm_ * tail * (1.0 + kSlack);
    amplitudes_behind_ = true;
    if (!(speed_ <= looseness * full_speed_)) update_speed(q, d);
}

void ContactScheduler::update_speed(std::span<const double> q, std::span<const double> d) {
    const ModalPropagator& prop = plan_.propagator();
    const std::size_t n = q.size();
    amplitude_.resize(n);
    prop.free_amplitudes(q, d, amplitude_);
    ++amplitude_epoch_;
    check_parked();
    // One pass each, vectorised; the tail beyond the head modes is summed when the head is set.
    const double speed = kernels::dot(prop.speed_factor().data(), amplitude_.data(), n);
    const double reach = kernels::sum(amplitude_.data(), n);
    reach_ = reach;
    stale_ = false;
    amplitudes_behind_ = false;
    set_head_modes(head_);
    speed_ = std::isfinite(speed) ? norm_ * speed * (1.0 + kSlack) : std::numeric_limits<double>::infinity();
    slack_ = std::isfinite(reach) ? kSlack * norm_ * reach : std::numeric_limits<double>::infinity();
    full_speed_ = speed_;
}

bool ContactScheduler::park(std::size_t i) {
    if (stale_ || amplitudes_behind_ || amplitude_.size() != plan_.mode_count() || tested_with_[i] == amplitude_epoch_ ||
        !(reach_ <= retry_reach_[i]))
        return false;
    tested_with_[i] = amplitude_epoch_;
    // Parking tests every sleeping point once: their rows are not worth keeping (N^2 numbers).
    const std::span<const double> row = plan_.screened_row(i, row_scratch_);
    const double envelope = kernels::weighted_abs_sum(amplitude_.data(), row.data(), row.size()) * (1.0 + kSlack);
    // u_i >= -envelope from now until the next impulse: its gap u_i - g stays above -envelope - g.
    const double room = -plan_.screened_height(i) - slack_;
    if (!(envelope < room)) {
        // Worth another test once the amplitudes have shrunk in proportion (a guess: skipping
        // a test only leaves the point in the queue).
        retry_reach_[i] = room > 0.0 ? reach_ * room / envelope : -1.0;
        return false;
    }
    if (park_epoch_ != amplitude_epoch_) {
        // The parked points hold while every later amplitude stays within the smallest they were
        // tested with (free motion only decays).
        if (parked_.empty())
            park_amplitude_.assign(amplitude_.begin(), amplitude_.end());
        else
            for (std::size_t j = 0; j < amplitude_.size(); ++j) park_amplitude_[j] = std::min(park_amplitude_[j], amplitude_[j]);
        park_epoch_ = amplitude_epoch_;
    }
    envelope_[i] = envelope;
    parked_.push_back(i);
    ++parks_;
    return true;
}

bool ContactScheduler::park_due(long steps) {
    const double horizon = budget_ + speed_ * static_cast<double>(steps) * plan_.dt();
    held_.clear();
    while (!queue_.empty() && queue_.top().first <= horizon) {
        if (!park(queue_.top().second)) held_.push_back(queue_.top());
        queue_.pop();
    }
    for (const Entry& e : held_) queue_.push(e);
    return held_.empty();
}

void ContactScheduler::check_parked() {
    // New amplitudes (decay, or an impulse seen as a change of motion): the envelopes still
    // bound the motion if no amplitude grew beyond those they were computed with (less than
    // the slack they carry, for round-off).
    if (parked_.empty()) return;
    for (std::size_t j = 0; j < amplitude_.size(); ++j)
        if (!(amplitude_[j] <= park_amplitude_[j] * (1.0 + 0.5 * kSlack))) {
            unpark();
            return;
        }
}

void ContactScheduler::unpark() {
    // Until now u_i >= -E_i: each point goes back to the queue with that gap, no look needed.
    if (parked_.empty()) return;
    ++releases_;
    for (std::size_t i : parked_) queue_.emplace(budget_ + std::max(-envelope_[i] - plan_.screened_height(i) - slack_, 0.0), i);
    parked_.clear();
    park_epoch_ = -1;
}

void ContactScheduler::motion_changed(std::span<const double> q, std::span<const double> d) {
    // Asleep points are keyed by budget, which grows with the speed: it must hold from now on.
    // Parked points need the new amplitudes to know whether their envelope still holds.
    if (queue_.empty() && parked_.empty())
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
