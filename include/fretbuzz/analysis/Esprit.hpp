#pragma once
// ESPRIT (Roy & Kailath 1989) for a sum of complex damped exponentials in white noise,
//   y[n] = sum_k a_k z_k^n + w[n],
// with the model order chosen by ESTER (Badeau, David & Richard 2006): the rotational
// invariance of the signal subspace holds exactly at the true order, so the inverse of
// the invariance error, J(p) = 1 / ||W_up - W_down Phi||_2^2, peaks there.
// The subspace comes from the SVD of the Hankel data matrix (Eigen), computed once; every
// order's check reuses its leading singular vectors.
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace fretbuzz {

struct ExponentialComponent {
    std::complex<double> pole;       // z_k
    std::complex<double> amplitude;  // a_k, at n = 0
    double energy = 0.0;             // sum_n |a_k z_k^n|^2 over the data
};

class Esprit {
public:
    // rows: the Hankel matrix's row count (the subspace dimension bound), 2 <= rows < y.size().
    Esprit(std::span<const std::complex<double>> y, std::size_t rows);

    // J(p) for p = 1..max_order (index p-1).
    std::vector<double> ester(std::size_t max_order) const;
    // The largest order whose J is at least `fraction` of the best one: an order a little
    // too high only adds poles the later checks reject, one too low loses partials.
    std::size_t choose_order(std::size_t max_order, double fraction = 0.1) const;
    // The poles of that order with their least-squares amplitudes.
    std::vector<ExponentialComponent> components(std::size_t order) const;
    // Mean squared residual of the least-squares fit of the last components() call's order.
    double residual_variance(const std::vector<ExponentialComponent>& components) const;
    std::size_t max_order() const;

private:
    std::vector<std::complex<double>> y_;
    std::size_t rows_;
    std::vector<std::complex<double>> basis_;  // leading left singular vectors, column-major rows_ x max
    std::size_t basis_columns_ = 0;
};

}  // namespace fretbuzz
