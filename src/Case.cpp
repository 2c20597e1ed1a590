#include "fretbuzz/Case.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/scheme/ModalBasis.hpp"

namespace fretbuzz {

bool Case::has_obstacle() const {
    return std::any_of(obstacle_height_m.begin(), obstacle_height_m.end(), [](double g) { return std::isfinite(g); });
}

void Case::make_lossless() { std::fill(modes.sigma_per_s.begin(), modes.sigma_per_s.end(), 0.0); }

namespace {

void require_length(const std::string& name, std::size_t actual, std::size_t expected) {
    if (actual != expected) {
        std::ostringstream out;
        out << name << " has " << actual << " values but the case has " << expected << " modes";
        throw InputError(out.str());
    }
}

void check_initial_shape_clears_obstacle(const Case& c) {
    const ModalBasis basis(c.string.length_m, c.mode_count());
    const std::vector<double> u0 = basis.displacement_at_grid(c.initial_displacement);
    // Touching is allowed; penetrating beyond round-off of the shape is not.
    double scale = 0.0;
    for (double v : u0) scale = std::max(scale, std::abs(v));
    const double tolerance = 1e-12 * scale;
    const double s = c.contact_orientation();
    for (std::size_t i = 0; i < u0.size(); ++i) {
        const double g = c.obstacle_height_m[i];
        if (!std::isfinite(g)) continue;  // nothing to touch here
        if (s * u0[i] < s * g - tolerance) {
            std::ostringstream out;
            out.precision(6);
            out << "initial shape penetrates the obstacle at x = " << c.grid_point(i) << " m: u = " << u0[i] << " m is "
                << (c.obstacle_above ? "above" : "below") << " the obstacle height " << g
                << " m; the initial displacement must satisfy u(x, 0) " << (c.obstacle_above ? "<=" : ">=")
                << " g(x) everywhere";
            throw InputError(out.str());
        }
    }
}

}  // namespace

void Case::validate() const {
    require_positive("string.L (length, m)", string.length_m);
    require_positive("string.T (tension, N)", string.tension_n);
    require_positive("string.mu (linear density, kg/m)", string.linear_density);
    modes.validate();
    const std::size_t n = mode_count();
    require_length("obstacle heights", obstacle_height_m.size(), n);
    require_length("initial displacement", initial_displacement.size(), n);
    require_length("initial velocity", initial_velocity.size(), n);
    for (std::size_t i = 0; i < n; ++i) {
        const double g = obstacle_height_m[i];
        if (std::isnan(g) || g == std::numeric_limits<double>::infinity())
            throw InputError(out_of_range_message("obstacle height at x = " + std::to_string(grid_point(i)) + " m", g,
                                                  "must be finite (or -inf for no obstacle)"));
        require_finite("initial displacement of mode " + std::to_string(i + 1), initial_displacement[i]);
        require_finite("initial velocity of mode " + std::to_string(i + 1), initial_velocity[i]);
    }
    require_positive("contact.K (penalty stiffness)", contact.stiffness);
    require_at_least("contact.alpha (penalty exponent)", contact.exponent, 1.0);
    require_positive("run.fs (sample rate, Hz)", run.sample_rate_hz);
    require_positive("run.duration (s)", run.duration_s);
    if (run.sample_rate_hz * run.duration_s > 4e9)
        throw InputError(out_of_range_message("run.fs * run.duration (number of steps)",
                                              run.sample_rate_hz * run.duration_s, "must be <= 4e9"));
    if (run.output_rate_hz) {
        require_positive("run.output_rate (Hz)", *run.output_rate_hz);
        if (*run.output_rate_hz > run.sample_rate_hz)
            throw InputError(out_of_range_message("run.output_rate (Hz)", *run.output_rate_hz,
                                                  "must not exceed run.fs = " + std::to_string(run.sample_rate_hz) +
                                                      " Hz (set a lower output rate, or \"native\")"));
    }
    require_positive("audio.rate (Hz)", run.audio_rate_hz);
    if (run.audio_rate_hz < 8000.0 || run.audio_rate_hz > 384000.0)
        throw InputError(out_of_range_message("audio.rate (Hz)", run.audio_rate_hz, "must be in [8000, 384000]"));
    if (observation_points_m.empty()) throw InputError("observe: at least one observation point is required");
    for (double x : observation_points_m) {
        require_finite("observation point x (m)", x);
        if (!(x > 0.0 && x < string.length_m))
            throw InputError(out_of_range_message("observation point x (m)", x,
                                                  "must lie inside the string, in (0, L) = (0, " +
                                                      std::to_string(string.length_m) + ")"));
    }
    check_initial_shape_clears_obstacle(*this);
}

}  // namespace fretbuzz
