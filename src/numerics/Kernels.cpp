#include "fretbuzz/numerics/Kernels.hpp"

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
// One mode's term of modal_energy, the same expression in every kernel that forms it.
template <class T>
FRETBUZZ_INLINE T energy_term(const T& e, const T& beta, const T& q, const T& d) {
    return 0.5 * (1.0 + e) * d * d + beta * q * (q - d);
}

// Sums of the step's pass: the losses, the energy (lanes 0-3 and 4-7 of every 8 modes).
struct PassSums {
    v4 loss_lo{}, loss_hi{}, energy_lo{}, energy_hi{};
};

// Four modes k..k+3 of the step's pass: their step (their push read from push), their loss and
// energy terms added to loss_sum and energy_sum, the next step's free prediction into x.
template <bool Lossy, bool Pushed, bool Predict, bool Energy>
FRETBUZZ_INLINE void step_lanes(const double* __restrict e, const double* __restrict beta,
                                const double* __restrict loss, const double* __restrict push, double* __restrict q,
                                double* __restrict d, std::size_t k, double* __restrict x, v4& loss_sum,
                                v4& energy_sum) {
    const v4 ek = load(e + k), bk = load(beta + k), qk = load(q + k), dk = load(d + k);
    v4 next = ek * dk - bk * qk;
    if constexpr (Pushed) next += load(push);
    if constexpr (Lossy) {
        const v4 span = next + dk;  // q^{n+1} - q^{n-1}
        loss_sum += load(loss + k) * span * span;
    }
    const v4 q_next = qk + next;
    store(q + k, q_next);
    store(d + k, next);
    if constexpr (Energy) energy_sum += energy_term(ek, bk, q_next, next);
    if constexpr (Predict) store(x, predicted(ek, bk, q_next, next));
}

// The modes [j, j + length) of the step's pass, length a multiple of kLanes (push and x indexed
// from j). Branch-free for each combination of what it forms.
template <bool Lossy, bool Pushed, bool Predict, bool Energy>
FRETBUZZ_INLINE void step_block(const double* e, const double* beta, const double* loss, const double* push, double* q,
                                double* d, std::size_t j, std::size_t length, double* x, PassSums& sums) {
    v4 loss_lo = sums.loss_lo, loss_hi = sums.loss_hi, energy_lo = sums.energy_lo, energy_hi = sums.energy_hi;
    for (std::size_t b = 0; b < length; b += kLanes) {
        step_lanes<Lossy, Pushed, Predict, Energy>(e, beta, loss, push + b, q, d, j + b, x + b, loss_lo, energy_lo);
        step_lanes<Lossy, Pushed, Predict, Energy>(e, beta, loss, push + b + 4, q, d, j + b + 4, x + b + 4, loss_hi,
                                                   energy_hi);
    }
    sums = {loss_lo, loss_hi, energy_lo, energy_hi};
}

template <bool Lossy, bool Pushed>
FRETBUZZ_INLINE void step_block_forming(bool predict, bool energy, const double* e, const double* beta,
                                        const double* loss, const double* push, double* q, double* d, std::size_t j,
                                        std::size_t length, double* x, PassSums& sums) {
    if (energy) {
        if (predict) step_block<Lossy, Pushed, true, true>(e, beta, loss, push, q, d, j, length, x, sums);
        else step_block<Lossy, Pushed, false, true>(e, beta, loss, push, q, d, j, length, x, sums);
    } else {
        if (predict) step_block<Lossy, Pushed, true, false>(e, beta, loss, push, q, d, j, length, x, sums);
        else step_block<Lossy, Pushed, false, false>(e, beta, loss, push, q, d, j, length, x, sums);
    }
}

