#pragma once
// The few loops every time step runs over all modes, written once, vectorisable
// (independent partial sums instead of one serial accumulator) and compiled for both
// baseline x86-64 and AVX2 machines, the faster chosen when the program starts.
#include <cstddef>

namespace fretbuzz::kernels {

// sum_j a_j b_j
double dot(const double* a, const double* b, std::size_t n);
// Rows that one pass over a vector multiplies at once (the rest: further passes).
inline constexpr std::size_t kMaxRowsPerPass = 4;
// Rows whose next prediction one step's pass can form (a finger's pad and the points it presses).
inline constexpr std::size_t kMaxForecastRows = 16;
// out[r] = dot(rows[r], x, n) for r < m, each the same sum, reading x once per kMaxRowsPerPass rows.
void dot_rows(const double* const* rows, std::size_t m, const double* x, std::size_t n, double* out);
// sum_j row_j q_j and sum_j row_j (q_j - d_j): u^n and u^{n-1} at one grid point.
void dot_current_previous(const double* row, const double* q, const double* d, std::size_t n, double& current,
                          double& previous);
// The free prediction of q^{n+1}: p_j = q_j + e_j d_j - beta_j q_j.
void predict(const double* e, const double* beta, const double* q, const double* d, double* p, std::size_t n);
// sum_j row_j p_j with p as predict computes it, without storing p (one contact point).
double predict_dot(const double* e, const double* beta, const double* q, const double* d, const double* row,
                   std::size_t n);
// out[r] = predict_dot(e, beta, q, d, rows[r], n) for r < m (the prediction formed once per pass).
void predict_dot_rows(const double* e, const double* beta, const double* q, const double* d, const double* const* rows,
                      std::size_t m, std::size_t n, double* out);
// One exact step of every mode in difference form, impulse may be null:
//   d_j <- e_j d_j - beta_j q_j + impulse_j,  q_j <- q_j + d_j.
// Returns sum_j loss_j (d_j^new + d_j^old)^2 (the damping term of the energy balance),
// or 0 when loss is null (lossless).
double advance(const double* e, const double* beta, const double* loss, const double* impulse, double* q, double* d,
               std::size_t n);
// advance with the impulse of one point, c row_j, formed on the fly (no impulse vector).
double advance_one_push(const double* e, const double* beta, const double* loss, double c, const double* row, double* q,
                        double* d, std::size_t n);
// advance with the impulse of m points, sum_r coefficients[r] rows[r]_j, formed on the fly as
// axpy would form it in a zeroed array (the same impulse, no impulse vector).
double advance_pushes(const double* e, const double* beta, const double* loss, const double* coefficients,
                      const double* const* rows, std::size_t m, double* q, double* d, std::size_t n);
// What one step's pass over the modes also forms while it holds q^{n+1} (advance_with_products).
struct StepProducts {
    // predicted[r] = predict_dot(e, beta, q^{n+1}, q^{n+1} - q^n, predict_rows[r], n): the next
    // step's free prediction at these rows, r < predict_count <= kMaxRowsPerPass
    // (kMaxForecastRows in advance_with_pad_products).
    const double* const* predict_rows = nullptr;
    std::size_t predict_count = 0;
    double* predicted = nullptr;
    // *observed = dot(observe_row, q^{n+1}, n) (a pickup), if observe_row is not null.
    const double* observe_row = nullptr;
    double* observed = nullptr;
    // *energy = modal_energy(e, beta, q^{n+1}, d^{n+1}, n), if energy is not null (a run that
    // audits its energy balance at every step: at an audio rate, one pass fewer per step).
    double* energy = nullptr;
};
// One step as advance (m = 0, no impulse), advance_one_push (m = 1, c = coefficients[0]) or
// advance_pushes (m >= 2) computes it, and the products asked for, each bit for bit the value
// of the separate kernel: one pass instead of two or three (m <= kMaxRowsPerPass; more pushes
// take the separate passes).
double advance_with_products(const double* e, const double* beta, const double* loss, const double* coefficients,
                             const double* const* rows, std::size_t m, const StepProducts& products, double* q,
                             double* d, std::size_t n);
// advance_with_products for a finger's pad: up to 16 pushes and kMaxForecastRows predicted rows,
// the counts known at run time, each result bit for bit the separate kernels' (one pass for the
// step, the pad's next predictions and the pickup, instead of four to six).
double advance_with_pad_products(const double* e, const double* beta, const double* loss, const double* coefficients,
                                 const double* const* rows, std::size_t m, const StepProducts& products, double* q,
                                 double* d, std::size_t n);
// sum_j (1+e_j)/2 d_j^2 + beta_j q_j (q_j - d_j): the discrete modal energy times 2 dt^2 / mu.
double modal_energy(const double* e, const double* beta, const double* q, const double* d, std::size_t n);
// A free flight's end in one pass over the modes: jump (E = [[qq, qd], [dq, dd]]) of modes
// [first, n) only (the others are already there), then, of the state it leaves, out[r] =
// dot(rows[r], q, n) for r < m and the returned modal_energy(e, beta, q, d, n), each bit for
// bit the separate kernel's (one pass instead of three; more than kMaxRowsPerPass rows take a
// second pass). The maps are indexed from mode 0, like q and d.
double jump_with_products(const double* qq, const double* qd, const double* dq, const double* dd, std::size_t first,
                          const double* e, const double* beta, const double* const* rows, std::size_t m, double* q,
                          double* d, std::size_t n, double* out);
// a_j = sqrt(q_j^2 + (aq_j q_j + ad_j d_j)^2): the amplitude of each mode's free motion.
void free_amplitudes(const double* aq, const double* ad, const double* q, const double* d, double* a, std::size_t n);
// sum_j x_j
double sum(const double* x, std::size_t n);
// sum_j w[j] |x[j]|
double weighted_abs_sum(const double* w, const double* x, std::size_t n);
// sum_j w[j] |x[j]| and sum_j s[j] |x[j]|, each to its accumulator (one pass over x).
void weighted_abs_sums(const double* w, const double* s, const double* x, std::size_t n, double& by_w, double& by_s);
// y_j += c x_j
void axpy(double c, const double* x, double* y, std::size_t n);
// (q, d) <- (I + E) (q, d) per mode, E = [[qq, qd], [dq, dd]]: a free flight's M-step map.
void jump(const double* qq, const double* qd, const double* dq, const double* dd, double* q, double* d, std::size_t n);

}  // namespace fretbuzz::kernels
