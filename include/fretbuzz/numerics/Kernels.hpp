#pragma once
// The few loops every time step runs over all modes, written once, vectorisable (independent
// partial sums instead of one serial accumulator) and compiled for baseline x86-64, AVX2 and
// AVX-512 machines, the fastest the processor runs chosen when the program starts (their
// results agree to round-off: tests/variants).
#include <cstddef>

namespace fretbuzz::kernels {

// sum_j a_j b_j
double dot(const double* a, const double* b, std::size_t n);
// Rows that one pass over a vector multiplies at once (the rest: further passes).
inline constexpr std::size_t kMaxRowsPerPass = 4;
// out[r] = dot(rows[r], x, n) for r < m, reading x once per kMaxRowsPerPass rows.
void dot_rows(const double* const* rows, std::size_t m, const double* x, std::size_t n, double* out);
// sum_j row_j q_j and sum_j row_j (q_j - d_j): u^n and u^{n-1} at one grid point.
void dot_current_previous(const double* row, const double* q, const double* d, std::size_t n, double& current,
                          double& previous);
// The free prediction of q^{n+1}: p_j = q_j + e_j d_j - beta_j q_j.
void predict(const double* e, const double* beta, const double* q, const double* d, double* p, std::size_t n);
// out[r] = sum_j rows[r]_j p_j for r < m, p as predict forms it, formed on the fly (not stored).
void predict_dot_rows(const double* e, const double* beta, const double* q, const double* d, const double* const* rows,
                      std::size_t m, std::size_t n, double* out);
// One exact step of every mode in difference form, impulse may be null:
//   d_j <- e_j d_j - beta_j q_j + impulse_j,  q_j <- q_j + d_j.
// Returns sum_j loss_j (d_j^new + d_j^old)^2 (the damping term of the energy balance),
// or 0 when loss is null (lossless).
double advance(const double* e, const double* beta, const double* loss, const double* impulse, double* q, double* d,
               std::size_t n);

// Rows a step's pass pushes with, and rows it forms predictions at, at most (each).
inline constexpr std::size_t kMaxPassRows = 16;
// One step of the string (Stepper): what it pushes with, and what it forms of the state it leaves
// while it holds it (one pass over the modes instead of one per product).
struct StepPass {
    // The impulse: impulse_j (if not null) + sum_r push_coefficients[r] push_rows[r]_j, r < pushes.
    const double* impulse = nullptr;
    const double* const* push_rows = nullptr;
    const double* push_coefficients = nullptr;
    std::size_t pushes = 0;
    // predicted[r] = sum_j predict_rows[r]_j p_j for r < predict_count, p the next step's free
    // prediction (predict's, from q^{n+1} and d^{n+1}).
    const double* const* predict_rows = nullptr;
    std::size_t predict_count = 0;
    double* predicted = nullptr;
    // *observed = dot(observe_row, q^{n+1}) (a pickup), if observe_row is not null.
    const double* observe_row = nullptr;
    double* observed = nullptr;
    // *energy = modal_energy(e, beta, q^{n+1}, d^{n+1}), if energy is not null.
    double* energy = nullptr;
};
// advance with the pushes of `pass`, and the products it asks for, in one pass over the modes
// (up to four pushes and four predicted rows with every sum in registers, more in blocks of
// modes). Two kernels, the plan choosing one for a run (Plan::step_kernel): with losses
// (returned as advance returns them) and lossless (loss unread, 0 returned).
using StepKernel = double (*)(const double* e, const double* beta, const double* loss, const StepPass& pass, double* q,
                              double* d, std::size_t n);
double step_lossy(const double* e, const double* beta, const double* loss, const StepPass& pass, double* q, double* d,
                  std::size_t n);
double step_lossless(const double* e, const double* beta, const double* loss, const StepPass& pass, double* q,
                     double* d, std::size_t n);

// sum_j (1+e_j)/2 d_j^2 + beta_j q_j (q_j - d_j): the discrete modal energy times 2 dt^2 / mu.
double modal_energy(const double* e, const double* beta, const double* q, const double* d, std::size_t n);
// (q, d) <- (I + E) (q, d) per mode, E = [[qq, qd], [dq, dd]]: a free flight's M-step map.
void jump(const double* qq, const double* qd, const double* dq, const double* dd, double* q, double* d, std::size_t n);
// A free flight's end in one pass over the modes: jump of modes [first, n) only (the others are
// already there; the maps are indexed from mode 0, like q and d), then, of the state it leaves,
// out[r] = dot(rows[r], q, n) for r < m (more than kMaxRowsPerPass rows take a second pass) and
// the returned modal_energy(e, beta, q, d, n).
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

}  // namespace fretbuzz::kernels