// push[0, length) (+)= sum_r c[r] rows[r][j + b] over M rows, in one pass over the buffer.
template <std::size_t M, bool First>
FRETBUZZ_INLINE void add_pushes(const double* const* rows, const double* c, std::size_t j, std::size_t length,
                                double* __restrict push) {
    for (std::size_t b = 0; b < length; b += 4) {
        v4 sum = c[0] * load(rows[0] + j + b);
        if constexpr (!First) sum = load(push + b) + sum;
        for (std::size_t r = 1; r < M; ++r) sum += c[r] * load(rows[r] + j + b);
        store(push + b, sum);
    }
}

// lo[r], hi[r] += the products of rows[r][j + b] and y[b] over the block, for M <= 4 rows (y
// read once). Named accumulators, held in registers (an array's were kept in memory).
template <std::size_t M>
FRETBUZZ_INLINE void add_products(const double* const* rows, const double* __restrict y, std::size_t j,
                                  std::size_t length, v4* lo, v4* hi) {
    static_assert(M >= 1 && M <= 4);
    const double* r0 = rows[0] + j;
    const double* r1 = M > 1 ? rows[1] + j : r0;
    const double* r2 = M > 2 ? rows[2] + j : r0;
    const double* r3 = M > 3 ? rows[3] + j : r0;
    v4 l0 = lo[0], h0 = hi[0], l1{}, h1{}, l2{}, h2{}, l3{}, h3{};
    if constexpr (M > 1) l1 = lo[1], h1 = hi[1];
    if constexpr (M > 2) l2 = lo[2], h2 = hi[2];
    if constexpr (M > 3) l3 = lo[3], h3 = hi[3];
    for (std::size_t b = 0; b < length; b += kLanes) {
        const v4 y_lo = load(y + b), y_hi = load(y + b + 4);
        l0 += load(r0 + b) * y_lo;
        h0 += load(r0 + b + 4) * y_hi;
        if constexpr (M > 1) {
            l1 += load(r1 + b) * y_lo;
            h1 += load(r1 + b + 4) * y_hi;
        }
        if constexpr (M > 2) {
            l2 += load(r2 + b) * y_lo;
            h2 += load(r2 + b + 4) * y_hi;
        }
        if constexpr (M > 3) {
            l3 += load(r3 + b) * y_lo;
            h3 += load(r3 + b + 4) * y_hi;
        }
    }
    lo[0] = l0, hi[0] = h0;
    if constexpr (M > 1) lo[1] = l1, hi[1] = h1;
    if constexpr (M > 2) lo[2] = l2, hi[2] = h2;
    if constexpr (M > 3) lo[3] = l3, hi[3] = h3;
}

// The end of a step's pass: modes [j, n) one by one (fewer than kLanes), then each sum folded
// with its lanes lo[r], hi[r] (the predicted rows', then the observed row's) and written out.
template <bool Lossy>
FRETBUZZ_INLINE double finish_pass(const double* e, const double* beta, const double* loss, const StepPass& pass,
                                   double* q, double* d, std::size_t j, std::size_t n, const v4* lo, const v4* hi,
                                   const PassSums& sums) {
    const std::size_t pushes = std::min(pass.pushes, kMaxPassRows), rows = std::min(pass.predict_count, kMaxPassRows);
    double loss_tail = 0.0, energy_tail = 0.0, tail[kMaxPassRows + 1];
    for (std::size_t r = 0; r <= rows; ++r) tail[r] = 0.0;  // (the used ones only: this runs every step)
    for (; j < n; ++j) {
        double next = e[j] * d[j] - beta[j] * q[j];
        if (pass.impulse != nullptr) next += pass.impulse[j];
        if (pushes != 0) {
            double sum = pass.push_coefficients[0] * pass.push_rows[0][j];
            for (std::size_t r = 1; r < pushes; ++r) sum += pass.push_coefficients[r] * pass.push_rows[r][j];
            next += sum;
        }
        if constexpr (Lossy) loss_tail += loss[j] * (next + d[j]) * (next + d[j]);
        q[j] += next;
        d[j] = next;
        if (pass.energy != nullptr) energy_tail += energy_term(e[j], beta[j], q[j], next);
        const double xj = predicted(e[j], beta[j], q[j], next);
        for (std::size_t r = 0; r < rows; ++r) tail[r] += pass.predict_rows[r][j] * xj;
        if (pass.observe_row != nullptr) tail[rows] += pass.observe_row[j] * q[j];
    }
    for (std::size_t r = 0; r < rows; ++r) pass.predicted[r] = fold(tail[r], lo[r], hi[r]);
    if (pass.observe_row != nullptr) *pass.observed = fold(tail[rows], lo[rows], hi[rows]);
    if (pass.energy != nullptr) *pass.energy = fold(energy_tail, sums.energy_lo, sums.energy_hi);
    return Lossy ? fold(loss_tail, sums.loss_lo, sums.loss_hi) : 0.0;
}

