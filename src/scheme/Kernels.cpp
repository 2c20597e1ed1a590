#include "fretbuzz/scheme/Kernels.hpp"

// Both variants compute the same sums in the same order. GCC contracts a * b + c into a
// fused multiply-add in C++ even in ISO mode (-ffp-contract=fast is its C++ default), so
// the AVX2 variant may differ from the baseline one in the last bits.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FRETBUZZ_MULTIVERSION __attribute__((target_clones("default", "arch=x86-64-v3")))
#else
#define FRETBUZZ_MULTIVERSION
#endif

namespace fretbuzz::kernels {

namespace {
constexpr std::size_t kLanes = 8;  // independent partial sums: enough to fill two AVX2 adders
// A dot product's lanes. 16 (four AVX2 chains instead of two) was measured no faster in the
// engine: its scalar remainder grows, and the sums would change in the last bits.
constexpr std::size_t kDotLanes = kLanes;
}

FRETBUZZ_MULTIVERSION double dot(const double* a, const double* b, std::size_t n) {
    double partial[kDotLanes] = {};
    std::size_t j = 0;
    for (; j + kDotLanes <= n; j += kDotLanes)
        for (std::size_t l = 0; l < kDotLanes; ++l) partial[l] += a[j + l] * b[j + l];
    double sum = 0.0;
    for (; j < n; ++j) sum += a[j] * b[j];
    for (double p : partial) sum += p;
    return sum;
}

FRETBUZZ_MULTIVERSION double predict_dot(const double* e, const double* beta, const double* q, const double* d,
                                         const double* row, std::size_t n) {
    // The same terms and partial sums as predict followed by dot.
    double partial[kDotLanes] = {};
    std::size_t j = 0;
    for (; j + kDotLanes <= n; j += kDotLanes)
        for (std::size_t l = 0; l < kDotLanes; ++l) {
            const std::size_t k = j + l;
            partial[l] += row[k] * (q[k] + (e[k] * d[k] - beta[k] * q[k]));
        }
    double sum = 0.0;
    for (; j < n; ++j) sum += row[j] * (q[j] + (e[j] * d[j] - beta[j] * q[j]));
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
// Impulse: an array (impulse[k]), or one row times c (c row[k]), or nothing.
enum class Push { none, array, row };

template <Push Pushed, bool Lossy>
inline double advance_variant(const double* __restrict e, const double* __restrict beta, const double* __restrict loss,
                              const double* __restrict impulse, double c, double* __restrict q, double* __restrict d,
                              std::size_t n) {
    double partial[kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) {
            const std::size_t k = j + l;
            double next = e[k] * d[k] - beta[k] * q[k];
            if constexpr (Pushed == Push::array) next += impulse[k];
            if constexpr (Pushed == Push::row) next += c * impulse[k];
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
        if constexpr (Pushed == Push::array) next += impulse[j];
        if constexpr (Pushed == Push::row) next += c * impulse[j];
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
        return loss != nullptr ? advance_variant<Push::array, true>(e, beta, loss, impulse, 0.0, q, d, n)
                               : advance_variant<Push::array, false>(e, beta, loss, impulse, 0.0, q, d, n);
    return loss != nullptr ? advance_variant<Push::none, true>(e, beta, loss, impulse, 0.0, q, d, n)
                           : advance_variant<Push::none, false>(e, beta, loss, impulse, 0.0, q, d, n);
}

FRETBUZZ_MULTIVERSION double advance_one_push(const double* e, const double* beta, const double* loss, double c,
                                              const double* row, double* q, double* d, std::size_t n) {
    return loss != nullptr ? advance_variant<Push::row, true>(e, beta, loss, row, c, q, d, n)
                           : advance_variant<Push::row, false>(e, beta, loss, row, c, q, d, n);
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

FRETBUZZ_MULTIVERSION void weighted_abs_sums(const double* w, const double* s, const double* x, std::size_t n,
                                             double& by_w, double& by_s) {
    double pw[kLanes] = {}, ps[kLanes] = {};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes)
        for (std::size_t l = 0; l < kLanes; ++l) {
            const double a = __builtin_fabs(x[j + l]);
            pw[l] += w[j + l] * a;
            ps[l] += s[j + l] * a;
        }
    double tw = 0.0, ts = 0.0;
    for (; j < n; ++j) {
        tw += w[j] * __builtin_fabs(x[j]);
        ts += s[j] * __builtin_fabs(x[j]);
    }
    for (std::size_t l = 0; l < kLanes; ++l) {
        tw += pw[l];
        ts += ps[l];
    }
    by_w = tw;
    by_s = ts;
}

FRETBUZZ_MULTIVERSION void axpy(double c, const double* x, double* y, std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) y[j] += c * x[j];
}

}  // namespace fretbuzz::kernels
