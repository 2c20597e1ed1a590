#pragma once
// ESPRIT (Roy & Kailath 1989) for a sum of complex damped exponentials in white noise,
//   y[n] = sum_k a_k z_k^n + w[n],
// with the model order chosen by ESTER (Badeau, David & Richard 2006): the rotational
// invariance of the signal subspace holds exactly at the true order, so the inverse of
// the invariance error, J(p) = 1 / ||W_up - W_down Phi||_2^2, peaks there.
// The subspace is the leading left singular vectors of the Hankel data matrix, computed
// once by randomized subspace iteration with FFT products (long records stay cheap: the
// matrix is never formed); every order's check reuses them.
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace fretbuzz {

struct ExponentialComponent {
    std::complex<double> pole;       // z_k
    std::complex<double> amplitude;  // a_k, at n = 0
    double energy = 0.0;             // sum_n |a_k z_k^n|^2 over the data
    // How much the least-squares residual grows without this component: its energy that
    // no other component can take over (below `energy` for close poles, which share).
    double own_energy = 0.0;
};

struct ExponentialFit {
    std::vector<ExponentialComponent> components;
    double residual_variance = 0.0;  // mean squared residual per sample
};

class Esprit {
public:
    // rows: the Hankel matrix's row count, 2 <= rows < y.size() (about y.size() / 3 resolves
    // close poles best); max_order: the highest order any later call asks for.
    Esprit(std::span<const std::complex<double>> y, std::size_t rows, std::size_t max_order);

    // J(p) for p = 1..max_order (index p-1).
    std::vector<double> ester(std::size_t max_order) const;
    // The largest order whose J is at least `fraction` of the best one: an order a little
    // too high only adds poles the later checks reject, one too low loses partials.
    std::size_t choose_order(std::size_t max_order, double fraction = 0.1) const;
    // The poles of that order with their least-squares amplitudes.
    ExponentialFit fit(std::size_t order) const;
    std::size_t max_order() const;

private:
    std::vector<std::complex<double>> y_;
    std::size_t rows_;
    std::vector<std::complex<double>> basis_;  // leading left singular vectors, column-major rows_ x basis_columns_
    std::size_t basis_columns_ = 0;
};

}  // namespace fretbuzz
