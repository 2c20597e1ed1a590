#include "fretbuzz/scheme/Kernels.hpp"

#include <algorithm>

#include "Multiversion.hpp"

#if defined(__GNUC__)
// GCC and Clang note that 32-byte vectors pass differently with and without AVX: the helpers that
// take them are always inlined, so no call passes one.
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

// The helpers below must be compiled inside each variant (an out-of-line copy would be the
// baseline one, called by both).
#if defined(__GNUC__)
#define FRETBUZZ_INLINE [[gnu::always_inline]] inline
#else
#define FRETBUZZ_INLINE inline
#endif

namespace fretbuzz::kernels {

namespace {
// Eight independent partial sums (enough to fill two AVX2 adders), held as two 4-lane
// vectors: lanes 0-3 and 4-7. Written with vector types because GCC vectorises the
// equivalent scalar loops over 8 lanes with heavy shuffles (vunpcklpd/vpermpd) for some
// of them; these give plain loads, multiplies and adds. A dot product's lanes: 16 (four
// AVX2 chains instead of two) was measured no faster in the engine (its scalar remainder grows).
typedef double v4 __attribute__((vector_size(32)));
constexpr std::size_t kLanes = 8;

FRETBUZZ_INLINE v4 load(const double* p) {
    v4 v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}
FRETBUZZ_INLINE void store(double* p, const v4& v) { __builtin_memcpy(p, &v, sizeof v); }

// The remainder's sum, then lanes 0 to 7 in order (as an array of 8 partial sums would).
FRETBUZZ_INLINE double fold(double sum, const v4& lo, const v4& hi) {
    for (int l = 0; l < 4; ++l) sum += lo[l];
    for (int l = 0; l < 4; ++l) sum += hi[l];
    return sum;
}

// p_j = q_j + (e_j d_j - beta_j q_j): the free prediction, the same expression everywhere.
template <class T>
FRETBUZZ_INLINE T predicted(const T& e, const T& beta, const T& q, const T& d) {
    return q + (e * d - beta * q);
}

// out[r] = sum_j rows[r][j] x_j for r < M, x read once; with Predict, x is the prediction
// formed from (e, beta, q, d) on the fly. Each sum is the one dot (or predict then dot) gives.
template <std::size_t M, bool Predict>
FRETBUZZ_INLINE void row_products(const double* const* rows, const double* x, const double* e, const double* beta,
                         const double* q, const double* d, std::size_t n, double* out) {
    v4 lo[M], hi[M];
    for (std::size_t r = 0; r < M; ++r) lo[r] = hi[r] = v4{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        v4 x_lo, x_hi;
        if constexpr (Predict) {
            x_lo = predicted(load(e + j), load(beta + j), load(q + j), load(d + j));
            x_hi = predicted(load(e + j + 4), load(beta + j + 4), load(q + j + 4), load(d + j + 4));
        } else {
            x_lo = load(x + j);
            x_hi = load(x + j + 4);
        }
        for (std::size_t r = 0; r < M; ++r) {
            lo[r] += load(rows[r] + j) * x_lo;
            hi[r] += load(rows[r] + j + 4) * x_hi;
        }
    }
    double tail[M] = {};
    for (; j < n; ++j) {
        const double xj = Predict ? predicted(e[j], beta[j], q[j], d[j]) : x[j];
        for (std::size_t r = 0; r < M; ++r) tail[r] += rows[r][j] * xj;
    }
    for (std::size_t r = 0; r < M; ++r) out[r] = fold(tail[r], lo[r], hi[r]);
}

template <bool Predict>
FRETBUZZ_INLINE void row_products_upto4(const double* const* rows, std::size_t m, const double* x, const double* e,
                               const double* beta, const double* q, const double* d, std::size_t n, double* out) {
    switch (m) {
        case 1: row_products<1, Predict>(rows, x, e, beta, q, d, n, out); break;
        case 2: row_products<2, Predict>(rows, x, e, beta, q, d, n, out); break;
        case 3: row_products<3, Predict>(rows, x, e, beta, q, d, n, out); break;
        default: row_products<4, Predict>(rows, x, e, beta, q, d, n, out); break;
    }
}
}  // namespace

FRETBUZZ_MULTIVERSION double dot(const double* a, const double* b, std::size_t n) {
    double out;
    row_products<1, false>(&a, b, nullptr, nullptr, nullptr, nullptr, n, &out);
    return out;
}

FRETBUZZ_MULTIVERSION void dot_rows(const double* const* rows, std::size_t m, const double* x, std::size_t n,
                                    double* out) {
    for (std::size_t r = 0; r < m; r += kMaxRowsPerPass)
        row_products_upto4<false>(rows + r, std::min(m - r, kMaxRowsPerPass), x, nullptr, nullptr, nullptr, nullptr, n,
                                  out + r);
}

FRETBUZZ_MULTIVERSION double predict_dot(const double* e, const double* beta, const double* q, const double* d,
                                         const double* row, std::size_t n) {
    double out;
    row_products<1, true>(&row, nullptr, e, beta, q, d, n, &out);
    return out;
}

FRETBUZZ_MULTIVERSION void predict_dot_rows(const double* e, const double* beta, const double* q, const double* d,
                                            const double* const* rows, std::size_t m, std::size_t n, double* out) {
    for (std::size_t r = 0; r < m; r += kMaxRowsPerPass)
        row_products_upto4<true>(rows + r, std::min(m - r, kMaxRowsPerPass), nullptr, e, beta, q, d, n, out + r);
}

// Runs once per woken point, not once per step.
FRETBUZZ_MULTIVERSION void dot_current_previous(const double* row, const double* q, const double* d, std::size_t n,
                                                double& current, double& previous) {
    v4 now_lo{}, now_hi{}, before_lo{}, before_hi{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        const v4 r_lo = load(row + j), r_hi = load(row + j + 4), q_lo = load(q + j), q_hi = load(q + j + 4);
        now_lo += r_lo * q_lo;
        now_hi += r_hi * q_hi;
        before_lo += r_lo * (q_lo - load(d + j));
        before_hi += r_hi * (q_hi - load(d + j + 4));
    }
    double c = 0.0, p = 0.0;
    for (; j < n; ++j) {
        c += row[j] * q[j];
        p += row[j] * (q[j] - d[j]);
    }
    current = fold(c, now_lo, now_hi);
    previous = fold(p, before_lo, before_hi);
}

FRETBUZZ_MULTIVERSION void predict(const double* e, const double* beta, const double* q, const double* d, double* p,
                                   std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) p[j] = predicted(e[j], beta[j], q[j], d[j]);
}

