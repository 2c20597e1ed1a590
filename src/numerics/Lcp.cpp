#include "fretbuzz/numerics/Lcp.hpp"

#include <algorithm>
#include <cmath>

namespace fretbuzz {

namespace {
// Entries below this (relative to the entering column's largest) are zero: the problem is
// scaled to unit q and M first, so round-off in the tableau stays near 1e-16.
constexpr double kPivotTolerance = 1e-12;
// Two ratios equal to this relative precision are a tie (broken by the next column).
constexpr double kTieTolerance = 1e-11;

double max_abs(std::span<const double> x) {
    double most = 0.0;
    for (double v : x) most = std::max(most, std::abs(v));
    return most;
}

bool same(double a, double b) { return std::abs(a - b) <= kTieTolerance * std::max({1.0, std::abs(a), std::abs(b)}); }
}  // namespace

LemkeSolver::LemkeSolver(std::size_t capacity) : capacity_(capacity) {
    tableau_.reserve(capacity * (2 * capacity + 2));
    basis_.reserve(capacity);
}

bool LemkeSolver::solve(std::span<const double> m, std::span<const double> q, std::size_t n, std::span<double> z) {
    pivots_ = 0;
    std::fill(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(n), 0.0);
    const std::span<const double> qn = q.first(n);
    if (std::all_of(qn.begin(), qn.end(), [](double v) { return v >= 0.0; })) return true;  // z = 0 answers it
    // Scaled to unit sizes: w' = M' z' + q', M' = M / sm, q' = q / sq, z = z' sq / sm.
    const double sq = max_abs(qn), sm = max_abs(m.first(n * n));
    if (!(sm > 0.0)) return false;  // M = 0 and some q_i < 0: nothing can make w_i >= 0
    n_ = n;
    width_ = 2 * n + 2;
    tableau_.assign(n * width_, 0.0);
    basis_.resize(n);
    const std::size_t z0 = 2 * n, rhs = 2 * n + 1;
    for (std::size_t i = 0; i < n; ++i) {
        at(i, i) = 1.0;
        for (std::size_t j = 0; j < n; ++j) at(i, n + j) = -m[i * n + j] / sm;
        at(i, z0) = -1.0;
        at(i, rhs) = q[i] / sq;
        basis_[i] = i;
    }
    // z0 enters where q is lowest (among equal lows the last row: that keeps every row's
    // [rhs, B^-1] lexicographically positive after the pivot).
    std::size_t r = 0;
    for (std::size_t i = 1; i < n; ++i)
        if (at(i, rhs) <= at(r, rhs)) r = i;
    std::size_t leaving = basis_[r];
    pivot(r, z0);
    const int most = 1000 + 50 * static_cast<int>(n);
    while (pivots_ < most) {
        const std::size_t entering = leaving < n ? leaving + n : leaving - n;  // the complement
        const std::ptrdiff_t row = leaving_row(entering);
        if (row < 0) return false;  // a secondary ray
        leaving = basis_[static_cast<std::size_t>(row)];
        pivot(static_cast<std::size_t>(row), entering);
        if (leaving == z0) {
            for (std::size_t i = 0; i < n; ++i)
                if (basis_[i] >= n && basis_[i] < z0) z[basis_[i] - n] = std::max(0.0, at(i, rhs)) * sq / sm;
            return true;
        }
    }
    return false;
}

std::ptrdiff_t LemkeSolver::leaving_row(std::size_t e) const {
    const std::size_t n = n_, rhs = 2 * n + 1, z0 = 2 * n;
    double column = 0.0;
    for (std::size_t i = 0; i < n; ++i) column = std::max(column, std::abs(at(i, e)));
    const double smallest = kPivotTolerance * column;
    std::ptrdiff_t best = -1;
    double best_ratio = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        if (!(at(i, e) > smallest)) continue;
        const double ratio = at(i, rhs) / at(i, e);
        if (best < 0 || ratio < best_ratio) {
            best = static_cast<std::ptrdiff_t>(i);
            best_ratio = ratio;
        }
    }
    if (best < 0) return -1;
    // Among the rows tied at the least ratio: z0's if it is there (the solve ends), else the
    // lexicographic least of [rhs, B^-1] / entry (B^-1 is the w columns; no two rows tie in it).
    std::ptrdiff_t chosen = -1;
    for (std::size_t i = 0; i < n; ++i) {
        if (!(at(i, e) > smallest) || !same(at(i, rhs) / at(i, e), best_ratio)) continue;
        if (basis_[i] == z0) return static_cast<std::ptrdiff_t>(i);
        if (chosen < 0) {
            chosen = static_cast<std::ptrdiff_t>(i);
            continue;
        }
        const auto c = static_cast<std::size_t>(chosen);
        for (std::size_t k = 0; k < n; ++k) {
            const double a = at(i, k) / at(i, e), b = at(c, k) / at(c, e);
            if (same(a, b)) continue;
            if (a < b) chosen = static_cast<std::ptrdiff_t>(i);
            break;
        }
    }
    return chosen;
}

void LemkeSolver::pivot(std::size_t r, std::size_t e) {
    ++pivots_;
    double* pivot_row = &tableau_[r * width_];
    const double p = pivot_row[e];
    for (std::size_t k = 0; k < width_; ++k) pivot_row[k] /= p;
    pivot_row[e] = 1.0;
    for (std::size_t i = 0; i < n_; ++i) {
        if (i == r) continue;
        double* row = &tableau_[i * width_];
        const double f = row[e];
        if (f == 0.0) continue;
        for (std::size_t k = 0; k < width_; ++k) row[k] -= f * pivot_row[k];
        row[e] = 0.0;
    }
    basis_[r] = e;
}

int projected_gauss_seidel(std::span<const double> m, std::span<const double> q, std::size_t n, std::span<double> z,
                           double tolerance, int max_sweeps) {
    for (int sweep = 1; sweep <= max_sweeps; ++sweep) {
        double moved = 0.0, size = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            double w = q[i];
            for (std::size_t j = 0; j < n; ++j) w += m[i * n + j] * z[j];
            const double next = std::max(0.0, z[i] - w / m[i * n + i]);
            moved = std::max(moved, std::abs(next - z[i]));
            z[i] = next;
            size = std::max(size, next);
        }
        if (moved <= tolerance * size) return sweep;
    }
    return -1;
}

double lcp_violation(std::span<const double> m, std::span<const double> q, std::size_t n, std::span<const double> z) {
    double worst = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        double w = q[i];
        for (std::size_t j = 0; j < n; ++j) w += m[i * n + j] * z[j];
        worst = std::max({worst, -z[i], -w, std::abs(z[i] * w)});
    }
    return worst;
}

}  // namespace fretbuzz
