// The fused contact-step kernels against the separate passes they replace: the same sums
// over the modal state, equal to round-off (the compiler may fuse a multiply and an add
// differently in the two), for any number of rows and any length (partial blocks too).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "fretbuzz/scheme/Kernels.hpp"

namespace fretbuzz {
namespace {

struct ModalState {
    std::vector<double> e, beta, loss, q, d;
    std::vector<std::vector<double>> rows;
};

ModalState random_state(std::size_t n, std::size_t count, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(-1.0, 1.0), positive(0.0, 1.0);
    ModalState s;
    for (std::size_t j = 0; j < n; ++j) {
        s.e.push_back(1.0 - 1e-3 * positive(rng));
        s.beta.push_back(4.0 * positive(rng));
        s.loss.push_back(1e-3 * positive(rng));
        s.q.push_back(1e-3 * unit(rng));
        s.d.push_back(1e-4 * unit(rng));
    }
    s.rows.assign(count, std::vector<double>(n));
    for (auto& row : s.rows)
        for (double& x : row) x = unit(rng);
    return s;
}

double relative(double a, double b) { return std::abs(a - b) / std::max(std::abs(b), 1e-300); }

TEST(Kernels, PredictedRowProductsEqualPredictThenDot) {
    for (std::size_t n : {1u, 7u, 8u, 110u, 862u}) {
        for (std::size_t count : {1u, 3u, 4u, 5u, 9u}) {
            const ModalState s = random_state(n, count, static_cast<unsigned>(n * 31 + count));
            std::vector<double> p(n);
            kernels::predict(s.e.data(), s.beta.data(), s.q.data(), s.d.data(), p.data(), n);
            std::vector<const double*> rows;
            for (const auto& r : s.rows) rows.push_back(r.data());
            std::vector<double> fused(count);
            kernels::predicted_dots(s.e.data(), s.beta.data(), s.q.data(), s.d.data(), rows.data(), count, fused.data(), n);
            for (std::size_t r = 0; r < count; ++r) {
                double norm = 0.0;  // the scale of the sum's round-off
                for (std::size_t j = 0; j < n; ++j) norm += std::abs(s.rows[r][j] * p[j]);
                EXPECT_LE(std::abs(fused[r] - kernels::dot(s.rows[r].data(), p.data(), n)), 1e-14 * norm)
                    << "n=" << n << " rows=" << count << " row " << r;
            }
        }
    }
}

TEST(Kernels, AdvanceWithRowsEqualsImpulseThenAdvance) {
    for (std::size_t n : {1u, 7u, 8u, 110u, 862u}) {
        for (std::size_t count : {0u, 1u, 2u, 5u}) {
            for (bool lossy : {false, true}) {
                const ModalState s = random_state(n, count + 1, static_cast<unsigned>(n * 7 + count));
                std::vector<double> coefficients(count), impulse(n, 0.0);
                std::vector<const double*> rows;
                for (std::size_t r = 0; r < count; ++r) {
                    coefficients[r] = 1e-5 * (static_cast<double>(r) - 1.5);
                    rows.push_back(s.rows[r].data());
                    kernels::axpy(coefficients[r], s.rows[r].data(), impulse.data(), n);
                }
                const double* probe = s.rows[count].data();
                ModalState a = s, b = s;
                const double* loss = lossy ? s.loss.data() : nullptr;
                const double losses_a = kernels::advance(s.e.data(), s.beta.data(), loss, count ? impulse.data() : nullptr,
                                                         a.q.data(), a.d.data(), n);
                const double probed_a = kernels::dot(probe, a.q.data(), n);
                double probed_b = 0.0;
                const double losses_b = kernels::advance_rows(s.e.data(), s.beta.data(), loss, rows.data(),
                                                              coefficients.data(), count, b.q.data(), b.d.data(), n,
                                                              probe, &probed_b);
                for (std::size_t j = 0; j < n; ++j) {
                    EXPECT_LE(relative(b.q[j], a.q[j]), 1e-14) << "n=" << n << " rows=" << count << " j=" << j;
                    EXPECT_LE(std::abs(b.d[j] - a.d[j]), 1e-14 * (std::abs(a.d[j]) + std::abs(s.d[j]) + std::abs(s.q[j])));
                }
                EXPECT_LE(std::abs(losses_b - losses_a), 1e-13 * std::abs(losses_a) + 1e-300);
                double norm = 0.0;
                for (std::size_t j = 0; j < n; ++j) norm += std::abs(probe[j] * a.q[j]);
                EXPECT_LE(std::abs(probed_b - probed_a), 1e-14 * norm);
            }
        }
    }
}

}  // namespace
}  // namespace fretbuzz