namespace {
// One variant per case so each loop is branch-free and vectorises.
// Impulse: an array (impulse[k]), or one row times c (c row[k]), or a sum of rows
// (c[0] row0[k] + c[1] row1[k] + ..., formed as axpy would form it in a zeroed array), or nothing.
enum class Push { none, array, row, rows };

// One mode of the scalar remainder: d_k <- e_k d_k - beta_k q_k + push, q_k += d_k, the loss
// term added to sum. Returns the new d_k.
template <Push Pushed, bool Lossy>
FRETBUZZ_INLINE double step_one(const double* e, const double* beta, const double* loss, const double* impulse, double c,
                                const double* const* rows, const double* coefficients, std::size_t m, double* q,
                                double* d, std::size_t k, double& sum) {
    double next = e[k] * d[k] - beta[k] * q[k];
    if constexpr (Pushed == Push::array) next += impulse[k];
    if constexpr (Pushed == Push::row) next += c * impulse[k];
    if constexpr (Pushed == Push::rows) {
        double push = coefficients[0] * rows[0][k];
        for (std::size_t r = 1; r < m; ++r) push += coefficients[r] * rows[r][k];
        next += push;
    }
    if constexpr (Lossy) {
        const double span = next + d[k];
        sum += loss[k] * span * span;
    }
    q[k] += next;
    d[k] = next;
    return next;
}

// Four modes' free step plus their pushes (what step_one does for one mode), the loss term
// of the step added to `partial`. Shared by the plain step and the step with products.
template <Push Pushed, bool Lossy>
FRETBUZZ_INLINE v4 lane_step(v4 ek, v4 bk, v4 qk, v4 dk, const double* __restrict loss, const double* __restrict impulse,
                             double c, const double* const* rows, const double* coefficients, std::size_t m,
                             std::size_t k, v4& partial) {
    v4 next = ek * dk - bk * qk;
    if constexpr (Pushed == Push::array) next += load(impulse + k);
    if constexpr (Pushed == Push::row) next += c * load(impulse + k);
    if constexpr (Pushed == Push::rows) {
        v4 push = coefficients[0] * load(rows[0] + k);
        for (std::size_t r = 1; r < m; ++r) push += coefficients[r] * load(rows[r] + k);
        next += push;
    }
    if constexpr (Lossy) {
        const v4 span = next + dk;  // q^{n+1} - q^{n-1}
        partial += load(loss + k) * span * span;
    }
    return next;
}

// Rows: M of them (a compile-time count, unrolled with its coefficients in registers), or m if M is 0.
template <Push Pushed, bool Lossy, std::size_t M = 0>
FRETBUZZ_INLINE double advance_variant(const double* __restrict e, const double* __restrict beta, const double* __restrict loss,
                              const double* __restrict impulse, double c, const double* const* rows,
                              const double* coefficients, std::size_t m, double* __restrict q, double* __restrict d,
                              std::size_t n) {
    if constexpr (M != 0) m = M;
    v4 partial_lo{}, partial_hi{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        for (std::size_t h = 0; h < kLanes; h += 4) {
            const std::size_t k = j + h;
            const v4 qk = load(q + k);
            const v4 next = lane_step<Pushed, Lossy>(load(e + k), load(beta + k), qk, load(d + k), loss, impulse, c, rows,
                                                     coefficients, m, k, h == 0 ? partial_lo : partial_hi);
            store(q + k, qk + next);
            store(d + k, next);
        }
    }
    double sum = 0.0;
    for (; j < n; ++j) step_one<Pushed, Lossy>(e, beta, loss, impulse, c, rows, coefficients, m, q, d, j, sum);
    return Lossy ? fold(sum, partial_lo, partial_hi) : 0.0;
}

template <std::size_t M>
FRETBUZZ_INLINE double advance_rows(const double* e, const double* beta, const double* loss, const double* coefficients,
                                    const double* const* rows, std::size_t m, double* q, double* d, std::size_t n) {
    return loss != nullptr ? advance_variant<Push::rows, true, M>(e, beta, loss, nullptr, 0.0, rows, coefficients, m, q, d, n)
                           : advance_variant<Push::rows, false, M>(e, beta, loss, nullptr, 0.0, rows, coefficients, m, q, d, n);
}
}  // namespace

