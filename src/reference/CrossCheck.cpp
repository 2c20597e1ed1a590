#include "fretbuzz/reference/CrossCheck.hpp"

#include <chrono>
#include <cmath>
#include <numbers>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/reference/FiniteDifferenceString.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz::reference {

FiniteDifferenceResult run_finite_difference(const StringProblem& problem, const FiniteDifferenceRun& run) {
    require_positive("output rate", run.output_rate_hz);
    require_positive("duration", run.duration_s);
    if (!(run.courant > 0.0 && run.courant < 1.0))
        throw InputError(out_of_range_message("courant", run.courant, "must lie in (0, 1)"));
    const auto start = std::chrono::steady_clock::now();
    const SubnormalFlush flushed;  // a decaying string's short waves sink below 1e-308
    // An integer number of steps per output sample, so the samples fall on exact steps.
    const double limit = run.courant * stability_limit(problem, run.intervals);
    // (The small slack keeps an exact ratio from rounding up by one.)
    const long steps_per_sample =
        std::max(1L, static_cast<long>(std::ceil(1.0 / (run.output_rate_hz * limit) - 1e-9)));
    const double dt = 1.0 / (run.output_rate_hz * static_cast<double>(steps_per_sample));
    FiniteDifferenceString string(problem, run.intervals, dt);

    FiniteDifferenceResult result;
    result.dt = dt;
    result.signal.rate_hz = run.output_rate_hz;
    const long samples = std::lround(run.duration_s * run.output_rate_hz);
    result.signal.values.push_back(string.displacement_at(run.observation_point_m));
    double initial_energy = 0.0;
    for (long k = 1; k <= samples; ++k) {
        for (long s = 0; s < steps_per_sample; ++s) {
            string.step();
            if (string.step_index() == 1) initial_energy = string.energy();
            const double drift = std::abs(string.energy() + string.dissipated() - initial_energy);
            result.max_relative_energy_drift = std::max(result.max_relative_energy_drift, drift / initial_energy);
        }
        result.signal.values.push_back(string.displacement_at(run.observation_point_m));
    }
    result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

SampledSignal run_modal(const StringProblem& problem, const ModalDiscretisation& discretisation) {
    const Case c = to_modal_case(problem, discretisation);
    ObservationRecorder recorder(0, discretisation.duration_s);
    RunObserver* observers[] = {&recorder};
    simulate(c, observers);
    return recorder.signal();
}

StringProblem slapping_string_problem() {
    StringProblem p;
    p.obstacle = [](double) { return -0.02; };
    p.initial_shape = [](double x) { return 0.05 * std::sin(std::numbers::pi * x); };
    p.contact_stiffness = 1e6;
    p.contact_exponent = 1.5;
    return p;
}

CrossCheckReport run_cross_check(const CrossCheckStudy& s) {
    if (s.intervals.empty()) throw InputError("--N: the list of grids is empty");
    CrossCheckReport report;
    report.reference = run_modal(s.problem, {s.reference_modes, s.reference_sample_rate_hz, s.duration_s,
                                             s.output_rate_hz, s.observation_point_m});
    for (const std::size_t n : s.intervals) {
        CrossCheckLevel level;
        level.intervals = n;
        FiniteDifferenceResult fd =
            run_finite_difference(s.problem, {n, s.courant, s.duration_s, s.output_rate_hz, s.observation_point_m});
        const SampledSignal modal =
            run_modal(s.problem, {n - 1, 1.0 / fd.dt, s.duration_s, s.output_rate_hz, s.observation_point_m});
        level.dt = fd.dt;
        level.fd_to_reference = relative_l2_error(fd.signal.values, report.reference.values);
        level.modal_to_reference = relative_l2_error(modal.values, report.reference.values);
        level.fd_to_modal = relative_l2_error(fd.signal.values, modal.values);
        level.fd_energy_drift = fd.max_relative_energy_drift;
        level.fd_signal = std::move(fd.signal);
        report.levels.push_back(std::move(level));
    }
    return report;
}

}  // namespace fretbuzz::reference
