// The LCP solvers (numerics/Lcp.hpp) against problems whose answers are known: closed forms,
// and every complementary basis of small problems enumerated by brute force; degenerate ones
// (ties and zeros in q, singular M) included.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "fretbuzz/numerics/Lcp.hpp"

namespace fretbuzz {
namespace {

// w = M z + q.
std::vector<double> slack(const std::vector<double>& m, const std::vector<double>& q, const std::vector<double>& z) {
    const std::size_t n = q.size();
    std::vector<double> w(q);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) w[i] += m[i * n + j] * z[j];
    return w;
}

// Every solution found on a complementary basis (z_i free on the subset, w_i = 0 there) whose
// block of M is nonsingular, by Gaussian elimination with partial pivoting.
std::vector<std::vector<double>> brute_force(const std::vector<double>& m, const std::vector<double>& q) {
    const std::size_t n = q.size();
    std::vector<std::vector<double>> found;
    for (unsigned mask = 0; mask < (1u << n); ++mask) {
        std::vector<std::size_t> set;
        for (std::size_t i = 0; i < n; ++i)
            if (mask & (1u << i)) set.push_back(i);
        const std::size_t k = set.size();
        std::vector<double> a(k * (k + 1));
        for (std::size_t r = 0; r < k; ++r) {
            for (std::size_t c = 0; c < k; ++c) a[r * (k + 1) + c] = m[set[r] * n + set[c]];
            a[r * (k + 1) + k] = -q[set[r]];
        }
        bool singular = false;
        for (std::size_t c = 0; c < k && !singular; ++c) {
            std::size_t p = c;
            for (std::size_t r = c + 1; r < k; ++r)
                if (std::abs(a[r * (k + 1) + c]) > std::abs(a[p * (k + 1) + c])) p = r;
            if (std::abs(a[p * (k + 1) + c]) < 1e-12) singular = true;
            for (std::size_t j = 0; j <= k && !singular; ++j) std::swap(a[c * (k + 1) + j], a[p * (k + 1) + j]);
            for (std::size_t r = 0; r < k && !singular; ++r) {
                if (r == c) continue;
                const double f = a[r * (k + 1) + c] / a[c * (k + 1) + c];
                for (std::size_t j = 0; j <= k; ++j) a[r * (k + 1) + j] -= f * a[c * (k + 1) + j];
            }
        }
        if (singular) continue;
        std::vector<double> z(n, 0.0);
        for (std::size_t r = 0; r < k; ++r) z[set[r]] = a[r * (k + 1) + k] / a[r * (k + 1) + r];
        const std::vector<double> w = slack(m, q, z);
        bool ok = true;
        for (std::size_t i = 0; i < n; ++i) ok = ok && z[i] >= -1e-12 && w[i] >= -1e-12;
        if (ok) found.push_back(z);
    }
    return found;
}

// A Gram matrix A A^T of n rows of length `rank` (rank < n: singular, as more contact points
// than modes give) plus `shift` I.
std::vector<double> gram(std::size_t n, std::size_t rank, double shift, std::mt19937& rng) {
    std::normal_distribution<double> normal;
    std::vector<double> a(n * rank), m(n * n, 0.0);
    for (double& x : a) x = normal(rng);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) {
            for (std::size_t k = 0; k < rank; ++k) m[i * n + j] += a[i * rank + k] * a[j * rank + k];
            if (i == j) m[i * n + j] += shift;
        }
    return m;
}

TEST(Lcp, LemkeSolvesAClosedForm) {
    // Both contacts pressed: z = -M^-1 q = (4/3, 7/3), w = 0.
    const std::vector<double> m = {2.0, 1.0, 1.0, 2.0}, q = {-5.0, -6.0};
    std::vector<double> z(2);
    LemkeSolver lemke(2);
    ASSERT_TRUE(lemke.solve(m, q, 2, z));
    EXPECT_NEAR(z[0], 4.0 / 3.0, 1e-14);
    EXPECT_NEAR(z[1], 7.0 / 3.0, 1e-14);
    // One pressed, one apart: q = (-2, 3): z = (1, 0), w = (0, 4).
    const std::vector<double> q2 = {-2.0, 3.0};
    ASSERT_TRUE(lemke.solve(m, q2, 2, z));
    EXPECT_NEAR(z[0], 1.0, 1e-14);
    EXPECT_EQ(z[1], 0.0);
}