FRETBUZZ_MULTIVERSION double advance(const double* e, const double* beta, const double* loss, const double* impulse,
                                     double* q, double* d, std::size_t n) {
    if (impulse != nullptr)
        return loss != nullptr ? advance_variant<Push::array, true>(e, beta, loss, impulse, 0.0, nullptr, nullptr, 0, q, d, n)
                               : advance_variant<Push::array, false>(e, beta, loss, impulse, 0.0, nullptr, nullptr, 0, q, d, n);
    return loss != nullptr ? advance_variant<Push::none, true>(e, beta, loss, impulse, 0.0, nullptr, nullptr, 0, q, d, n)
                           : advance_variant<Push::none, false>(e, beta, loss, impulse, 0.0, nullptr, nullptr, 0, q, d, n);
}

FRETBUZZ_MULTIVERSION double advance_one_push(const double* e, const double* beta, const double* loss, double c,
                                              const double* row, double* q, double* d, std::size_t n) {
    return loss != nullptr ? advance_variant<Push::row, true>(e, beta, loss, row, c, nullptr, nullptr, 0, q, d, n)
                           : advance_variant<Push::row, false>(e, beta, loss, row, c, nullptr, nullptr, 0, q, d, n);
}

FRETBUZZ_MULTIVERSION double advance_pushes(const double* e, const double* beta, const double* loss,
                                            const double* coefficients, const double* const* rows, std::size_t m,
                                            double* q, double* d, std::size_t n) {
    // The usual few points of a fret or a bridge: unrolled. (No lambda here: it would be
    // compiled outside this variant.)
    switch (m) {
        case 2: return advance_rows<2>(e, beta, loss, coefficients, rows, m, q, d, n);
        case 3: return advance_rows<3>(e, beta, loss, coefficients, rows, m, q, d, n);
        case 4: return advance_rows<4>(e, beta, loss, coefficients, rows, m, q, d, n);
        case 5: return advance_rows<5>(e, beta, loss, coefficients, rows, m, q, d, n);
        case 6: return advance_rows<6>(e, beta, loss, coefficients, rows, m, q, d, n);
        default: return advance_rows<0>(e, beta, loss, coefficients, rows, m, q, d, n);
    }
}

