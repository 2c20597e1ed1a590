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

void GridContact::put_to_sleep(ContactScheduler& scheduler, std::span<const double> q, std::span<const double> d) {
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

template <ContactForceLaw Law>
void GridContact::solve(const Law& law, double k, std::span<const double> g_span, std::span<const double> predicted,
                        bool solved, std::vector<std::pair<std::size_t, double>>& forces, StepRecord& record) {
    // Raw pointers and local sums: the forces' emplace_back would otherwise make the compiler
    // reload every member at every point (503 points at the flat obstacle's onset).
    double* eta_prev = eta_prev_.data();
    double* eta_curr = eta_curr_.data();
    const double* grid = predicted.data();
    const double* g = g_span.data();
    double psi = psi_curr_;
    int most_iterations = record.stats.max_newton_iterations;
    bool touched = record.touched_obstacle;
    const auto take = [&](std::size_t i, double a, const ContactSolution& s) {
        const double eta_next = a + s.increment;
        eta_prev[i] = eta_curr[i];
        eta_curr[i] = eta_next;
        psi += law.potential(eta_next, s.root);  // sqrt(eta_next) as the solve left it
        most_iterations = std::max(most_iterations, s.iterations);
        if (s.force != 0.0) {
            forces.emplace_back(i, s.force);
            touched = true;
        }
    };
    // Two loops: the batch's has no call to the solve in it (the compiler keeps more in registers).
    const std::size_t count = active_.size();
    const std::size_t* active = active_.data();
    if (solved) {
        const ContactSolution* solutions = solutions_.data();
        for (std::size_t p = 0; p < count; ++p) take(active[p], eta_prev[active[p]], solutions[p]);
    } else {
        for (std::size_t p = 0; p < count; ++p) {
            const std::size_t i = active[p];
            const double a = eta_prev[i];
            take(i, a, law.solve(a, g[i] - grid[i] - a, k));
        }
    }
    psi_curr_ = psi;
    record.stats.max_newton_iterations = most_iterations;
    record.touched_obstacle = touched;
    if (touched) ++record.stats.contact_steps;
}

// The laws the scheme plans with.
template void GridContact::classify(const PenaltyContact&, std::span<const std::size_t>, std::span<const double>,
                                    std::span<const double>, std::span<const double>, std::span<const char>,
                                    ContactScheduler*);
template void GridContact::solve(const PenaltyContact&, double, std::span<const double>, std::span<const double>, bool,
                                 std::vector<std::pair<std::size_t, double>>&, StepRecord&);

}  // namespace fretbuzz