// The step's pass for many rows, in blocks of modes: each block's pushes summed into a small
// buffer (four rows per pass over it), the block stepped (its predictions kept in another
// buffer), then the rows' products over the block, four rows per pass, their accumulators in
// registers.
template <bool Lossy>
FRETBUZZ_INLINE double step_blocked(const double* __restrict e, const double* __restrict beta,
                                    const double* __restrict loss, const StepPass& pass, double* __restrict q,
                                    double* __restrict d, std::size_t n) {
    constexpr std::size_t kBlock = 8 * kLanes;
    const std::size_t pushes = std::min(pass.pushes, kMaxPassRows), rows = std::min(pass.predict_count, kMaxPassRows);
    const bool pushed = pushes != 0 || pass.impulse != nullptr, energy = pass.energy != nullptr;
    v4 lo[kMaxPassRows + 1], hi[kMaxPassRows + 1];  // the predicted rows', then the observed row's
    for (std::size_t r = 0; r <= rows; ++r) lo[r] = hi[r] = v4{};
    PassSums sums;
    double buffer[kBlock], x[kBlock];
    std::size_t j = 0;
    const std::size_t whole = n - n % kLanes;
    while (j < whole) {
        const std::size_t length = std::min(kBlock, whole - j);
        // The block's pushes: the impulse vector as it is, or the rows summed into the buffer.
        const double* push = pushes == 0 && pass.impulse != nullptr ? pass.impulse + j : buffer;
        if (pushes != 0) {
            if (pass.impulse != nullptr)
                for (std::size_t b = 0; b < length; b += 4) store(buffer + b, load(pass.impulse + j + b));
            for (std::size_t r = 0; r < pushes; r += 4) {
                const double* const* at = pass.push_rows + r;
                const double* c = pass.push_coefficients + r;
                const bool first = r == 0 && pass.impulse == nullptr;
                switch (std::min<std::size_t>(4, pushes - r)) {
                    case 1: first ? add_pushes<1, true>(at, c, j, length, buffer) : add_pushes<1, false>(at, c, j, length, buffer); break;
                    case 2: first ? add_pushes<2, true>(at, c, j, length, buffer) : add_pushes<2, false>(at, c, j, length, buffer); break;
                    case 3: first ? add_pushes<3, true>(at, c, j, length, buffer) : add_pushes<3, false>(at, c, j, length, buffer); break;
                    default: first ? add_pushes<4, true>(at, c, j, length, buffer) : add_pushes<4, false>(at, c, j, length, buffer); break;
                }
            }
        }
        if (pushed)
            step_block_forming<Lossy, true>(rows != 0, energy, e, beta, loss, push, q, d, j, length, x, sums);
        else
            step_block_forming<Lossy, false>(rows != 0, energy, e, beta, loss, push, q, d, j, length, x, sums);
        for (std::size_t r = 0; r < rows; r += 4) {
            const double* const* at = pass.predict_rows + r;
            switch (std::min<std::size_t>(4, rows - r)) {
                case 1: add_products<1>(at, x, j, length, lo + r, hi + r); break;
                case 2: add_products<2>(at, x, j, length, lo + r, hi + r); break;
                case 3: add_products<3>(at, x, j, length, lo + r, hi + r); break;
                default: add_products<4>(at, x, j, length, lo + r, hi + r); break;
            }
        }
        if (pass.observe_row != nullptr) add_products<1>(&pass.observe_row, q + j, j, length, lo + rows, hi + rows);
        j += length;
    }
    return finish_pass<Lossy>(e, beta, loss, pass, q, d, j, n, lo, hi, sums);
}