namespace {
// One mode's term of modal_energy, the same expression in every kernel that forms it.
template <class T>
FRETBUZZ_INLINE T energy_term(const T& e, const T& beta, const T& q, const T& d) {
    return 0.5 * (1.0 + e) * d * d + beta * q * (q - d);
}

// advance_variant with, in the same pass, the products of q^{n+1} that the next step and the
// caller read: P rows with the next step's free prediction (formed from q^{n+1} and
// q^{n+1} - q^n as predict_dot forms it from memory) and O rows with q^{n+1} itself (as dot).
// Each sum has the lanes and the order of predict_dot's or dot's.
template <Push Pushed, bool Lossy, std::size_t P, std::size_t O, std::size_t M, bool E>
FRETBUZZ_INLINE double advance_products(const double* __restrict e, const double* __restrict beta,
                                        const double* __restrict loss, double c, const double* row,
                                        const double* coefficients, const double* const* rows, std::size_t m,
                                        const StepProducts& products, double* __restrict q, double* __restrict d,
                                        std::size_t n) {
    m = M;  // unrolled, the coefficients in registers
    constexpr std::size_t R = P + O;
    constexpr std::size_t kSize = R == 0 ? 1 : R;  // no zero-size arrays
    const double* out_rows[kSize];
    for (std::size_t r = 0; r < P; ++r) out_rows[r] = products.predict_rows[r];
    if constexpr (O == 1) out_rows[P] = products.observe_row;
    v4 lo[kSize], hi[kSize];
    for (std::size_t r = 0; r < R; ++r) lo[r] = hi[r] = v4{};
    v4 partial_lo{}, partial_hi{};
    v4 energy_lo{}, energy_hi{};  // modal_energy's lanes
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        for (std::size_t h = 0; h < kLanes; h += 4) {
            const std::size_t k = j + h;
            const v4 ek = load(e + k), bk = load(beta + k), qk = load(q + k);
            const v4 next = lane_step<Pushed, Lossy>(ek, bk, qk, load(d + k), loss, row, c, rows, coefficients, m, k,
                                                     h == 0 ? partial_lo : partial_hi);
            const v4 q_next = qk + next;
            store(q + k, q_next);
            store(d + k, next);
            if constexpr (E) (h == 0 ? energy_lo : energy_hi) += energy_term(ek, bk, q_next, next);
            if constexpr (P != 0) {
                const v4 x = predicted(ek, bk, q_next, next);
                for (std::size_t r = 0; r < P; ++r) (h == 0 ? lo : hi)[r] += load(out_rows[r] + k) * x;
            }
            for (std::size_t r = P; r < R; ++r) (h == 0 ? lo : hi)[r] += load(out_rows[r] + k) * q_next;
        }
    }
    double sum = 0.0;
    double tail[kSize] = {};
    [[maybe_unused]] const std::size_t rest = j;
    for (; j < n; ++j) {
        const double next = step_one<Pushed, Lossy>(e, beta, loss, row, c, rows, coefficients, m, q, d, j, sum);
        const double q_next = q[j];
        double x = 0.0;
        if constexpr (P != 0) x = predicted(e[j], beta[j], q_next, next);
        for (std::size_t r = 0; r < R; ++r) tail[r] += out_rows[r][j] * (r < P ? x : q_next);
    }
    for (std::size_t r = 0; r < P; ++r) products.predicted[r] = fold(tail[r], lo[r], hi[r]);
    if constexpr (O == 1) *products.observed = fold(tail[P], lo[P], hi[P]);
    if constexpr (E) {  // the remainder as modal_energy sums it
        double energy = 0.0;
        for (std::size_t k = rest; k < n; ++k) energy += energy_term(e[k], beta[k], q[k], d[k]);
        *products.energy = fold(energy, energy_lo, energy_hi);
    }
    return Lossy ? fold(sum, partial_lo, partial_hi) : 0.0;
}

