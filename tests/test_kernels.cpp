// The step's one pass over the modes (kernels::step_lossy, step_lossless) and the other fused
// passes agree with plain loops that form each quantity on its own, within the stated
// tolerance: the step with its pushes (rows, or an impulse vector), its losses, the next step's
// predictions at up to 16 rows, the observation row and the modal energy; row products in one
// pass; a free flight's closing jump with its products.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "Equivalence.hpp"
#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {
namespace {

using testing::agree;

struct Data {
    std::vector<double> e, beta, loss, q, d;
    std::vector<std::vector<double>> rows;
};

// Values over 7 orders of magnitude each way, as modal amplitudes and mode shapes can be.
Data random_data(std::mt19937_64& random, std::size_t n, int row_count) {
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    const auto values = [&](bool positive) {
        std::vector<double> v(n);
        for (double& x : v) x = (positive ? std::abs(unit(random)) : unit(random)) * std::exp(8.0 * unit(random));
        return v;
    };
    Data data{values(true), values(true), values(true), values(false), values(false), {}};
    for (int r = 0; r < row_count; ++r) data.rows.push_back(values(false));
    return data;
}

// sum_j row_j x_j, and sum_j |row_j x_j|: the size of its terms, the scale its round-off is
// measured against where they cancel.
struct Sum {
    double value = 0.0, size = 0.0;
};
Sum plain_dot(const double* row, const std::vector<double>& x) {
    Sum s;
    for (std::size_t j = 0; j < x.size(); ++j) {
        s.value += row[j] * x[j];
        s.size += std::abs(row[j] * x[j]);
    }
    return s;
}

// The modal energy sum_j (1 + e_j)/2 d_j^2 + beta_j q_j (q_j - d_j), and the size of its terms.
Sum plain_energy(const Data& data, const std::vector<double>& q, const std::vector<double>& d) {
    Sum s;
    for (std::size_t j = 0; j < q.size(); ++j) {
        const double kinetic = 0.5 * (1.0 + data.e[j]) * d[j] * d[j], potential = data.beta[j] * q[j] * (q[j] - d[j]);
        s.value += kinetic + potential;
        s.size += std::abs(kinetic) + std::abs(potential);
    }
    return s;
}

std::vector<double> plain_prediction(const Data& data, const std::vector<double>& q, const std::vector<double>& d) {
    std::vector<double> p(q.size());
    for (std::size_t j = 0; j < q.size(); ++j) p[j] = q[j] + (data.e[j] * d[j] - data.beta[j] * q[j]);
    return p;
}

TEST(Kernels, RowProductsInOnePassAgreeWithOneDotEach) {
    std::mt19937_64 random(3);
    for (std::size_t n = 0; n < 200; n += (n < 40 ? 1 : 23)) {
        const Data data = random_data(random, n, 7);
        const std::vector<double> predicted = plain_prediction(data, data.q, data.d);
        for (std::size_t m = 1; m <= data.rows.size(); ++m) {
            std::vector<const double*> rows;
            for (std::size_t r = 0; r < m; ++r) rows.push_back(data.rows[r].data());
            std::vector<double> read(m), formed(m);
            kernels::dot_rows(rows.data(), m, predicted.data(), n, read.data());
            kernels::predict_dot_rows(data.e.data(), data.beta.data(), data.q.data(), data.d.data(), rows.data(), m, n,
                                      formed.data());
            for (std::size_t r = 0; r < m; ++r) {
                const Sum plain = plain_dot(rows[r], predicted);
                EXPECT_TRUE(agree(read[r], plain.value, plain.size)) << "n=" << n << " m=" << m << " r=" << r;
                EXPECT_TRUE(agree(formed[r], plain.value, plain.size)) << "n=" << n << " m=" << m << " r=" << r;
                EXPECT_TRUE(agree(kernels::dot(rows[r], predicted.data(), n), plain.value, plain.size)) << n;
            }
        }
    }
}

// The envelope of a point (ContactScheduler::park) is one weighted sum of the two that the
// push weights take in one pass: the same sum to round-off.
TEST(Kernels, OneWeightedAbsSumEqualsThePairsFirst) {
    std::mt19937_64 random(5);
    for (std::size_t n = 0; n < 200; n += (n < 40 ? 1 : 23)) {
        const Data data = random_data(random, n, 0);
        double first = 0.0, second = 0.0;
        kernels::weighted_abs_sums(data.beta.data(), data.e.data(), data.q.data(), n, first, second);
        EXPECT_TRUE(agree(kernels::weighted_abs_sum(data.beta.data(), data.q.data(), n), first)) << "n=" << n;
    }
}

// One step by plain loops: the pushes' impulse, the step, the losses (0 without them).
double plain_step(const Data& data, bool lossy, const std::vector<double>& impulse, std::vector<double>& q,
                  std::vector<double>& d) {
    double losses = 0.0;
    for (std::size_t j = 0; j < q.size(); ++j) {
        const double next = data.e[j] * d[j] - data.beta[j] * q[j] + impulse[j];
        if (lossy) losses += data.loss[j] * (next + d[j]) * (next + d[j]);
        q[j] += next;
        d[j] = next;
    }
    return losses;
}

// The step's pass from data's state, with 0 to 16 pushes by rows or one impulse vector, with and
// without losses, predicting at 0 to 16 rows (the pushed ones first, then others), with and
// without the observation row and the energy: every result agrees with the plain loops.
TEST(Kernels, StepPassAgreesWithPlainLoops) {
    std::mt19937_64 random(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    long compared = 0;
    for (std::size_t n = 0; n <= 1100; n += (n < 70 ? 1 : 61)) {
        const Data data = random_data(random, n, 2 * static_cast<int>(kernels::kMaxPassRows) + 1);
        const double* pickup = data.rows.back().data();
        for (std::size_t pushes : {0, 1, 2, 3, 5, 16}) {
            for (const bool by_vector : {false, true}) {
                if (by_vector && pushes == 0) continue;
                std::vector<const double*> push_rows;
                std::vector<double> coefficients, impulse(n, 0.0);
                for (std::size_t r = 0; r < pushes; ++r) {
                    push_rows.push_back(data.rows[r].data());
                    coefficients.push_back(1e-3 * unit(random));
                    for (std::size_t j = 0; j < n; ++j) impulse[j] += coefficients[r] * push_rows[r][j];
                }
                for (const bool lossy : {false, true}) {
                    std::vector<double> q1 = data.q, d1 = data.d;
                    const double losses = plain_step(data, lossy, impulse, q1, d1);
                    const std::vector<double> next_prediction = plain_prediction(data, q1, d1);
                    const Sum energy_after = plain_energy(data, q1, d1);
                    for (std::size_t count : {0, 1, 4, 7, 16}) {
                        for (const bool extras : {false, true}) {  // the observation row and the energy
                            std::vector<const double*> predict_rows;
                            for (std::size_t r = 0; r < count; ++r) predict_rows.push_back(data.rows[r].data());
                            std::vector<double> q2 = data.q, d2 = data.d, predicted(count, -1.0);
                            double observed = -1.0, energy = -1.0;
                            kernels::StepPass pass;
                            if (by_vector) {
                                pass.impulse = impulse.data();
                            } else {
                                pass.push_rows = push_rows.data();
                                pass.push_coefficients = coefficients.data();
                                pass.pushes = pushes;
                            }
                            pass.predict_rows = predict_rows.data();
                            pass.predict_count = count;
                            pass.predicted = predicted.data();
                            if (extras) {
                                pass.observe_row = pickup;  // (null for n = 0: no row)
                                pass.observed = &observed;
                                pass.energy = &energy;
                            }
                            const kernels::StepKernel step = lossy ? kernels::step_lossy : kernels::step_lossless;
                            const double pass_losses = step(data.e.data(), data.beta.data(), data.loss.data(), pass,
                                                            q2.data(), d2.data(), n);
                            const std::string where = "n=" + std::to_string(n) + " pushes=" + std::to_string(pushes) +
                                                      (by_vector ? " (vector)" : "") + " predicted=" +
                                                      std::to_string(count) + (lossy ? " lossy" : "") +
                                                      (extras ? " observed, energy" : "");
                            ASSERT_TRUE(agree(q2, q1)) << where;
                            ASSERT_TRUE(agree(d2, d1)) << where;
                            ASSERT_TRUE(agree(pass_losses, losses)) << where;
                            for (std::size_t r = 0; r < count; ++r) {
                                const Sum plain = plain_dot(predict_rows[r], next_prediction);
                                ASSERT_TRUE(agree(predicted[r], plain.value, plain.size)) << where << " row " << r;
                            }
                            if (extras) {
                                const Sum plain = plain_dot(pickup, q1);
                                if (pickup != nullptr) {
                                    ASSERT_TRUE(agree(observed, plain.value, plain.size)) << where;
                                }
                                ASSERT_TRUE(agree(energy, energy_after.value, energy_after.size)) << where;
                            }
                            ++compared;
                        }
                    }
                    // advance (the plain step of free flights and the second polarisation) too.
                    std::vector<double> q3 = data.q, d3 = data.d;
                    const double advance_losses =
                        kernels::advance(data.e.data(), data.beta.data(), lossy ? data.loss.data() : nullptr,
                                         pushes == 0 ? nullptr : impulse.data(), q3.data(), d3.data(), n);
                    ASSERT_TRUE(agree(q3, q1) && agree(d3, d1) && agree(advance_losses, losses)) << "advance n=" << n;
                }
            }
        }
    }
    EXPECT_GT(compared, 10000);
}

// A free flight's end (jump_with_products): from any first jumped mode, lossless (e = 1) or
// lossy, with 0 to 6 rows: the same q, d, modal energy and row products as jump, modal_energy
// and dot, within the stated tolerance.
TEST(Kernels, FlightEndInOnePassAgreesWithTheSeparatePasses) {
    std::mt19937_64 random(13);
    constexpr std::size_t kMaps = 4, kRows = 6;
    for (std::size_t n = 0; n <= 1100; n += (n < 70 ? 1 : 13)) {
        Data data = random_data(random, n, kMaps + kRows);
        const auto map = [&](std::size_t i) { return data.rows[i].data(); };
        std::vector<const double*> rows;
        for (std::size_t r = 0; r < kRows; ++r) rows.push_back(data.rows[kMaps + r].data());
        for (const bool lossless : {false, true}) {
            if (lossless) std::fill(data.e.begin(), data.e.end(), 1.0);
            for (const std::size_t first : {std::size_t{0}, std::size_t{1}, std::size_t{3}, std::size_t{4},
                                            std::size_t{5}, std::size_t{13}, std::size_t{48}, n}) {
                if (first > n) continue;
                std::vector<double> q1 = data.q, d1 = data.d;
                kernels::jump(map(0) + first, map(1) + first, map(2) + first, map(3) + first, q1.data() + first,
                              d1.data() + first, n - first);
                const Sum energy = plain_energy(data, q1, d1);
                ASSERT_TRUE(agree(kernels::modal_energy(data.e.data(), data.beta.data(), q1.data(), d1.data(), n),
                                  energy.value, energy.size));
                for (std::size_t m = 0; m <= kRows; ++m) {
                    std::vector<double> q2 = data.q, d2 = data.d, fused(m, -1.0);
                    const double fused_energy =
                        kernels::jump_with_products(map(0), map(1), map(2), map(3), first, data.e.data(),
                                                    data.beta.data(), rows.data(), m, q2.data(), d2.data(), n,
                                                    fused.data());
                    const std::string where = "n=" + std::to_string(n) + " first=" + std::to_string(first) +
                                              " rows=" + std::to_string(m) + (lossless ? " lossless" : "");
                    ASSERT_TRUE(agree(q2, q1) && agree(d2, d1)) << where;
                    ASSERT_TRUE(agree(fused_energy, energy.value, energy.size)) << where;
                    for (std::size_t r = 0; r < m; ++r) {
                        const Sum plain = plain_dot(rows[r], q1);
                        ASSERT_TRUE(agree(fused[r], plain.value, plain.size)) << where << " row " << r;
                    }
                }
            }
        }
    }
}

}  // namespace
}  // namespace fretbuzz
