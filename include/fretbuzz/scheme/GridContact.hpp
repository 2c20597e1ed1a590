#pragma once
// The obstacle's points on the grid as a string steps: at each, the scheme's scalar equation
// (one per point: S dx S^T = I keeps them apart), solved for the points the screening keeps
// awake (`active`), from eta^{n-1} and eta^n kept at each; and the contact energy's sums of Psi
// over every obstacle point of the grid, those under a played part's pad included (their part
// solves them and hands their Psi here).
#include <algorithm>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/scheme/ContactForceLaw.hpp"
#include "fretbuzz/scheme/ContactScheduler.hpp"
#include "fretbuzz/scheme/StepRecord.hpp"

namespace fretbuzz {

class GridContact {
public:
    // grid_points: N (every list is bounded by it and reserved once: stepping never allocates).
    explicit GridContact(std::size_t grid_points);

    const std::vector<std::size_t>& active() const { return active_; }
    // Grid point i solved from now on, from u^n and u^{n-1} there (g: its obstacle height).
    void activate(std::size_t i, double g, double u_now, double u_before) {
        eta_curr_[i] = g - u_now;
        eta_prev_[i] = g - u_before;
        active_.push_back(i);
    }
    void clear();  // none active, no energy (a restart)
    // Every obstacle point (not under a pad: on_pad) looked at for the state u^n, u^{n-1} on the
    // grid: its Psi counted, and solved from now on unless the screening can put it to sleep.
    template <ContactForceLaw Law>
    void classify(const Law& law, std::span<const std::size_t> points, std::span<const double> g,
                  std::span<const double> u_now, std::span<const double> u_before, std::span<const char> on_pad,
                  ContactScheduler* screening);
    // The points apart from the obstacle over both levels that the screening lets sleep.
    void put_to_sleep(ContactScheduler& scheduler, std::span<const double> q, std::span<const double> d) {
        if (!active_.empty()) sleep_apart(scheduler, q, d);
    }

    // Psi sums: the step moves them one level on; parts add their pads' Psi of level n + 1.
    void begin_step() {
        psi_prev_ = psi_curr_;
        psi_curr_ = 0.0;
    }
    void add_potential(double psi) { psi_curr_ += psi; }
    bool at_rest() const { return psi_curr_ == 0.0 && psi_prev_ == 0.0; }
    double energy(double dx) const { return 0.5 * dx * (psi_curr_ + psi_prev_); }  // dx (Psi^n + Psi^{n-1}) / 2

    // The active points' equations as a batch (a and b, from the free prediction at each point in
    // `predicted`): for PenaltyContact::solve_all or a joint solve, whose solutions go to solutions().
    void gather_equations(std::span<const double> g, std::span<const double> predicted);
    std::span<const double> a() const { return solve_a_; }
    std::span<const double> b() const { return solve_b_; }
    std::span<ContactSolution> solutions() { return solutions_; }
    // The step at every active point: from the batch's solutions (solved), else each point's own
    // solve from `predicted`. Moves eta on, adds Psi, appends the non-zero forces to `forces`.
    template <ContactForceLaw Law>
    void solve(const Law& law, double k, std::span<const double> g, std::span<const double> predicted, bool solved,
               std::vector<std::pair<std::size_t, double>>& forces, StepRecord& record);

private:
    void sleep_apart(ContactScheduler& scheduler, std::span<const double> q, std::span<const double> d);

    std::vector<std::size_t> active_;  // points solved every step
    std::vector<double> eta_prev_, eta_curr_;  // eta^{n-1}, eta^n at active points
    std::vector<double> solve_a_, solve_b_;
    std::vector<ContactSolution> solutions_;
    double psi_curr_ = 0.0, psi_prev_ = 0.0;  // sum_i Psi(eta_i^n), sum_i Psi(eta_i^{n-1})
};

// (In the header: the step's loop, inlined where the contact set calls it.)
template <ContactForceLaw Law>
inline void GridContact::solve(const Law& law, double k, std::span<const double> g_span, std::span<const double> predicted,
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

}  // namespace fretbuzz