template <Push Pushed, std::size_t P, std::size_t O, bool E, std::size_t M = 1>
FRETBUZZ_INLINE double advance_products_lossy(const double* e, const double* beta, const double* loss, double c,
                                              const double* row, const double* coefficients, const double* const* rows,
                                              std::size_t m, const StepProducts& products, double* q, double* d,
                                              std::size_t n) {
    return loss != nullptr
               ? advance_products<Pushed, true, P, O, M, E>(e, beta, loss, c, row, coefficients, rows, m, products, q, d, n)
               : advance_products<Pushed, false, P, O, M, E>(e, beta, loss, c, row, coefficients, rows, m, products, q, d, n);
}

template <std::size_t P, std::size_t O, bool E>
FRETBUZZ_INLINE double advance_products_pushed(const double* e, const double* beta, const double* loss,
                                               const double* coefficients, const double* const* rows, std::size_t m,
                                               const StepProducts& products, double* q, double* d, std::size_t n) {
    if (m == 0)
        return advance_products_lossy<Push::none, P, O, E>(e, beta, loss, 0.0, nullptr, nullptr, nullptr, 0, products, q, d, n);
    if (m == 1)  // as advance_one_push: c row_j added by one multiply-add
        return advance_products_lossy<Push::row, P, O, E>(e, beta, loss, coefficients[0], rows[0], nullptr, nullptr, 0,
                                                       products, q, d, n);
    if (m == 2)
        return advance_products_lossy<Push::rows, P, O, E, 2>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
    if (m == 3)
        return advance_products_lossy<Push::rows, P, O, E, 3>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
    return advance_products_lossy<Push::rows, P, O, E, 4>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
}

template <std::size_t O, bool E>
FRETBUZZ_INLINE double advance_products_counted(const double* e, const double* beta, const double* loss,
                                                const double* coefficients, const double* const* rows, std::size_t m,
                                                const StepProducts& products, double* q, double* d, std::size_t n) {
    switch (products.predict_count) {
        case 0: return advance_products_pushed<0, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        case 1: return advance_products_pushed<1, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        case 2: return advance_products_pushed<2, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        case 3: return advance_products_pushed<3, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        default: return advance_products_pushed<4, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
    }
}

// advance_products with run-time counts, for a finger's pad: up to kMaxInlinePushes pushes (the
// pad and the fret it presses on) and up to kMaxForecastRows product rows (the same points, at
// the next step). The pushes take the form advance_pushes gives them (M as it picks); each
// product accumulates as predict_dot or dot does, in an array instead of registers.
template <Push Pushed, bool Lossy, std::size_t M>
FRETBUZZ_INLINE double advance_many_products(const double* __restrict e, const double* __restrict beta,
                                             const double* __restrict loss, double c, const double* row,
                                             const double* coefficients, const double* const* rows, std::size_t m,
                                             const StepProducts& products, double* __restrict q, double* __restrict d,
                                             std::size_t n) {
    if constexpr (M != 0) m = M;
    constexpr std::size_t kMost = kMaxForecastRows + 1;
    const std::size_t P = products.predict_count;
    const std::size_t R = P + (products.observe_row != nullptr ? 1 : 0);
    const double* out_rows[kMost];
    for (std::size_t r = 0; r < P; ++r) out_rows[r] = products.predict_rows[r];
    if (R > P) out_rows[P] = products.observe_row;
    v4 lo[kMost], hi[kMost];
    for (std::size_t r = 0; r < R; ++r) lo[r] = hi[r] = v4{};
    v4 partial_lo{}, partial_hi{};
    // Blocks of modes: the step of a block, its predictions kept in a small buffer, then each
    // row's products over the block with its two accumulators in registers (the same lanes and
    // the same order of terms as one pass: only the loads and stores of the sums are fewer).
    constexpr std::size_t kBlock = 8 * kLanes;
    v4 x_lanes[kBlock / 4], q_lanes[kBlock / 4];
    std::size_t j = 0;
    while (j + kLanes <= n) {
        const std::size_t end = std::min(n - (n - j) % kLanes, j + kBlock);
        std::size_t lanes = 0;
        for (std::size_t b = j; b < end; b += kLanes) {
            for (std::size_t h = 0; h < kLanes; h += 4) {
                const std::size_t k = b + h;
                const v4 ek = load(e + k), bk = load(beta + k), qk = load(q + k);
                const v4 next = lane_step<Pushed, Lossy>(ek, bk, qk, load(d + k), loss, row, c, rows, coefficients, m,
                                                         k, h == 0 ? partial_lo : partial_hi);
                const v4 q_next = qk + next;
                store(q + k, q_next);
                store(d + k, next);
                x_lanes[lanes] = predicted(ek, bk, q_next, next);
                q_lanes[lanes++] = q_next;
            }
        }
        for (std::size_t r = 0; r < R; ++r) {
            const v4* x = r < P ? x_lanes : q_lanes;
            const double* out = out_rows[r];
            v4 l = lo[r], h = hi[r];
            for (std::size_t b = j, a = 0; b < end; b += kLanes, a += 2) {
                l += load(out + b) * x[a];
                h += load(out + b + 4) * x[a + 1];
            }
            lo[r] = l;
            hi[r] = h;
        }
        j = end;
    }
    // The remainder: its step, then its products as predict_dot and dot form theirs (row_products'
    // own remainder, on the stored q^{n+1} and d^{n+1}), 4 rows at a time.
    double sum = 0.0;
    const std::size_t rest = j;
    for (; j < n; ++j) step_one<Pushed, Lossy>(e, beta, loss, row, c, rows, coefficients, m, q, d, j, sum);
    double tail[kMost] = {};
    const double* shifted[kMost];
    for (std::size_t r = 0; r < R; ++r) shifted[r] = out_rows[r] + rest;
    for (std::size_t r = 0; r < P; r += kMaxRowsPerPass)
        row_products_upto4<true>(shifted + r, std::min(P - r, kMaxRowsPerPass), nullptr, e + rest, beta + rest, q + rest,
                                 d + rest, n - rest, tail + r);
    if (R > P) row_products<1, false>(shifted + P, q + rest, nullptr, nullptr, nullptr, nullptr, n - rest, tail + P);
    for (std::size_t r = 0; r < P; ++r) products.predicted[r] = fold(tail[r], lo[r], hi[r]);
    if (R > P) *products.observed = fold(tail[P], lo[P], hi[P]);
    if (products.energy != nullptr) *products.energy = modal_energy(e, beta, q, d, n);  // (a pad's pass: rare)
    return Lossy ? fold(sum, partial_lo, partial_hi) : 0.0;
}

