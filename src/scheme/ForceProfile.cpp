#include "fretbuzz/scheme/ForceProfile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <numbers>

#include "fretbuzz/numerics/Kernels.hpp"

namespace fretbuzz {

std::vector<double> pad_mean_shapes(const ModalBasis& basis, double x, double width) {
    std::vector<double> shape = basis.mode_shapes_at(x);
    // The pad's mean of sin(j pi x / L) over [x - w/2, x + w/2]: sin(j pi x / L) sin(h) / h.
    const double half_angle = 0.5 * std::numbers::pi * width / basis.length();
    if (half_angle > 0.0)
        for (std::size_t j = 0; j < shape.size(); ++j) {
            const double h = static_cast<double>(j + 1) * half_angle;
            shape[j] *= std::sin(h) / h;
        }
    return shape;
}

ForceProfile::ForceProfile(const ForceSpec& spec, const ModalBasis& basis, double dt, double along)
    : force_(spec.force_profile),
      along_(along),
      dt_(dt),
      quiet_from_s_(force_.zero_from()),  // (also with no share here: the other polarisation's)
      shape_(pad_mean_shapes(basis, spec.position_m, spec.width_m)),
      on_grid_(basis.mode_count(), 0.0) {
    basis.to_grid(shape_, on_grid_);
}

ForceProfile::ForceProfile(std::vector<double> shape, const ModalBasis& basis)
    : force_({}),
      along_(1.0),
      dt_(0.0),
      quiet_from_s_(std::numeric_limits<double>::infinity()),
      shape_(std::move(shape)),
      on_grid_(basis.mode_count(), 0.0),
      driven_(true) {
    basis.to_grid(shape_, on_grid_);
}

void ForceProfile::reshape(std::span<const double> shape, const ModalBasis& basis, std::span<double> scratch) {
    std::copy(shape.begin(), shape.end(), shape_.begin());
    for (std::size_t i = 0; i < on_grid_.size(); ++i)
        on_grid_[i] = kernels::dot(basis.row(i, scratch).data(), shape_.data(), shape_.size());
}

void ForceProfile::begin_step(std::span<const double> q, std::span<const double> d) {
    double now = 0.0;
    kernels::dot_current_previous(shape_.data(), q.data(), d.data(), q.size(), now, before_);
}

void ForceProfile::end_step(std::span<const double> q, double load) {
    work_ += 0.5 * load * (kernels::dot(shape_.data(), q.data(), q.size()) - before_);
}

}  // namespace fretbuzz
