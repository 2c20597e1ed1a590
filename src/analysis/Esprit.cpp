#include "fretbuzz/analysis/Esprit.hpp"

#include <fftw3.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <random>
#include <stdexcept>

#include "FastLength.hpp"
#include "fretbuzz/numerics/SineTransform.hpp"

namespace fretbuzz {

namespace {

using Matrix = Eigen::MatrixXcd;
using Vector = Eigen::VectorXcd;

// Columns computed beyond the ones kept, and subspace iterations: the kept singular vectors
// converge like (sigma_{kept + extra} / sigma_k)^(2 iterations + 1).
constexpr std::size_t kExtraColumns = 12;
constexpr int kIterations = 6;

// Phi solving W_down Phi = W_up in the least-squares sense, W with orthonormal columns:
// W_down* W_down = I - l* l (l: W's last row), so the normal equations are p x p.
Matrix rotation(const Matrix& w) {
    const Eigen::Index m = w.rows(), p = w.cols();
    const Matrix cross = w.topRows(m - 1).adjoint() * w.bottomRows(m - 1);
    const Matrix gram = Matrix::Identity(p, p) - w.row(m - 1).adjoint() * w.row(m - 1);
    return gram.ldlt().solve(cross);
}

// Gram-Schmidt, each column projected out twice ("twice is enough", Giraud et al. 2005);
// a third pass where the second still removed most of it (a column dependent on the others).
Matrix orthonormal_columns(Matrix q) {
    for (Eigen::Index j = 0; j < q.cols(); ++j) {
        double before = q.col(j).norm();
        for (int pass = 0; pass < 3 && j > 0; ++pass) {
            const Vector c = q.leftCols(j).adjoint() * q.col(j);
            q.col(j).noalias() -= q.leftCols(j) * c;
            const double after = q.col(j).norm();
            if (pass >= 1 && after > 0.5 * before) break;
            before = after;
        }
        const double norm = q.col(j).norm();
        if (norm > 0.0) q.col(j) /= norm;
    }
    return q;
}

// Products with the Hankel matrix H(r, c) = y[r + c] (rows x cols) and its adjoint, by FFT:
// both are correlations with y, so a product costs two transforms of about the data's length
// instead of rows x cols operations.
class HankelProducts {
public:
    HankelProducts(std::span<const std::complex<double>> y, std::size_t rows)
        : rows_(rows), cols_(y.size() - rows + 1), length_(smooth_length(y.size())),
          spectrum_(length_), buffer_(fftw_alloc_complex(length_), fftw_free) {
        if (!buffer_) throw std::bad_alloc();
        {
            std::lock_guard lock(fftw_planner_mutex());
            const int n = static_cast<int>(length_);
            forward_ = fftw_plan_dft_1d(n, buffer_.get(), buffer_.get(), FFTW_FORWARD, FFTW_ESTIMATE);
            backward_ = fftw_plan_dft_1d(n, buffer_.get(), buffer_.get(), FFTW_BACKWARD, FFTW_ESTIMATE);
        }
        load(y.data(), y.size(), false);
        fftw_execute(forward_);
        for (std::size_t k = 0; k < length_; ++k) spectrum_[k] = at(k);
    }
    ~HankelProducts() {
        std::lock_guard lock(fftw_planner_mutex());
        fftw_destroy_plan(forward_);
        fftw_destroy_plan(backward_);
    }
    HankelProducts(const HankelProducts&) = delete;
    HankelProducts& operator=(const HankelProducts&) = delete;

    // H v for each column v (cols_ rows): out[r] = sum_c y[r + c] v[c] = IFFT(Y conj(FFT(conj v)))[r].
    Matrix times(const Matrix& v) { return correlate(v, rows_, false); }
    // H* w for each column w (rows_ rows): out[c] = conj(IFFT(Y conj(FFT(w)))[c]).
    Matrix adjoint_times(const Matrix& w) { return correlate(w, cols_, true); }

private:
    std::complex<double>& at(std::size_t k) { return reinterpret_cast<std::complex<double>*>(buffer_.get())[k]; }
    double scale() const { return static_cast<double>(length_); }
    void load(const std::complex<double>* data, std::size_t n, bool conjugate) {
        for (std::size_t k = 0; k < length_; ++k)
            at(k) = k < n ? (conjugate ? std::conj(data[k]) : data[k]) : std::complex<double>(0.0);
    }
    // The correlation of y with each column, the first `size` lags; `adjoint` conjugates the
    // result where H v conjugates the input.
    Matrix correlate(const Matrix& x, std::size_t size, bool adjoint) {
        Matrix out(static_cast<Eigen::Index>(size), x.cols());
        for (Eigen::Index j = 0; j < x.cols(); ++j) {
            load(x.col(j).data(), static_cast<std::size_t>(x.rows()), !adjoint);
            fftw_execute(forward_);
            for (std::size_t k = 0; k < length_; ++k) at(k) = spectrum_[k] * std::conj(at(k));
            fftw_execute(backward_);
            for (std::size_t i = 0; i < size; ++i)
                out(static_cast<Eigen::Index>(i), j) = (adjoint ? std::conj(at(i)) : at(i)) / scale();
        }
        return out;
    }

