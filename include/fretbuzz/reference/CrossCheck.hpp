#pragma once
// Runs one StringProblem with both discretisations and samples u(x, t) at the same
// instants, so the modal scheme can be checked against an independent one.
#include <cstddef>
#include <vector>

#include "fretbuzz/reference/StringProblem.hpp"
#include "fretbuzz/run/ConvergenceSignal.hpp"

namespace fretbuzz::reference {

struct FiniteDifferenceRun {
    std::size_t intervals = 0;   // N
    double courant = 0.9;        // dt <= courant * stability limit, rounded down to divide 1/output rate
    double duration_s = 0.0;
    double output_rate_hz = 0.0;
    double observation_point_m = 0.0;
};

struct FiniteDifferenceResult {
    SampledSignal signal;
    double dt = 0.0;
    double max_relative_energy_drift = 0.0;  // max_n |H + dissipated - H^{1/2}| / H^{1/2}
    double wall_seconds = 0.0;
};

FiniteDifferenceResult run_finite_difference(const StringProblem& problem, const FiniteDifferenceRun& run);

// The modal scheme through the library's simulate().
SampledSignal run_modal(const StringProblem& problem, const ModalDiscretisation& discretisation);

// The cross-check problem: a lossless ideal string (L = T = mu = 1, so c = 1 and the
// fundamental is 0.5 Hz) released from u = 0.05 sin(pi x) over a flat obstacle at -0.02,
// K = 1e6, alpha = 1.5: it slaps the obstacle over most of its length once per period.
StringProblem slapping_string_problem();

// One refinement level: the finite-difference scheme on N intervals at Courant number 0.8,
// the modal scheme on the same grid and step, both against a much finer modal run.
struct CrossCheckLevel {
    std::size_t intervals = 0;
    double dt = 0.0;
    double fd_to_reference = 0.0;     // relative L2 differences of u(x_obs, t)
    double modal_to_reference = 0.0;
    double fd_to_modal = 0.0;
    double fd_energy_drift = 0.0;     // max relative |H + dissipated - H^{1/2}|
    SampledSignal fd_signal;
};

struct CrossCheckStudy {
    StringProblem problem = slapping_string_problem();
    std::vector<std::size_t> intervals{80, 160, 320, 640};
    double courant = 0.8;
    double duration_s = 2.0;
    double output_rate_hz = 100.0;
    double observation_point_m = 0.25;
    std::size_t reference_modes = 1279;
    double reference_sample_rate_hz = 6400.0;
};

struct CrossCheckReport {
    SampledSignal reference;
    std::vector<CrossCheckLevel> levels;
};

CrossCheckReport run_cross_check(const CrossCheckStudy& study);

}  // namespace fretbuzz::reference
