#include "fretbuzz/scheme/Kernels.hpp"

#include <algorithm>

// Both variants compute the same sums in the same order (no fused multiply-add
// contraction in ISO C++ mode), so results do not depend on the machine.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FRETBUZZ_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define FRETBUZZ_MULTIVERSION
#endif

namespace fretbuzz::kernels {

namespace {
constexpr std::size_t kLanes = 8;  // independent partial sums: enough to fill two AVX2 adders
}

FRETBUZZ_MULTIVERSION double dot(const double* a, const double* b, std::size_t n) {
    double partial[kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) partial[l] += a[j + l] * b[j + l];
    double sum = 0.0;
    for (; j < n; ++j) sum += a[j] * b[j];
    for (double p : partial) sum += p;
    return sum;
}

FRETBUZZ_MULTIVERSION void dot_current_previous(const double* row, const double* q, const double* d, std::size_t n,
                                                double& current, double& previous) {
    double now[kLanes] = {}, before[kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) {
            now[l] += row[j + l] * q[j + l];
            before[l] += row[j + l] * (q[j + l] - d[j + l]);
        }
    double c = 0.0, p = 0.0;
    for (; j < n; ++j) {
        c += row[j] * q[j];
        p += row[j] * (q[j] - d[j]);
    }
    for (std::size_t l = 0; l < kLanes; ++l) {
        c += now[l];
        p += before[l];
    }
    current = c;
    previous = p;
}

FRETBUZZ_MULTIVERSION void predict(const double* e, const double* beta, const double* q, const double* d, double* p,
                                   std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) p[j] = q[j] + (e[j] * d[j] - beta[j] * q[j]);
}

namespace {
// One variant per case so each loop is branch-free and vectorises.
template <bool Pushed, bool Lossy>
inline double advance_variant(const double* __restrict e, const double* __restrict beta, const double* __restrict loss,
                              const double* __restrict impulse, double* __restrict q, double* __restrict d,
                              std::size_t n) {
    double partial[kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) {
            const std::size_t k = j + l;
            double next = e[k] * d[k] - beta[k] * q[k];
            if constexpr (Pushed) next += impulse[k];
            if constexpr (Lossy) {
                const double span = next + d[k];  // q^{n+1} - q^{n-1}
                partial[l] += loss[k] * span * span;
            }
            q[k] += next;
            d[k] = next;
        }
    double sum = 0.0;
    for (; j < n; ++j) {
        double next = e[j] * d[j] - beta[j] * q[j];
        if constexpr (Pushed) next += impulse[j];
        if constexpr (Lossy) sum += loss[j] * (next + d[j]) * (next + d[j]);
        q[j] += next;
        d[j] = next;
    }
    for (double p : partial) sum += p;
    return sum;
}
}  // namespace

FRETBUZZ_MULTIVERSION double advance(const double* e, const double* beta, const double* loss, const double* impulse,
                                     double* q, double* d, std::size_t n) {
    if (impulse != nullptr)
        return loss != nullptr ? advance_variant<true, true>(e, beta, loss, impulse, q, d, n)
                               : advance_variant<true, false>(e, beta, loss, impulse, q, d, n);
    return loss != nullptr ? advance_variant<false, true>(e, beta, loss, impulse, q, d, n)
                           : advance_variant<false, false>(e, beta, loss, impulse, q, d, n);
}

namespace {
// Up to this many rows share one pass over the modal state (4 x 8 partial sums fit the registers).
constexpr std::size_t kRowsPerPass = 4;

template <std::size_t Rows>
inline void predicted_dots_group(const double* __restrict e, const double* __restrict beta, const double* __restrict q,
                                 const double* __restrict d, const double* const* rows, double* out, std::size_t n) {
    double partial[Rows][kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        double p[kLanes];
        for (std::size_t l = 0; l < kLanes; ++l) p[l] = q[j + l] + (e[j + l] * d[j + l] - beta[j + l] * q[j + l]);
        for (std::size_t r = 0; r < Rows; ++r)
            for (std::size_t l = 0; l < kLanes; ++l) partial[r][l] += rows[r][j + l] * p[l];
    }
    double sum[Rows] = {};
    for (; j < n; ++j) {
        const double p = q[j] + (e[j] * d[j] - beta[j] * q[j]);
        for (std::size_t r = 0; r < Rows; ++r) sum[r] += rows[r][j] * p;
    }
    for (std::size_t r = 0; r < Rows; ++r) {
        for (double x : partial[r]) sum[r] += x;
        out[r] = sum[r];
    }
}
}  // namespace

FRETBUZZ_MULTIVERSION void predicted_dots(const double* e, const double* beta, const double* q, const double* d,
                                          const double* const* rows, std::size_t count, double* out, std::size_t n) {
    for (std::size_t first = 0; first < count; first += kRowsPerPass) {
        const double* const* r = rows + first;
        double* o = out + first;
        switch (std::min(kRowsPerPass, count - first)) {
            case 1: predicted_dots_group<1>(e, beta, q, d, r, o, n); break;
            case 2: predicted_dots_group<2>(e, beta, q, d, r, o, n); break;
            case 3: predicted_dots_group<3>(e, beta, q, d, r, o, n); break;
            default: predicted_dots_group<4>(e, beta, q, d, r, o, n); break;
        }
    }
}