    std::size_t rows_, cols_, length_;
    std::vector<std::complex<double>> spectrum_;
    std::unique_ptr<fftw_complex, decltype(&fftw_free)> buffer_;
    fftw_plan forward_ = nullptr, backward_ = nullptr;
};

}  // namespace

Esprit::Esprit(std::span<const std::complex<double>> y, std::size_t rows, std::size_t max_order)
    : y_(y.begin(), y.end()), rows_(rows) {
    if (rows < 2 || rows >= y.size()) throw std::invalid_argument("Esprit: need 2 <= rows < samples");
    const std::size_t cols = y.size() - rows + 1;
    basis_columns_ = std::min({max_order, rows - 1, cols});
    const auto width = static_cast<Eigen::Index>(std::min({basis_columns_ + kExtraColumns, rows, cols}));
    // The leading left singular vectors of H by subspace iteration from a random start
    // (Halko, Martinsson & Tropp 2011), with a fixed seed: the same data give the same poles.
    HankelProducts hankel(y, rows);
    std::mt19937_64 random(2011);
    std::normal_distribution<double> normal;
    Matrix start(static_cast<Eigen::Index>(cols), width);
    for (Eigen::Index j = 0; j < width; ++j)
        for (Eigen::Index i = 0; i < start.rows(); ++i) start(i, j) = {normal(random), normal(random)};
    // Orthonormalised after each H H* (not in between: the squared spread of the singular
    // values stays within what Gram-Schmidt twice handles, 150 dB of amplitude).
    Matrix q = orthonormal_columns(hankel.times(start));
    for (int it = 0; it < kIterations; ++it) q = orthonormal_columns(hankel.times(hankel.adjoint_times(q)));
    // H ~ Q Q* H = Q (H* Q)*: with (H* Q) = U S V*, H's left singular vectors are Q V, and V
    // holds the eigenvectors of the small (Q* H)(H* Q), whose eigenvalues are S^2 (ascending).
    const Matrix projected = hankel.adjoint_times(q);
    const Eigen::SelfAdjointEigenSolver<Matrix> eigen(projected.adjoint() * projected);
    const Matrix leading =
        q * eigen.eigenvectors().rowwise().reverse().leftCols(static_cast<Eigen::Index>(basis_columns_));
    basis_.assign(leading.data(), leading.data() + leading.size());
}

std::size_t Esprit::max_order() const { return basis_columns_; }

std::vector<double> Esprit::ester(std::size_t max_order) const {
    max_order = std::min(max_order, basis_columns_);
    const Eigen::Map<const Matrix> all(basis_.data(), static_cast<Eigen::Index>(rows_),
                                       static_cast<Eigen::Index>(basis_columns_));
    std::vector<double> j;
    for (std::size_t p = 1; p <= max_order; ++p) {
        const Matrix w = all.leftCols(static_cast<Eigen::Index>(p));
        const Eigen::Index m = w.rows();
        const Matrix error = w.bottomRows(m - 1) - w.topRows(m - 1) * rotation(w);
        const Matrix square = error.adjoint() * error;  // ||E||_2^2: its largest eigenvalue
        const double norm2 =
            Eigen::SelfAdjointEigenSolver<Matrix>(square, Eigen::EigenvaluesOnly).eigenvalues().maxCoeff();
        j.push_back(1.0 / std::max(norm2, 1e-300));
    }
    return j;
}

std::size_t Esprit::choose_order(std::size_t max_order, double fraction) const {
    const std::vector<double> j = ester(max_order);
    if (j.empty()) return 0;
    const double best = *std::max_element(j.begin(), j.end());
    std::size_t order = 1;
    for (std::size_t p = 1; p <= j.size(); ++p)
        if (j[p - 1] >= fraction * best) order = p;
    return order;
}

ExponentialFit Esprit::fit(std::size_t order) const {
    order = std::min(order, basis_columns_);
    ExponentialFit out;
    const auto n = static_cast<Eigen::Index>(y_.size());
    const Vector data = Eigen::Map<const Vector>(y_.data(), n);
    if (order == 0) {
        out.residual_variance = data.squaredNorm() / static_cast<double>(n);
        return out;
    }
    const Eigen::Map<const Matrix> all(basis_.data(), static_cast<Eigen::Index>(rows_),
                                       static_cast<Eigen::Index>(basis_columns_));
    const Eigen::ComplexEigenSolver<Matrix> eigen(rotation(all.leftCols(static_cast<Eigen::Index>(order))), false);
    const Vector poles = eigen.eigenvalues();

    // Column k is z_k^n, or z_k^(n - last) for a growing pole: every entry at most 1, so a
    // long record cannot overflow; the amplitude at n = 0 takes the factor back.
    const auto p = static_cast<Eigen::Index>(order);
    const Eigen::Index last = n - 1;
    Matrix vandermonde(n, p);
    for (Eigen::Index k = 0; k < p; ++k) {
        const bool growing = std::abs(poles(k)) > 1.0;
        std::complex<double> power = 1.0;
        for (Eigen::Index i = 0; i < n; ++i) {
            vandermonde(growing ? last - i : i, k) = power;
            power *= growing ? 1.0 / poles(k) : poles(k);
        }
    }
    const Vector coefficients = vandermonde.colPivHouseholderQr().solve(data);
    // Removing component k from the least-squares fit raises the residual by
    // |c_k|^2 / (G^-1)_kk, with G = V* V the Gram matrix of the columns.
    const Matrix gram_inverse =
        (vandermonde.adjoint() * vandermonde).completeOrthogonalDecomposition().pseudoInverse();
    const Vector residual = data - vandermonde * coefficients;
    for (Eigen::Index k = 0; k < p; ++k) {
        const double inverse_kk = gram_inverse(k, k).real();
        const bool growing = std::abs(poles(k)) > 1.0;
        const std::complex<double> amplitude =
            growing ? coefficients(k) * std::pow(poles(k), -static_cast<double>(last)) : coefficients(k);
        out.components.push_back({poles(k), amplitude, (vandermonde.col(k) * coefficients(k)).squaredNorm(),
                                  inverse_kk > 0.0 ? std::norm(coefficients(k)) / inverse_kk : 0.0});
    }
    out.residual_variance = residual.squaredNorm() / static_cast<double>(n);
    return out;
}

}  // namespace fretbuzz
