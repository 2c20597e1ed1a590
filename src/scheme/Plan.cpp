#include "fretbuzz/scheme/Plan.hpp"

#include <cmath>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

Plan::Plan(const Case& c, double dt, PlanOptions options)
    : dt_(dt),
      mu_(c.string.linear_density),
      basis_(c.string.length_m, c.mode_count(), options.measure_transform),
      propagator_(c.modes, dt),
      contact_(c.contact.stiffness, c.contact.exponent),
      obstacle_(c.obstacle_height_m),
      options_(options) {
    require_positive("time step dt (s)", dt);
    for (std::size_t i = 0; i < obstacle_.size(); ++i)
        if (std::isfinite(obstacle_[i])) obstacle_points_.push_back(i);
    // A transform costs a few tens of row products at these sizes; measured by bench/.
    transform_threshold_ = options.transform_threshold != 0
                               ? options.transform_threshold
                               : std::max<std::size_t>(16, static_cast<std::size_t>(std::log2(mode_count() + 1) * 6));
}

}  // namespace fretbuzz