template <Push Pushed, std::size_t M = 0>
FRETBUZZ_INLINE double advance_many_lossy(const double* e, const double* beta, const double* loss, double c,
                                          const double* row, const double* coefficients, const double* const* rows,
                                          std::size_t m, const StepProducts& products, double* q, double* d,
                                          std::size_t n) {
    return loss != nullptr
               ? advance_many_products<Pushed, true, M>(e, beta, loss, c, row, coefficients, rows, m, products, q, d, n)
               : advance_many_products<Pushed, false, M>(e, beta, loss, c, row, coefficients, rows, m, products, q, d, n);
}

}  // namespace

FRETBUZZ_MULTIVERSION double advance_with_pad_products(const double* e, const double* beta, const double* loss,
                                                           const double* coefficients, const double* const* rows,
                                                           std::size_t m, const StepProducts& products, double* q,
                                                           double* d, std::size_t n) {
    switch (m) {  // advance_pushes' choice of form for each count
        case 0: return advance_many_lossy<Push::none>(e, beta, loss, 0.0, nullptr, nullptr, nullptr, 0, products, q, d, n);
        case 1:
            return advance_many_lossy<Push::row>(e, beta, loss, coefficients[0], rows[0], nullptr, nullptr, 0, products, q,
                                                 d, n);
        case 2: return advance_many_lossy<Push::rows, 2>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
        case 3: return advance_many_lossy<Push::rows, 3>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
        case 4: return advance_many_lossy<Push::rows, 4>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
        case 5: return advance_many_lossy<Push::rows, 5>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
        case 6: return advance_many_lossy<Push::rows, 6>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
        default: return advance_many_lossy<Push::rows>(e, beta, loss, 0.0, nullptr, coefficients, rows, m, products, q, d, n);
    }
}

