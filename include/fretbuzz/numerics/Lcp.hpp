#pragma once
// The linear complementarity problem LCP(M, q): find z with
//     w = M z + q >= 0,   z >= 0,   z . w = 0
// (Cottle, Pang and Stone, "The Linear Complementarity Problem", 1992). Contacts solved jointly
// give M = H M_s^-1 H^T (the Delassus matrix: symmetric, positive semidefinite). For such an M,
// Lemke's complementary pivoting ends on a solution whenever one exists (M is copositive-plus),
// and with the lexicographic ratio test it cannot cycle on degenerate problems (ties in q, zeros
// in q, M singular). Projected Gauss-Seidel is the iterative cross-check.
#include <cstddef>
#include <span>
#include <vector>

namespace fretbuzz {

// Lemke's method with a covering vector of ones, on a dense tableau; the workspace is sized once
// for problems up to `capacity` unknowns, so that solving allocates nothing.
class LemkeSolver {
public:
    explicit LemkeSolver(std::size_t capacity = 0);
    std::size_t capacity() const { return capacity_; }
    // Solves LCP(M, q) for n <= capacity unknowns (m: n x n, row-major) into z. False if Lemke
    // ends on a secondary ray (no solution: M not copositive-plus, or the problem infeasible).
    bool solve(std::span<const double> m, std::span<const double> q, std::size_t n, std::span<double> z);
    int pivots() const { return pivots_; }  // of the last solve

private:
    // Row r, entering column e: the lexicographic minimum ratio over rows with a positive entry.
    std::ptrdiff_t leaving_row(std::size_t e) const;
    void pivot(std::size_t r, std::size_t e);
    double& at(std::size_t row, std::size_t col) { return tableau_[row * width_ + col]; }
    double at(std::size_t row, std::size_t col) const { return tableau_[row * width_ + col]; }

    std::size_t capacity_;
    std::size_t n_ = 0, width_ = 0;
    std::vector<double> tableau_;      // [w (identity) | -M | -1 | q] per row, pivoted in place
    std::vector<std::size_t> basis_;  // the basic variable of each row: w_i = i, z_i = n + i, z0 = 2n
    int pivots_ = 0;
};

// Projected Gauss-Seidel: z_i <- max(0, z_i - (q + M z)_i / M_ii), sweep after sweep, from z as
// given, until no z_i moves by more than tolerance x max|z| (M_ii > 0). Returns the sweeps made,
// or -1 if max_sweeps was not enough.
int projected_gauss_seidel(std::span<const double> m, std::span<const double> q, std::size_t n, std::span<double> z,
                           double tolerance = 1e-14, int max_sweeps = 100000);

// The largest violation of the conditions by z: max over i of -z_i, -w_i and |z_i w_i|.
double lcp_violation(std::span<const double> m, std::span<const double> q, std::size_t n, std::span<const double> z);

}  // namespace fretbuzz
