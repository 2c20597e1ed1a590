#include "SnapshotTaps.hpp"

#include <algorithm>
#include <cmath>

namespace fretbuzz {

SnapshotTaps::SnapshotTaps(const Case& c, const Plan& plan, std::span<RunObserver* const> observers) : plan_(plan) {
    for (RunObserver* o : observers)
        if (const double rate = o->snapshot_rate_hz(); rate > 0.0) {
            const double until = std::min(o->snapshot_until_s(), c.run.duration_s);
            taps_.push_back({o, std::max(1L, std::lround(c.run.sample_rate_hz / rate)),
                             static_cast<long>(std::floor(until * c.run.sample_rate_hz))});
        }
    if (taps_.empty()) return;
    x_.resize(c.mode_count());
    u_.resize(c.mode_count());
    for (std::size_t i = 0; i < x_.size(); ++i) x_[i] = plan_.basis().grid_point(i);
}

bool SnapshotTaps::due_within(long n, long steps) const {
    for (const Tap& tap : taps_) {
        const long next = (n / tap.stride + 1) * tap.stride;
        if (next < n + steps && next <= tap.last_step) return true;
    }
    return false;
}

void SnapshotTaps::report(long n, double t, std::span<const double> q) {
    bool shaped = false;
    for (const Tap& tap : taps_) {
        if (n % tap.stride != 0 || n > tap.last_step) continue;
        if (!shaped) {
            plan_.basis().to_grid(q, u_);
            plan_.orient(u_);
        }
        shaped = true;
        tap.observer->snapshot(t, x_, u_);
    }
}

}  // namespace fretbuzz