FRETBUZZ_MULTIVERSION double advance_with_products(const double* e, const double* beta, const double* loss,
                                                   const double* coefficients, const double* const* rows, std::size_t m,
                                                   const StepProducts& products, double* q, double* d, std::size_t n) {
    if (m > kMaxRowsPerPass) {  // many pushes: the separate passes
        const double losses = advance_pushes(e, beta, loss, coefficients, rows, m, q, d, n);
        if (products.predict_count != 0)
            predict_dot_rows(e, beta, q, d, products.predict_rows, products.predict_count, n, products.predicted);
        if (products.observe_row != nullptr) *products.observed = dot(products.observe_row, q, n);
        if (products.energy != nullptr) *products.energy = modal_energy(e, beta, q, d, n);
        return losses;
    }
    if (products.energy != nullptr)
        return products.observe_row != nullptr
                   ? advance_products_counted<1, true>(e, beta, loss, coefficients, rows, m, products, q, d, n)
                   : advance_products_counted<0, true>(e, beta, loss, coefficients, rows, m, products, q, d, n);
    return products.observe_row != nullptr
               ? advance_products_counted<1, false>(e, beta, loss, coefficients, rows, m, products, q, d, n)
               : advance_products_counted<0, false>(e, beta, loss, coefficients, rows, m, products, q, d, n);
}

namespace {
// One mode's M-step jump (jump and jump_with_products): q += E_qq q + E_qd d, d <- E_dq q + (1 + E_dd) d.
template <class T>
FRETBUZZ_INLINE void jump_one(const T& qq, const T& qd, const T& dq, const T& dd, T& q, T& d) {
    const T q_next = q + (qq * q + qd * d);
    d = dq * q + (d + dd * d);
    q = q_next;
}

// jump_with_products for M rows (a compile-time count: its accumulators stay in registers).
template <std::size_t M>
FRETBUZZ_INLINE double jump_products(const double* __restrict qq, const double* __restrict qd,
                                     const double* __restrict dq, const double* __restrict dd, std::size_t first,
                                     const double* __restrict e, const double* __restrict beta,
                                     const double* const* rows, double* __restrict q, double* __restrict d,
                                     std::size_t n, double* out) {
    // Modes [first, jumped) one by one, the rest of [first, n) four at a time (or in the remainder).
    const std::size_t jumped = std::min(n, (first + 3) / 4 * 4);
    for (std::size_t k = first; k < jumped; ++k) jump_one(qq[k], qd[k], dq[k], dd[k], q[k], d[k]);
    v4 energy_lo{}, energy_hi{}, lo[M + 1], hi[M + 1];  // (M + 1: no empty array)
    for (std::size_t r = 0; r < M; ++r) lo[r] = hi[r] = v4{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        for (std::size_t h = 0; h < kLanes; h += 4) {
            const std::size_t k = j + h;
            v4 qk = load(q + k), dk = load(d + k);
            if (k >= jumped) {
                jump_one(load(qq + k), load(qd + k), load(dq + k), load(dd + k), qk, dk);
                store(q + k, qk);
                store(d + k, dk);
            }
            (h == 0 ? energy_lo : energy_hi) += energy_term(load(e + k), load(beta + k), qk, dk);
            for (std::size_t r = 0; r < M; ++r) (h == 0 ? lo[r] : hi[r]) += load(rows[r] + k) * qk;
        }
    }
    // The remainder as modal_energy and dot form theirs.
    for (std::size_t k = std::max(j, jumped); k < n; ++k) jump_one(qq[k], qd[k], dq[k], dd[k], q[k], d[k]);
    double energy = 0.0, tail[M + 1] = {};
    for (; j < n; ++j) {
        energy += energy_term(e[j], beta[j], q[j], d[j]);
        for (std::size_t r = 0; r < M; ++r) tail[r] += rows[r][j] * q[j];
    }
    for (std::size_t r = 0; r < M; ++r) out[r] = fold(tail[r], lo[r], hi[r]);
    return fold(energy, energy_lo, energy_hi);
}
}  // namespace

FRETBUZZ_MULTIVERSION double modal_energy(const double* e, const double* beta, const double* q, const double* d,
                                           std::size_t n) {
    v4 lo{}, hi{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        lo += energy_term(load(e + j), load(beta + j), load(q + j), load(d + j));
        hi += energy_term(load(e + j + 4), load(beta + j + 4), load(q + j + 4), load(d + j + 4));
    }
    double sum = 0.0;
    for (; j < n; ++j) sum += energy_term(e[j], beta[j], q[j], d[j]);
    return fold(sum, lo, hi);
}

