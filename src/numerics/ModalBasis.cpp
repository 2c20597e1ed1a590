#include "fretbuzz/numerics/ModalBasis.hpp"

#include <cmath>
#include <numbers>
#include <utility>

namespace fretbuzz {

ModalBasis::ModalBasis(double length_m, std::size_t mode_count, bool measure_transform)
    : length_(length_m),
      modes_(mode_count),
      dx_(length_m / static_cast<double>(mode_count + 1)),
      transform_(std::make_unique<SineTransform>(mode_count, measure_transform)),
      rows_(mode_count) {
    const std::size_t n = modes_ + 1;
    sine_table_.resize(2 * n);
    // sin(pi k / N) evaluated once, exactly symmetric, so rows are reproducible.
    for (std::size_t k = 0; k < 2 * n; ++k)
        sine_table_[k] = std::sin(std::numbers::pi * static_cast<double>(k) / static_cast<double>(n));
}

std::vector<double> ModalBasis::mode_shapes_at(double x) const {
    std::vector<double> phi(modes_);
    mode_shapes_at(x, phi);
    return phi;
}

void ModalBasis::mode_shapes_at(double x, std::span<double> phi) const {
    const double norm = std::sqrt(2.0 / length_);
    for (std::size_t j = 0; j < modes_; ++j)
        phi[j] = norm * std::sin(static_cast<double>(j + 1) * std::numbers::pi * x / length_);
}

std::span<const double> ModalBasis::build_row(std::size_t i) const {
    AlignedVector& row = rows_[i];
    row.assign(modes_, 0.0);
    fill_row(i, row);
    return row;
}

std::span<const double> ModalBasis::row(std::size_t i, std::span<double> scratch) const {
    if (!rows_[i].empty()) return rows_[i];
    fill_row(i, scratch);
    return scratch.first(modes_);
}

void ModalBasis::fill_row(std::size_t i, std::span<double> r) const {
    const std::size_t period = 2 * (modes_ + 1);
    const double norm = std::sqrt(2.0 / length_);
    std::size_t k = 0;
    for (std::size_t j = 0; j < modes_; ++j) {
        k += i + 1;  // k = (i+1)(j+1) mod 2N
        if (k >= period) k -= period;
        r[j] = norm * sine_table_[k];
    }
}

void ModalBasis::to_grid(std::span<const double> q, std::span<double> u) const {
    // S q = sqrt(2/L) sum_j q_j sin(pi i j / N) = RODFT00(q) / sqrt(2 L)
    transform_->apply(q, u, 1.0 / std::sqrt(2.0 * length_));
}

void ModalBasis::to_modes(std::span<const double> u, std::span<double> q) const {
    transform_->apply(u, q, dx_ / std::sqrt(2.0 * length_));
}

std::vector<double> ModalBasis::displacement_at_grid(std::span<const double> q) const {
    std::vector<double> u(modes_);
    to_grid(q, u);
    return u;
}

double ModalBasis::transform_flops() const { return transform_->planned_flops(); }

}  // namespace fretbuzz