TEST(Lcp, PositiveDefiniteProblemsMatchEveryComplementaryBasis) {
    // Positive definite M: exactly one solution, which enumeration finds and both solvers must give.
    std::mt19937 rng(57);
    std::normal_distribution<double> normal;
    LemkeSolver lemke(7);
    for (int trial = 0; trial < 300; ++trial) {
        const std::size_t n = 1 + static_cast<std::size_t>(trial % 7);
        const std::vector<double> m = gram(n, n, 0.1, rng);
        std::vector<double> q(n);
        for (double& x : q) x = normal(rng);
        const auto solutions = brute_force(m, q);
        ASSERT_EQ(solutions.size(), 1u) << "trial " << trial;
        std::vector<double> z(n), pgs(n, 0.0);
        ASSERT_TRUE(lemke.solve(m, q, n, z)) << "trial " << trial;
        ASSERT_GT(projected_gauss_seidel(m, q, n, pgs, 1e-15), 0) << "trial " << trial;
        for (std::size_t i = 0; i < n; ++i) {
            EXPECT_NEAR(z[i], solutions[0][i], 1e-10 * (1.0 + std::abs(solutions[0][i]))) << "trial " << trial;
            EXPECT_NEAR(pgs[i], solutions[0][i], 1e-8 * (1.0 + std::abs(solutions[0][i]))) << "trial " << trial;
        }
        EXPECT_LT(lcp_violation(m, q, n, z), 1e-12);
    }
}

TEST(Lcp, DegenerateProblemsAreSolvedWithoutCycling) {
    // Singular M (rank below n) and q with ties and zeros: Lemke's plain ratio test can cycle
    // here; the lexicographic one must end, on a solution whose w = M z + q is the enumeration's
    // (for symmetric semidefinite M, w is the same for every solution).
    std::mt19937 rng(2018);
    std::uniform_int_distribution<int> level(-2, 1);
    LemkeSolver lemke(6);
    int solved = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const std::size_t n = 2 + static_cast<std::size_t>(trial % 5);
        const std::size_t rank = 1 + static_cast<std::size_t>(trial % static_cast<int>(n - 1));
        const std::vector<double> m = gram(n, rank, 0.0, rng);
        std::vector<double> q(n);
        for (double& x : q) x = level(rng);  // few levels: many ties, many zeros
        const auto solutions = brute_force(m, q);
        std::vector<double> z(n);
        const bool ok = lemke.solve(m, q, n, z);
        if (solutions.empty()) continue;  // infeasible (or only on singular bases): not compared
        ASSERT_TRUE(ok) << "trial " << trial;
        double largest = 1.0;
        for (double x : z) largest = std::max(largest, x);
        EXPECT_LT(lcp_violation(m, q, n, z), 1e-12 * largest * largest) << "trial " << trial << " max z " << largest;
        const std::vector<double> w = slack(m, q, z), w_ref = slack(m, q, solutions[0]);
        for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(w[i], w_ref[i], 1e-9) << "trial " << trial;
        ++solved;
    }
    EXPECT_GT(solved, 200);
}

TEST(Lcp, TwoPointsAtOnePlaceShareTheImpulse) {
    // Identical rows (two contacts at the same x): M = [[1, 1], [1, 1]], q = (-1, -1): any
    // z1 + z2 = 1; and a third, untouched unknown with q = 0.
    const std::vector<double> m = {1, 1, 0, 1, 1, 0, 0, 0, 1}, q = {-1, -1, 0};
    std::vector<double> z(3);
    LemkeSolver lemke(3);
    ASSERT_TRUE(lemke.solve(m, q, 3, z));
    EXPECT_NEAR(z[0] + z[1], 1.0, 1e-14);
    EXPECT_EQ(z[2], 0.0);
}

TEST(Lcp, AnInfeasibleProblemEndsOnARay) {
    // w1 + w2 = -2 whatever z: no solution, and Lemke says so rather than returning one.
    const std::vector<double> m = {1, -1, -1, 1}, q = {-1, -1};
    std::vector<double> z(2);
    LemkeSolver lemke(2);
    EXPECT_FALSE(lemke.solve(m, q, 2, z));
}

}  // namespace
}  // namespace fretbuzz
