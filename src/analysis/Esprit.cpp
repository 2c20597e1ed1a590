#include "fretbuzz/analysis/Esprit.hpp"

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fretbuzz {

namespace {

using Matrix = Eigen::MatrixXcd;
using Vector = Eigen::VectorXcd;

// Keep at most this many singular vectors: orders above it are never asked for.
constexpr std::size_t kMaxBasis = 96;

Eigen::Map<const Matrix> as_matrix(const std::vector<std::complex<double>>& data, std::size_t rows, std::size_t cols) {
    return {data.data(), static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols)};
}

// Phi solving W_down Phi = W_up in the least-squares sense, for the first p columns.
Matrix rotation(const Matrix& w) {
    const Eigen::Index m = w.rows();
    return w.topRows(m - 1).colPivHouseholderQr().solve(w.bottomRows(m - 1));
}

}  // namespace

Esprit::Esprit(std::span<const std::complex<double>> y, std::size_t rows) : y_(y.begin(), y.end()), rows_(rows) {
    if (rows < 2 || rows >= y.size()) throw std::invalid_argument("Esprit: need 2 <= rows < samples");
    const std::size_t cols = y.size() - rows + 1;
    Matrix hankel(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
    for (std::size_t c = 0; c < cols; ++c)
        for (std::size_t r = 0; r < rows; ++r) hankel(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = y_[r + c];
    const Eigen::BDCSVD<Matrix> svd(hankel, Eigen::ComputeThinU);
    basis_columns_ = std::min({kMaxBasis, rows - 1, static_cast<std::size_t>(svd.matrixU().cols())});
    const Matrix leading = svd.matrixU().leftCols(static_cast<Eigen::Index>(basis_columns_));
    basis_.assign(leading.data(), leading.data() + leading.size());
}

std::size_t Esprit::max_order() const { return basis_columns_; }

std::vector<double> Esprit::ester(std::size_t max_order) const {
    max_order = std::min(max_order, basis_columns_);
    const auto all = as_matrix(basis_, rows_, basis_columns_);
    std::vector<double> j;
    for (std::size_t p = 1; p <= max_order; ++p) {
        const Matrix w = all.leftCols(static_cast<Eigen::Index>(p));
        const Eigen::Index m = w.rows();
        const Matrix error = w.bottomRows(m - 1) - w.topRows(m - 1) * rotation(w);
        const double norm = Eigen::JacobiSVD<Matrix>(error).singularValues()(0);
        j.push_back(1.0 / std::max(norm * norm, 1e-300));
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

std::vector<ExponentialComponent> Esprit::components(std::size_t order) const {
    order = std::min(order, basis_columns_);
    if (order == 0) return {};
    const Matrix w = as_matrix(basis_, rows_, basis_columns_).leftCols(static_cast<Eigen::Index>(order));
    const Eigen::ComplexEigenSolver<Matrix> eigen(rotation(w), false);
    const Vector poles = eigen.eigenvalues();

    const auto n = static_cast<Eigen::Index>(y_.size());
    const auto p = static_cast<Eigen::Index>(order);
    Matrix vandermonde(n, p);
    for (Eigen::Index k = 0; k < p; ++k) {
        std::complex<double> power = 1.0;
        for (Eigen::Index i = 0; i < n; ++i) {
            vandermonde(i, k) = power;
            power *= poles(k);
        }
    }
    const Vector data = Eigen::Map<const Vector>(y_.data(), n);
    const Vector amplitudes = vandermonde.colPivHouseholderQr().solve(data);
    std::vector<ExponentialComponent> result;
    for (Eigen::Index k = 0; k < p; ++k)
        result.push_back({poles(k), amplitudes(k), (vandermonde.col(k) * amplitudes(k)).squaredNorm()});
    return result;
}

double Esprit::residual_variance(const std::vector<ExponentialComponent>& components) const {
    double sum = 0.0;
    for (std::size_t i = 0; i < y_.size(); ++i) {
        std::complex<double> model = 0.0;
        for (const ExponentialComponent& c : components) model += c.amplitude * std::pow(c.pole, static_cast<double>(i));
        sum += std::norm(y_[i] - model);
    }
    return sum / static_cast<double>(y_.size());
}

}  // namespace fretbuzz
