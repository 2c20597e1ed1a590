#include "fretbuzz/scheme/Plan.hpp"

#include <algorithm>
#include <cmath>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/SamplingCheck.hpp"

namespace fretbuzz {

Plan::Plan(const Case& c, double dt, PlanOptions options)
    : dt_(dt),
      mu_(c.string.linear_density),
      basis_(c.string.length_m, c.mode_count(), options.measure_transform),
      propagator_(c.modes, dt),
      contact_(c.contact.stiffness, c.contact.exponent),
      obstacle_(c.obstacle_height_m),
      fingers_(c.fingers),
      forces_(c.forces),
      options_(options) {
    require_positive("time step dt (s)", dt);
    // Without an obstacle the modal update is exact at any dt: nothing can alias.
    if (c.has_obstacle()) warnings_ = require_sampling(c.modes, 1.0 / dt, c.run.allow_aliasing).warnings;
    // An obstacle above is solved as its mirror image below (u -> -u).
    if (c.obstacle_above)
        for (double& g : obstacle_)
            if (std::isfinite(g)) g = -g;
    for (std::size_t i = 0; i < obstacle_.size(); ++i)
        if (std::isfinite(obstacle_[i])) obstacle_points_.push_back(i);
    transform_threshold_ = options.transform_threshold != 0 ? options.transform_threshold
                                                            : default_transform_threshold(mode_count());
}

std::size_t Plan::default_transform_threshold(std::size_t modes) {
    // A sine transform of length N runs through a real DFT of length 2(N+1): with N+1 made of
    // small primes it costs about 6 log2(N) products of a row of S with a vector; a large
    // prime factor p slows FFTW roughly by p/8 (measured: N = 999, 7 us; N = 862, N+1 prime,
    // 75 us; one row product, 0.1 us). A fixed rule, not a timing, so runs are reproducible.
    std::size_t rest = modes + 1, largest = 1;
    for (std::size_t f = 2; f * f <= rest; ++f)
        while (rest % f == 0) {
            largest = f;
            rest /= f;
        }
    largest = std::max(largest, rest);
    const double penalty = std::max(1.0, static_cast<double>(largest) / 8.0);
    const double rows = 6.0 * std::log2(static_cast<double>(modes) + 1.0) * penalty;
    return std::clamp<std::size_t>(static_cast<std::size_t>(rows), 16, std::max<std::size_t>(16, modes / 2));
}

}  // namespace fretbuzz
