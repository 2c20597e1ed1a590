#pragma once
// The obstacle's points on the grid as a string steps: at each, the scheme's scalar equation
// (one per point: S dx S^T = I keeps them apart), solved for the points the screening keeps
// awake (`active`), from eta^{n-1} and eta^n kept at each; and the contact energy's sums of Psi
// over every obstacle point of the grid, those under a played part's pad included (their part
// solves them and hands their Psi here).
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
    void put_to_sleep(ContactScheduler& scheduler, std::span<const double> q, std::span<const double> d);

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
    std::vector<std::size_t> active_;  // points solved every step
    std::vector<double> eta_prev_, eta_curr_;  // eta^{n-1}, eta^n at active points
    std::vector<double> solve_a_, solve_b_;
    std::vector<ContactSolution> solutions_;
    double psi_curr_ = 0.0, psi_prev_ = 0.0;  // sum_i Psi(eta_i^n), sum_i Psi(eta_i^{n-1})
};

}  // namespace fretbuzz
