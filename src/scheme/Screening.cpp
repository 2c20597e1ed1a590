#include "fretbuzz/scheme/Screening.hpp"

namespace fretbuzz {

namespace {
// Free modes decay: tighten the speed bound this often even when nothing touches.
constexpr long kSpeedRefreshSteps = 1L << 14;
}  // namespace

Screening::Screening(const Plan& plan) : plan_(&plan), scheduler_(plan), on_(plan.options().screen_contacts) {
    due_.reserve(2 * plan.mode_count() + 16);
}

void Screening::start(const ModalState& modes, long n) {
    scheduler_.update_speed(modes.q(), modes.d());
    next_speed_refresh_ = n + kSpeedRefreshSteps;
}

bool Screening::refresh_after_step(const ModalState& modes, long next) {
    if (next < next_speed_refresh_) return false;
    scheduler_.motion_changed(modes.q(), modes.d());  // the modes have decayed: a tighter bound
    next_speed_refresh_ = next + kSpeedRefreshSteps;
    return true;
}

void Screening::refresh_after_flight(const ModalState& modes, long n) {
    if (n >= next_speed_refresh_) start(modes, n);
}

bool Screening::sleeps_on_low_modes(std::size_t i, std::size_t head, double tail, const ModalState& modes) {
    const double low = kernels::dot(plan_->screened_row(i).data(), modes.q().data(), head);
    return scheduler_.sleep(i, low - tail - plan_->screened_height(i));
}

void Screening::wake(const ModalState& modes, GridContact& grid, ExactPoints& points, std::span<double> field) {
    const std::vector<double>& g = plan_->obstacle();
    const std::size_t n = modes.size();
    const bool use_transform = due_.size() > plan_->transform_threshold();
    if (use_transform) plan_->basis().to_grid(modes.q(), field);
    const std::size_t head = scheduler_.head_modes();
    const double tail = scheduler_.tail_bound();
    for (std::size_t i : due_) {
        // Cheapest first: the low modes and a bound on the rest, then the exact height.
        if (i >= n) {  // exact point p = i - N
            const std::size_t p = i - n;
            if (head < n && sleeps_on_low_modes(i, head, tail, modes)) continue;
            const double u_now = modes.at(points.contact().row(p).data());
            if (scheduler_.sleep(i, u_now - points.contact().height(p))) continue;
            points.wake(p, modes);
            continue;
        }
        const std::span<const double> row = plan_->basis().row(i);
        double u_now = 0.0, u_before = 0.0;
        if (use_transform) {
            u_now = field[i];
        } else {
            if (head < n && sleeps_on_low_modes(i, head, tail, modes)) continue;
            u_now = modes.at(row.data());
        }
        if (scheduler_.sleep(i, u_now - g[i])) continue;
        modes.at_both(row.data(), u_now, u_before);
        grid.activate(i, g[i], u_now, u_before);
    }
}

long Screening::fly_head(ModalState& modes, long steps, std::size_t head, std::span<const std::vector<double>> probes,
                         std::vector<double>& u, std::vector<double>* v) {
    scheduler_.set_head_modes(head);
    const double tail = scheduler_.tail_bound();
    const std::size_t width = probes.size();
    u.resize(static_cast<std::size_t>(steps) * width);
    if (v != nullptr) v->resize(u.size());
    long flown = 0;
    bool interrupted = false;
    while (flown < steps && !interrupted) {
        due_.clear();
        scheduler_.pop_due(due_);
        for (std::size_t i : due_) {
            if (!interrupted && scheduler_.park(i)) continue;
            if (interrupted || !sleeps_on_low_modes(i, head, tail, modes)) {
                interrupted = true;  // a closer look is needed: leave it to a full step
                scheduler_.wake_now(i);
            }
        }
        if (interrupted) break;
        modes.step_modes(0, head);
        for (std::size_t p = 0; p < width; ++p) {
            const std::size_t at = static_cast<std::size_t>(flown) * width + p;
            u[at] = kernels::dot(probes[p].data(), modes.q().data(), head);
            if (v != nullptr) (*v)[at] = kernels::dot(probes[p].data(), modes.d().data(), head) / plan_->dt();
        }
        scheduler_.end_step();
        ++flown;
    }
    return flown;
}

}  // namespace fretbuzz