// The step's pass for few rows (up to four pushes and four predicted rows, and the observed
// one: a point or a short bridge the string rests on, the usual case at audio rates, where the
// blocked pass's buffers would cost half the pass): one loop, every sum in registers, the
// counts known when compiling.
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



// advance_variant with, in the same pass, the products of q^{n+1} that the next step and the
// caller read: P rows with the next step's free prediction (formed from q^{n+1} and
// q^{n+1} - q^n as predict_dot forms it from memory) and O rows with q^{n+1} itself (as dot).
// Each sum has the lanes and the order of predict_dot's or dot's.
template <Push Pushed, bool Lossy, std::size_t P, std::size_t O, std::size_t M, bool E>
FRETBUZZ_INLINE double advance_products(const double* __restrict e, const double* __restrict beta,
                                        const double* __restrict loss, double c, const double* row,
                                        const double* coefficients, const double* const* rows, std::size_t m,
                                        const StepPass& products, double* __restrict q, double* __restrict d,
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
                                              std::size_t m, const StepPass& products, double* q, double* d,
                                              std::size_t n) {
    return loss != nullptr
               ? advance_products<Pushed, true, P, O, M, E>(e, beta, loss, c, row, coefficients, rows, m, products, q, d, n)
               : advance_products<Pushed, false, P, O, M, E>(e, beta, loss, c, row, coefficients, rows, m, products, q, d, n);
}

template <std::size_t P, std::size_t O, bool E>
FRETBUZZ_INLINE double advance_products_pushed(const double* e, const double* beta, const double* loss,
                                               const double* coefficients, const double* const* rows, std::size_t m,
                                               const StepPass& products, double* q, double* d, std::size_t n) {
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
                                                const StepPass& products, double* q, double* d, std::size_t n) {
    switch (products.predict_count) {
        case 0: return advance_products_pushed<0, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        case 1: return advance_products_pushed<1, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        case 2: return advance_products_pushed<2, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        case 3: return advance_products_pushed<3, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
        default: return advance_products_pushed<4, O, E>(e, beta, loss, coefficients, rows, m, products, q, d, n);
    }
}


