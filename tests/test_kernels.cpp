// The step's fused passes give the sums of the separate ones within the stated tolerance: several
// row products in one pass (with the prediction formed on the fly or read), and several pushes
// added inside the step instead of through an impulse vector.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "Equivalence.hpp"
#include "fretbuzz/scheme/Kernels.hpp"

namespace fretbuzz {
namespace {

using testing::agree;

struct Data {
    std::vector<double> e, beta, loss, q, d;
    std::vector<std::vector<double>> rows;
};

Data random_data(std::mt19937_64& random, std::size_t n, int row_count = 7) {
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

// The step by the kernel for its number of pushes (what the one-pass kernels must equal).
double separate_step(const Data& data, const double* loss, const std::vector<double>& coefficients,
                     const std::vector<const double*>& rows, std::vector<double>& q, std::vector<double>& d) {
    const std::size_t n = q.size(), pushes = rows.size();
    if (pushes == 0) return kernels::advance(data.e.data(), data.beta.data(), loss, nullptr, q.data(), d.data(), n);
    if (pushes == 1)
        return kernels::advance_one_push(data.e.data(), data.beta.data(), loss, coefficients[0], rows[0], q.data(),
                                         d.data(), n);
    return kernels::advance_pushes(data.e.data(), data.beta.data(), loss, coefficients.data(), rows.data(), pushes,
                                   q.data(), d.data(), n);
}

TEST(Kernels, RowProductsInOnePassEqualOneDotEach) {
    std::mt19937_64 random(3);
    for (std::size_t n = 0; n < 200; n += (n < 40 ? 1 : 23)) {
        const Data data = random_data(random, n);
        std::vector<double> predicted(n);
        kernels::predict(data.e.data(), data.beta.data(), data.q.data(), data.d.data(), predicted.data(), n);
        for (std::size_t m = 1; m <= data.rows.size(); ++m) {
            std::vector<const double*> rows;
            for (std::size_t r = 0; r < m; ++r) rows.push_back(data.rows[r].data());
            std::vector<double> read(m), formed(m), separate(m);
            kernels::dot_rows(rows.data(), m, predicted.data(), n, read.data());
            kernels::predict_dot_rows(data.e.data(), data.beta.data(), data.q.data(), data.d.data(), rows.data(), m, n,
                                      formed.data());
            for (std::size_t r = 0; r < m; ++r) separate[r] = kernels::dot(rows[r], predicted.data(), n);
            EXPECT_TRUE(agree(read, separate)) << "n=" << n << " m=" << m;
            EXPECT_TRUE(agree(formed, separate)) << "n=" << n << " m=" << m;
        }
    }
}

// The envelope of a point (ContactScheduler::park) is one weighted sum of the two that the
// push weights take in one pass: the same sum to round-off (the compiler may fuse its
// multiply-adds, which it does not in the pair's loop).
TEST(Kernels, OneWeightedAbsSumEqualsThePairsFirst) {
    std::mt19937_64 random(5);
    for (std::size_t n = 0; n < 200; n += (n < 40 ? 1 : 23)) {
        const Data data = random_data(random, n);
        double first = 0.0, second = 0.0;
        kernels::weighted_abs_sums(data.beta.data(), data.e.data(), data.q.data(), n, first, second);
        EXPECT_NEAR(kernels::weighted_abs_sum(data.beta.data(), data.q.data(), n), first, 1e-14 * first) << "n=" << n;
    }
}

// Pushes on data's first m rows with random coefficients.
struct Pushes {
    std::vector<const double*> rows;
    std::vector<double> coefficients;
};
Pushes random_pushes(const Data& data, std::size_t m, std::mt19937_64& random) {
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    Pushes p;
    for (std::size_t r = 0; r < m; ++r) {
        p.rows.push_back(data.rows[r].data());
        p.coefficients.push_back(1e-3 * unit(random));
    }
    return p;
}

TEST(Kernels, PushesAddedInsideTheStepEqualAnImpulseVector) {
    std::mt19937_64 random(5);
    for (std::size_t n = 0; n < 200; n += (n < 40 ? 1 : 23)) {
        const Data data = random_data(random, n);
        for (std::size_t m = 1; m <= data.rows.size(); ++m) {
            const auto [rows, coefficients] = random_pushes(data, m, random);
            for (const double* loss : {static_cast<const double*>(nullptr), data.loss.data()}) {
                std::vector<double> impulse(n, 0.0), q1 = data.q, d1 = data.d, q2 = data.q, d2 = data.d;
                for (std::size_t r = 0; r < m; ++r) kernels::axpy(coefficients[r], rows[r], impulse.data(), n);
                const double by_vector =
                    kernels::advance(data.e.data(), data.beta.data(), loss, impulse.data(), q1.data(), d1.data(), n);
                const double inside = kernels::advance_pushes(data.e.data(), data.beta.data(), loss, coefficients.data(),
                                                              rows.data(), m, q2.data(), d2.data(), n);
                EXPECT_TRUE(agree(q1, q2) && agree(d1, d2)) << "n=" << n << " m=" << m;
                EXPECT_TRUE(agree(by_vector, inside)) << "n=" << n << " m=" << m;
            }
        }
    }
}

// A pass that steps the modes and forms products (advance_with_products, advance_with_pad_products).
using StepWithProducts = double (*)(const double*, const double*, const double*, const double*, const double* const*,
                                    std::size_t, const kernels::StepProducts&, double*, double*, std::size_t);

// `step` from data's state with 0 to most_pushes pushes, with and without losses, predicting at
// `counts` rows (data.rows from first_row on: the pushed rows first, then points that touch
// without a force), with and without a pickup: the same q, d and losses as the step alone, the
// next step's predictions as predict_dot gives them at that step (and as dot_rows gives them
// from the stored prediction), the pickup as dot gives it, within the stated tolerance.
void expect_the_separate_passes(StepWithProducts step, std::mt19937_64& random, const Data& data,
                                std::size_t most_pushes, std::size_t first_row, std::span<const std::size_t> counts) {
    const std::size_t n = data.q.size();
    std::vector<const double*> predict_rows;
    for (std::size_t r = first_row; r < data.rows.size() - 1; ++r) predict_rows.push_back(data.rows[r].data());
    const double* pickup = data.rows.back().data();
    for (std::size_t pushes = 0; pushes <= most_pushes; ++pushes) {
        const auto [rows, coefficients] = random_pushes(data, pushes, random);
        for (const double* loss : {static_cast<const double*>(nullptr), data.loss.data()}) {
            std::vector<double> q1 = data.q, d1 = data.d, stored(n);
            const double losses = separate_step(data, loss, coefficients, rows, q1, d1);
            kernels::predict(data.e.data(), data.beta.data(), q1.data(), d1.data(), stored.data(), n);
            for (std::size_t count : counts) {
                for (const double* observe : {static_cast<const double*>(nullptr), pickup}) {
                    std::vector<double> q2 = data.q, d2 = data.d, predicted(count, -1.0), separate(count), read(count);
                    double observed = -1.0;
                    kernels::StepProducts products;
                    products.predict_rows = predict_rows.data();
                    products.predict_count = count;
                    products.predicted = predicted.data();
                    products.observe_row = observe;
                    products.observed = &observed;
                    // The modal energy of q^{n+1} in the pass too, in every other case (each
                    // count with and without it, over the pickup's two cases).
                    double energy = -1.0;
                    const bool with_energy = (count + (observe != nullptr ? 1 : 0)) % 2 == 1;
                    if (with_energy) products.energy = &energy;
                    const double fused = step(data.e.data(), data.beta.data(), loss, coefficients.data(), rows.data(),
                                              pushes, products, q2.data(), d2.data(), n);
                    for (std::size_t r = 0; r < count; ++r)
                        separate[r] = kernels::predict_dot(data.e.data(), data.beta.data(), q1.data(), d1.data(),
                                                           predict_rows[r], n);
                    kernels::dot_rows(predict_rows.data(), count, stored.data(), n, read.data());
                    const std::string where = "n=" + std::to_string(n) + " pushes=" + std::to_string(pushes) +
                                              " predicted=" + std::to_string(count) + (loss ? " lossy" : "") +
                                              (observe ? " observed" : "");
                    ASSERT_TRUE(agree(q1, q2) && agree(d1, d2)) << where;
                    ASSERT_TRUE(agree(losses, fused)) << where;
                    ASSERT_TRUE(agree(predicted, separate)) << where;
                    ASSERT_TRUE(agree(predicted, read)) << where;
                    if (observe != nullptr) {
                        ASSERT_TRUE(agree(observed, kernels::dot(observe, q1.data(), n))) << where;
                    }
                    if (with_energy) {
                        const double separate_energy =
                            kernels::modal_energy(data.e.data(), data.beta.data(), q1.data(), d1.data(), n);
                        ASSERT_TRUE(agree(energy, separate_energy)) << where << " energy";
                    }
                }
            }
        }
    }
}

// The few rows of a fret or a bridge (more than 4 pushes: the separate passes inside).
TEST(Kernels, StepWithProductsEqualsTheSeparatePasses) {
    std::mt19937_64 random(7);
    const std::vector<std::size_t> counts = {0, 1, 2, 3, 4};
    for (std::size_t n = 0; n <= 1100; ++n) {
        const Data data = random_data(random, n);
        ASSERT_NO_FATAL_FAILURE(
            expect_the_separate_passes(kernels::advance_with_products, random, data, 6, 0, counts));
    }
}

// A finger's pad: up to 16 pushes and 16 predicted rows in the one pass.
TEST(Kernels, StepWithAPadsProductsEqualsTheSeparatePasses) {
    std::mt19937_64 random(11);
    const std::vector<std::size_t> counts = {0, 1, 5, 11, 16};
    for (std::size_t n = 0; n <= 1100; n += (n < 40 ? 1 : 61)) {
        const Data data = random_data(random, n, 18);
        ASSERT_NO_FATAL_FAILURE(
            expect_the_separate_passes(kernels::advance_with_pad_products, random, data, 16, 1, counts));
    }
}
// A free flight's end (jump_with_products): from any first jumped mode, lossless (e = 1) or
// lossy, with 0 to 6 rows, the same q, d, modal energy and row products as jump, modal_energy
// and dot, within the stated tolerance.
TEST(Kernels, FlightEndInOnePassEqualsTheSeparatePasses) {
    std::mt19937_64 random(13);
    constexpr std::size_t kMaps = 4, kRows = 6;
    for (std::size_t n = 0; n <= 1100; ++n) {
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
                const double energy = kernels::modal_energy(data.e.data(), data.beta.data(), q1.data(), d1.data(), n);
                for (std::size_t m = 0; m <= kRows; ++m) {
                    std::vector<double> q2 = data.q, d2 = data.d, fused(m, -1.0), separate(m);
                    const double fused_energy =
                        kernels::jump_with_products(map(0), map(1), map(2), map(3), first, data.e.data(),
                                                    data.beta.data(), rows.data(), m, q2.data(), d2.data(), n,
                                                    fused.data());
                    for (std::size_t r = 0; r < m; ++r) separate[r] = kernels::dot(rows[r], q1.data(), n);
                    const std::string where = "n=" + std::to_string(n) + " first=" + std::to_string(first) +
                                              " rows=" + std::to_string(m) + (lossless ? " lossless" : "");
                    ASSERT_TRUE(agree(q1, q2) && agree(d1, d2)) << where;
                    ASSERT_TRUE(agree(energy, fused_energy)) << where;
                    ASSERT_TRUE(agree(fused, separate)) << where;
                }
            }
        }
    }
}
}  // namespace
}  // namespace fretbuzz
