#include "fretbuzz/Case.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
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

// Quantities derived from several inputs, checked before a run plans anything: each would
// otherwise overflow deep inside the scheme and surface as a divergence naming nothing.
void check_derived_quantities(const Case& c) {
    const double fs = c.run.sample_rate_hz;
    const double dt = 1.0 / fs;
    if (std::lround(c.run.duration_s * fs) < 1) {
        std::ostringstream allowed;
        allowed << "must be at least one time step, 1/run.fs = " << dt << " s";
        throw InputError(out_of_range_message("run.duration (s)", c.run.duration_s, allowed.str()));
    }
    for (std::size_t j = 0; j < c.mode_count(); ++j) {
        const std::string mode = "mode " + std::to_string(j + 1);
        // e^{-sigma dt} and sinh of the overdamped rate overflow or underflow near sigma dt = 700;
        // a mode that loses e^-100 of its amplitude in one step is not a physical input anyway.
        const double sigma_dt = c.modes.sigma_per_s[j] * dt;
        if (!(sigma_dt <= Case::kMaxSigmaDt)) {
            std::ostringstream allowed;
            allowed << "sigma * dt = " << sigma_dt << " at run.fs = " << fs << " Hz; must be <= " << Case::kMaxSigmaDt
                    << " (lower the damping or raise fs)";
            throw InputError(out_of_range_message(mode + " sigma_per_s", c.modes.sigma_per_s[j], allowed.str()));
        }
        // The one-step map evaluates sin(omega dt): far above fs its phase is round-off.
        const double omega_dt = 2.0 * std::numbers::pi * c.modes.frequency_hz[j] * dt;
        if (!(omega_dt <= Case::kMaxOmegaDt)) {
            std::ostringstream allowed;
            allowed << "omega * dt = " << omega_dt << " at run.fs = " << fs << " Hz; must be <= " << Case::kMaxOmegaDt;
            throw InputError(out_of_range_message(mode + " frequency_hz", c.modes.frequency_hz[j], allowed.str()));
        }
    }
    // The energy is mu / (2 dt^2) times a sum over modes: both must be representable.
    const double scale = c.string.linear_density / (2.0 * dt * dt);
    if (!std::isfinite(scale)) {
        std::ostringstream allowed;
        allowed << "with run.fs = " << fs << " Hz the energy scale mu fs^2 / 2 overflows; must keep mu * fs^2 finite";
        throw InputError(out_of_range_message("string.mu (linear density, kg/m)", c.string.linear_density, allowed.str()));
    }
    double initial = 0.0;  // (1/2) mu sum_j (v_j^2 + omega_j^2 q_j^2)
    for (std::size_t j = 0; j < c.mode_count(); ++j) {
        const double omega = 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
        const double q = c.initial_displacement[j] * omega, v = c.initial_velocity[j];
        initial += 0.5 * c.string.linear_density * (v * v + q * q);
    }
    if (!std::isfinite(initial))
        throw InputError(out_of_range_message(
            "string.mu (linear density, kg/m)", c.string.linear_density,
            "with this initial displacement and velocity the initial energy overflows; must keep the energy finite"));
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
    if (contact.exponent > kMaxExponent)
        throw InputError(out_of_range_message("contact.alpha (penalty exponent)", contact.exponent,
                                              "must be in [1, " + std::to_string(static_cast<int>(kMaxExponent)) + "]"));
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
    check_derived_quantities(*this);
    check_initial_shape_clears_obstacle(*this);
}

}  // namespace fretbuzz