// The few rows' pass with and without the energy, and the blocked pass: functions of their own
// (multiversioned, each called through the processor's choice). Compiled into one function,
// GCC kept the few rows' pointers and sums in memory (a slower pass; docs/performance.md).
template <bool Lossy, bool E>
FRETBUZZ_INLINE double step_few(const double* e, const double* beta, const double* loss, const StepPass& pass,
                                double* q, double* d, std::size_t n) {
    const double* losses = Lossy ? loss : nullptr;
    return pass.observe_row != nullptr
               ? advance_products_counted<1, E>(e, beta, losses, pass.push_coefficients, pass.push_rows, pass.pushes,
                                                pass, q, d, n)
               : advance_products_counted<0, E>(e, beta, losses, pass.push_coefficients, pass.push_rows, pass.pushes,
                                                pass, q, d, n);
}
FRETBUZZ_MULTIVERSION [[gnu::noinline]] double few_lossy(const double* e, const double* beta, const double* loss,
                                                         const StepPass& pass, double* q, double* d, std::size_t n) {
    return step_few<true, false>(e, beta, loss, pass, q, d, n);
}
FRETBUZZ_MULTIVERSION [[gnu::noinline]] double few_lossy_energy(const double* e, const double* beta, const double* loss,
                                                                const StepPass& pass, double* q, double* d,
                                                                std::size_t n) {
    return step_few<true, true>(e, beta, loss, pass, q, d, n);
}
FRETBUZZ_MULTIVERSION [[gnu::noinline]] double few_lossless(const double* e, const double* beta, const double* loss,
                                                            const StepPass& pass, double* q, double* d, std::size_t n) {
    return step_few<false, false>(e, beta, loss, pass, q, d, n);
}
FRETBUZZ_MULTIVERSION [[gnu::noinline]] double few_lossless_energy(const double* e, const double* beta,
                                                                   const double* loss, const StepPass& pass, double* q,
                                                                   double* d, std::size_t n) {
    return step_few<false, true>(e, beta, loss, pass, q, d, n);
}
FRETBUZZ_MULTIVERSION [[gnu::noinline]] double blocked_lossy(const double* e, const double* beta, const double* loss,
                                                             const StepPass& pass, double* q, double* d, std::size_t n) {
    return step_blocked<true>(e, beta, loss, pass, q, d, n);
}
FRETBUZZ_MULTIVERSION [[gnu::noinline]] double blocked_lossless(const double* e, const double* beta,
                                                                const double* loss, const StepPass& pass, double* q,
                                                                double* d, std::size_t n) {
    return step_blocked<false>(e, beta, loss, pass, q, d, n);
}

// Few rows (up to four pushes and four predicted rows: a point or a short bridge the string
// rests on, the usual case at audio rates, where the blocked pass's buffers cost a third more)
// in registers, many rows (a finger's pad, a string landing on a long obstacle) in blocks.
bool few_rows(const StepPass& pass) {
    constexpr std::size_t kFew = 4;
    return pass.pushes <= kFew && pass.predict_count <= kFew && pass.impulse == nullptr;
}
}  // namespace

FRETBUZZ_MULTIVERSION double advance(const double* e, const double* beta, const double* loss, const double* impulse,
                                     double* q, double* d, std::size_t n) {
    const StepPass none;  // no products
    if (impulse != nullptr)
        return loss != nullptr
                   ? advance_products<Push::array, true, 0, 0, 1, false>(e, beta, loss, 0.0, impulse, nullptr, nullptr, 0, none, q, d, n)
                   : advance_products<Push::array, false, 0, 0, 1, false>(e, beta, loss, 0.0, impulse, nullptr, nullptr, 0, none, q, d, n);
    return loss != nullptr
               ? advance_products<Push::none, true, 0, 0, 1, false>(e, beta, loss, 0.0, nullptr, nullptr, nullptr, 0, none, q, d, n)
               : advance_products<Push::none, false, 0, 0, 1, false>(e, beta, loss, 0.0, nullptr, nullptr, nullptr, 0, none, q, d, n);
}

double step_lossy(const double* e, const double* beta, const double* loss, const StepPass& pass, double* q, double* d,
                  std::size_t n) {
    if (!few_rows(pass)) return blocked_lossy(e, beta, loss, pass, q, d, n);
    return pass.energy != nullptr ? few_lossy_energy(e, beta, loss, pass, q, d, n) : few_lossy(e, beta, loss, pass, q, d, n);
}

double step_lossless(const double* e, const double* beta, const double* loss, const StepPass& pass, double* q,
                     double* d, std::size_t n) {
    if (!few_rows(pass)) return blocked_lossless(e, beta, loss, pass, q, d, n);
    return pass.energy != nullptr ? few_lossless_energy(e, beta, loss, pass, q, d, n)
                                  : few_lossless(e, beta, loss, pass, q, d, n);
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

// Vector types, as dot's: GCC vectorised the plain loops over 8 lanes with shuffles, far
// slower (the speed bound's growth after a flat obstacle's impulse is one of these).
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
