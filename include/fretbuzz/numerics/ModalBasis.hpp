#pragma once
// The modes of a simply supported string, phi_j(x) = sqrt(2/L) sin(j pi x / L),
// j = 1..Nm, and the grid of Nm interior points x_i = i L/(Nm+1) on which they
// are discretely orthogonal (Issanchou et al. 2017, section 3): S_ij = phi_j(x_i),
// S^-1 = dx S^T. Rows of S are made on demand and kept, so a run that only ever
// looks at a few points never pays for the whole matrix.
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "fretbuzz/numerics/CacheAligned.hpp"

#include "fretbuzz/numerics/SineTransform.hpp"

namespace fretbuzz {

class ModalBasis {
public:
    ModalBasis(double length_m, std::size_t mode_count, bool measure_transform = false);

    std::size_t mode_count() const { return modes_; }
    double length() const { return length_; }
    double grid_step() const { return dx_; }
    double grid_point(std::size_t i) const { return static_cast<double>(i + 1) * dx_; }

    // phi_j(x) for j = 1..Nm at any x in [0, L].
    std::vector<double> mode_shapes_at(double x) const;
    // The same into `phi` (mode_count() values), allocating nothing.
    void mode_shapes_at(double x, std::span<double> phi) const;
    // Row i of S: phi_j(x_i) for j = 1..Nm (reference stays valid for the basis' life). Inline
    // once built: a step asks for its points' rows several times.
    std::span<const double> row(std::size_t i) const {
        const AlignedVector& r = rows_[i];
        return r.empty() ? build_row(i) : std::span<const double>(r);
    }
    // Row i: the kept one if it was built, else written into `scratch` (size mode_count())
    // without keeping it. For passes over every point once (all rows kept would be N^2 numbers).
    std::span<const double> row(std::size_t i, std::span<double> scratch) const;
    // u = S q on the whole grid (fast transform).
    void to_grid(std::span<const double> q, std::span<double> u) const;
    // FFTW's estimated operation count of one transform (see SineTransform).
    double transform_flops() const;
    // q = dx S^T u (fast transform).
    void to_modes(std::span<const double> u, std::span<double> q) const;
    std::vector<double> displacement_at_grid(std::span<const double> q) const;

private:
    double length_;
    std::size_t modes_;
    double dx_;
    void fill_row(std::size_t i, std::span<double> r) const;
    std::span<const double> build_row(std::size_t i) const;  // row i, built and kept

    std::vector<double> sine_table_;  // sin(pi k / N), k = 0..2N-1
    std::unique_ptr<SineTransform> transform_;
    mutable std::vector<AlignedVector> rows_;
};

}  // namespace fretbuzz