namespace {
// advance() with the impulse sum_r c_r rows_r formed on the fly, term by term in the order
// of the rows (as axpy into a zeroed vector would), and an optional probe dot of q^{n+1}.
template <bool Lossy, bool Probed>
inline double advance_rows_variant(const double* __restrict e, const double* __restrict beta,
                                   const double* __restrict loss, const double* const* rows,
                                   const double* __restrict coefficients, std::size_t count,
                                   const double* __restrict probe, double& probed, double* __restrict q,
                                   double* __restrict d, std::size_t n) {
    double partial[kLanes] = {}, at_probe[kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        double push[kLanes];
        for (std::size_t l = 0; l < kLanes; ++l) push[l] = coefficients[0] * rows[0][j + l];
        for (std::size_t r = 1; r < count; ++r)
            for (std::size_t l = 0; l < kLanes; ++l) push[l] += coefficients[r] * rows[r][j + l];
        for (std::size_t l = 0; l < kLanes; ++l) {
            const std::size_t k = j + l;
            const double next = (e[k] * d[k] - beta[k] * q[k]) + push[l];
            if constexpr (Lossy) {
                const double span = next + d[k];
                partial[l] += loss[k] * span * span;
            }
            q[k] += next;
            d[k] = next;
            if constexpr (Probed) at_probe[l] += probe[k] * q[k];
        }
    }
    double sum = 0.0, probe_sum = 0.0;
    for (; j < n; ++j) {
        double push = coefficients[0] * rows[0][j];
        for (std::size_t r = 1; r < count; ++r) push += coefficients[r] * rows[r][j];
        const double next = (e[j] * d[j] - beta[j] * q[j]) + push;
        if constexpr (Lossy) sum += loss[j] * (next + d[j]) * (next + d[j]);
        q[j] += next;
        d[j] = next;
        if constexpr (Probed) probe_sum += probe[j] * q[j];
    }
    for (double p : partial) sum += p;
    if constexpr (Probed) {
        for (double p : at_probe) probe_sum += p;
        probed = probe_sum;
    }
    return sum;
}
}  // namespace

FRETBUZZ_MULTIVERSION double advance_rows(const double* e, const double* beta, const double* loss,
                                          const double* const* rows, const double* coefficients, std::size_t count,
                                          double* q, double* d, std::size_t n, const double* probe, double* probed) {
    double unused = 0.0;
    double& out = probed != nullptr ? *probed : unused;
    if (count == 0) {
        const double losses = advance(e, beta, loss, nullptr, q, d, n);
        if (probe != nullptr) out = dot(probe, q, n);
        return losses;
    }
    if (probe != nullptr)
        return loss != nullptr ? advance_rows_variant<true, true>(e, beta, loss, rows, coefficients, count, probe, out, q, d, n)
                               : advance_rows_variant<false, true>(e, beta, loss, rows, coefficients, count, probe, out, q, d, n);
    return loss != nullptr ? advance_rows_variant<true, false>(e, beta, loss, rows, coefficients, count, probe, out, q, d, n)
                           : advance_rows_variant<false, false>(e, beta, loss, rows, coefficients, count, probe, out, q, d, n);
}

FRETBUZZ_MULTIVERSION double modal_energy(const double* e, const double* beta, const double* q, const double* d,
                                           std::size_t n) {
    double partial[kLanes] = {};
    std::size_t j = 0;
    auto term = [&](std::size_t k) { return 0.5 * (1.0 + e[k]) * d[k] * d[k] + beta[k] * q[k] * (q[k] - d[k]); };
    for (; j + kLanes <= n; j += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) partial[l] += term(j + l);
    double sum = 0.0;
    for (; j < n; ++j) sum += term(j);
    for (double p : partial) sum += p;
    return sum;
}

FRETBUZZ_MULTIVERSION void free_amplitudes(const double* aq, const double* ad, const double* q, const double* d,
                                           double* a, std::size_t n) {
    // The argument is never negative: __builtin_sqrt lets the loop vectorise (no errno path).
    for (std::size_t j = 0; j < n; ++j) {
        const double c = aq[j] * q[j] + ad[j] * d[j];
        a[j] = __builtin_sqrt(q[j] * q[j] + c * c);
    }
}

FRETBUZZ_MULTIVERSION double sum(const double* x, std::size_t n) {
    double partial[kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) partial[l] += x[j + l];
    double total = 0.0;
    for (; j < n; ++j) total += x[j];
    for (double p : partial) total += p;
    return total;
}

FRETBUZZ_MULTIVERSION void axpy(double c, const double* x, double* y, std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) y[j] += c * x[j];
}

}  // namespace fretbuzz::kernels