FRETBUZZ_MULTIVERSION double jump_with_products(const double* qq, const double* qd, const double* dq, const double* dd,
                                                std::size_t first, const double* e, const double* beta,
                                                const double* const* rows, std::size_t m, double* q, double* d,
                                                std::size_t n, double* out) {
    switch (m) {
        case 0: return jump_products<0>(qq, qd, dq, dd, first, e, beta, rows, q, d, n, out);
        case 1: return jump_products<1>(qq, qd, dq, dd, first, e, beta, rows, q, d, n, out);
        case 2: return jump_products<2>(qq, qd, dq, dd, first, e, beta, rows, q, d, n, out);
        case 3: return jump_products<3>(qq, qd, dq, dd, first, e, beta, rows, q, d, n, out);
        case 4: return jump_products<4>(qq, qd, dq, dd, first, e, beta, rows, q, d, n, out);
        default: {  // more rows: their products in passes of their own
            const double energy = jump_products<0>(qq, qd, dq, dd, first, e, beta, rows, q, d, n, out);
            dot_rows(rows, m, q, n, out);
            return energy;
        }
    }
}

FRETBUZZ_MULTIVERSION void free_amplitudes(const double* aq, const double* ad, const double* q, const double* d,
                                           double* a, std::size_t n) {
    // The argument is never negative; the file is built without errno for sqrt, so the loop vectorises.
    for (std::size_t j = 0; j < n; ++j) {
        const double c = aq[j] * q[j] + ad[j] * d[j];
        a[j] = __builtin_sqrt(q[j] * q[j] + c * c);
    }
}

FRETBUZZ_MULTIVERSION double sum(const double* x, std::size_t n) {
    v4 lo{}, hi{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        lo += load(x + j);
        hi += load(x + j + 4);
    }
    double total = 0.0;
    for (; j < n; ++j) total += x[j];
    return fold(total, lo, hi);
}

namespace {
FRETBUZZ_INLINE v4 magnitude(const v4& x) {
    typedef long long bits4 __attribute__((vector_size(32)));
    bits4 b;
    __builtin_memcpy(&b, &x, sizeof b);
    b &= 0x7fffffffffffffffLL;  // the sign bit cleared: |x| in every lane
    v4 out;
    __builtin_memcpy(&out, &b, sizeof out);
    return out;
}
}  // namespace

// Vector types, as dot's: GCC vectorised the plain loops over 8 lanes with shuffles, four
// times slower (the speed bound's growth after a flat obstacle's impulse is one of these).
FRETBUZZ_MULTIVERSION double weighted_abs_sum(const double* w, const double* x, std::size_t n) {
    v4 lo{}, hi{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        lo += load(w + j) * magnitude(load(x + j));
        hi += load(w + j + 4) * magnitude(load(x + j + 4));
    }
    double total = 0.0;
    for (; j < n; ++j) total += w[j] * __builtin_fabs(x[j]);
    return fold(total, lo, hi);
}

FRETBUZZ_MULTIVERSION void weighted_abs_sums(const double* w, const double* s, const double* x, std::size_t n,
                                             double& by_w, double& by_s) {
    v4 w_lo{}, w_hi{}, s_lo{}, s_hi{};
    std::size_t j = 0;
    for (; j + kLanes <= n; j += kLanes) {
        const v4 a_lo = magnitude(load(x + j)), a_hi = magnitude(load(x + j + 4));
        w_lo += load(w + j) * a_lo;
        w_hi += load(w + j + 4) * a_hi;
        s_lo += load(s + j) * a_lo;
        s_hi += load(s + j + 4) * a_hi;
    }
    double tw = 0.0, ts = 0.0;
    for (; j < n; ++j) {
        tw += w[j] * __builtin_fabs(x[j]);
        ts += s[j] * __builtin_fabs(x[j]);
    }
    by_w = fold(tw, w_lo, w_hi);
    by_s = fold(ts, s_lo, s_hi);
}

FRETBUZZ_MULTIVERSION void axpy(double c, const double* x, double* y, std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) y[j] += c * x[j];
}

FRETBUZZ_MULTIVERSION void jump(const double* qq, const double* qd, const double* dq, const double* dd, double* q,
                                double* d, std::size_t n) {
    for (std::size_t j = 0; j < n; ++j) jump_one(qq[j], qd[j], dq[j], dd[j], q[j], d[j]);
}

}  // namespace fretbuzz::kernels
