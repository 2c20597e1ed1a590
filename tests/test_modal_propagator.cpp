// Without an obstacle the scheme is the exact damped oscillator at any time step:
// the modal coordinates must equal the closed-form solution to round-off, including
// for dt far above the period of the highest mode (no numerical dispersion).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/Stepper.hpp"

namespace fretbuzz {
namespace {

// Closed-form damped motion in long double (a reference more precise than the scheme).
long double exact_motion(double nu, double sigma, double q0, double v0, long double t) {
    const long double w = 2.0L * std::numbers::pi_v<long double> * nu;
    const long double s = sigma;
    const long double envelope = std::exp(-s * t);
    if (s < w) {
        const long double wd = std::sqrt((w - s) * (w + s));
        return envelope * (q0 * std::cos(wd * t) + (v0 + s * q0) * std::sin(wd * t) / wd);
    }
    const long double g = std::sqrt((s - w) * (s + w));
    return envelope * (q0 * std::cosh(g * t) + (v0 + s * q0) * (g > 0 ? std::sinh(g * t) / g : t));
}

Case free_string_case() {
    Case c = load_case("bass-pop");
    c.obstacle_height_m.assign(c.mode_count(), -std::numeric_limits<double>::infinity());
    // A non-zero initial velocity too, so both initial conditions are checked.
    c.initial_velocity.resize(c.mode_count());
    for (std::size_t j = 0; j < c.mode_count(); ++j)
        c.initial_velocity[j] = 0.3 * c.initial_displacement[j] * 2.0 * std::numbers::pi * c.modes.frequency_hz[j];
    return c;
}

struct Exactness {
    double max_error = 0.0;  // max over steps and modes of |q - q_exact| / max_t |q_exact| (per mode)
};

Exactness compare_with_closed_form(const Case& c, double dt, long steps, std::size_t modes_checked = 0) {
    const Plan plan(c, dt);
    Stepper stepper(plan, c.initial_displacement, c.initial_velocity);
    const std::size_t n = modes_checked ? modes_checked : c.mode_count();
    std::vector<double> peak(n, 0.0), worst(n, 0.0);
    for (long k = 1; k <= steps; ++k) {
        stepper.step();
        const auto q = stepper.modal_displacement();
        for (std::size_t j = 0; j < n; ++j) {
            const long double exact = exact_motion(c.modes.frequency_hz[j], c.modes.sigma_per_s[j],
                                                   c.initial_displacement[j], c.initial_velocity[j],
                                                   static_cast<long double>(k) * dt);
            peak[j] = std::max(peak[j], static_cast<double>(std::abs(exact)));
            worst[j] = std::max(worst[j], static_cast<double>(std::abs(q[j] - exact)));
        }
    }
    Exactness e;
    for (std::size_t j = 0; j < n; ++j)
        if (peak[j] > 0.0) e.max_error = std::max(e.max_error, worst[j] / peak[j]);
    return e;
}

TEST(ModalPropagator, MatchesClosedFormAtSmallAndHugeSteps) {
    const Case c = free_string_case();
    const double nu_max = c.modes.frequency_hz.back();
    // From well resolved to dt = 50 periods of the highest mode; each run spans at most
    // ~300 periods of the highest mode so the long-double reference stays exact.
    for (const double periods : {0.05, 0.43, 3.7, 50.0}) {
        const double dt = periods / nu_max;
        const long steps = std::max(20L, std::lround(300.0 / periods));
        const Exactness e = compare_with_closed_form(c, dt, steps);
        EXPECT_LT(e.max_error, 1e-12) << "dt = " << dt << " s (" << periods << " periods of the highest mode)";
    }
}

TEST(ModalPropagator, LowModesStayExactOverManySmallSteps) {
    // 4 MHz: omega dt ~ 1.5e-4 for mode 1, where the textbook recursion A q^n - e q^{n-1}
    // loses about 8 digits. Round-off still adds up like n eps (about 1e-16 per step), so
    // 8 000 steps (2 ms) is where the 1e-12 bound is meaningful; all modes are checked.
    const Case c = free_string_case();
    const Exactness e = compare_with_closed_form(c, 1.0 / 4e6, 8000);
    EXPECT_LT(e.max_error, 1e-12);
}

TEST(ModalPropagator, OverdampedAndCriticalModesAreExact) {
    Case c = free_string_case();
    c.modes.frequency_hz.resize(3);
    c.modes.sigma_per_s = {2.0 * std::numbers::pi * 10.0 * 3.0, 2.0 * std::numbers::pi * 20.0, 1.0};
    c.modes.frequency_hz = {10.0, 20.0, 30.0};  // overdamped, critical, underdamped
    c.modes.source.resize(3);
    c.initial_displacement = {1e-3, -2e-3, 5e-4};
    c.initial_velocity = {0.1, 0.0, -0.2};
    c.obstacle_height_m.assign(3, -std::numeric_limits<double>::infinity());
    const Exactness e = compare_with_closed_form(c, 1e-3, 500);
    EXPECT_LT(e.max_error, 1e-12);
}

}  // namespace
}  // namespace fretbuzz
