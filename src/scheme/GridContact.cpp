#include "fretbuzz/scheme/GridContact.hpp"

#include <algorithm>

#include "fretbuzz/scheme/PenaltyContact.hpp"

namespace fretbuzz {

GridContact::GridContact(std::size_t grid_points) : eta_prev_(grid_points, 0.0), eta_curr_(grid_points, 0.0) {
    active_.reserve(grid_points);
    solve_a_.reserve(grid_points);
    solve_b_.reserve(grid_points);
    solutions_.reserve(grid_points);
}

void GridContact::clear() {
    active_.clear();
    psi_prev_ = psi_curr_ = 0.0;
}

template <ContactForceLaw Law>
void GridContact::classify(const Law& law, std::span<const std::size_t> points, std::span<const double> g,
                           std::span<const double> u_now, std::span<const double> u_before, std::span<const char> on_pad,
                           ContactScheduler* screening) {
    for (std::size_t i : points) {
        psi_prev_ += law.potential(g[i] - u_before[i]);
        psi_curr_ += law.potential(g[i] - u_now[i]);
        if (on_pad[i] != 0) continue;  // solved with its part
        const bool apart = g[i] - u_before[i] <= 0.0 && g[i] - u_now[i] <= 0.0;
        if (screening == nullptr || !apart || !screening->sleep(i, u_now[i] - g[i])) activate(i, g[i], u_now[i], u_before[i]);
    }
}

void GridContact::sleep_apart(ContactScheduler& scheduler, std::span<const double> q, std::span<const double> d) {
    std::erase_if(active_, [&](std::size_t i) {
        if (!(eta_curr_[i] <= 0.0 && eta_prev_[i] <= 0.0)) return false;
        scheduler.refresh(q, d);  // the speed bound is kept current only while some point sleeps
        return scheduler.sleep(i, -eta_curr_[i]);
    });
}

void GridContact::gather_equations(std::span<const double> g, std::span<const double> predicted) {
    const std::size_t count = active_.size();
    solve_a_.resize(count);  // within the reserved capacity: no allocation
    solve_b_.resize(count);
    solutions_.resize(count);
    const double* eta_prev = eta_prev_.data();
    for (std::size_t p = 0; p < count; ++p) {
        const std::size_t i = active_[p];
        solve_a_[p] = eta_prev[i];
        solve_b_[p] = g[i] - predicted[i] - eta_prev[i];
    }
}

// The laws the scheme plans with.
template void GridContact::classify(const PenaltyContact&, std::span<const std::size_t>, std::span<const double>,
                                    std::span<const double>, std::span<const double>, std::span<const char>,
                                    ContactScheduler*);

}  // namespace fretbuzz
