#include "fretbuzz/sweep/Convergence.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <numeric>
#include <sstream>
#include <thread>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/run/ConvergenceSignal.hpp"
#include "fretbuzz/run/Simulation.hpp"

namespace fretbuzz {

std::string parameter_name(ConvergenceParameter parameter) {
    return parameter == ConvergenceParameter::sample_rate ? "fs" : "K";
}

namespace {

std::string ten_digits(double value) {
    std::ostringstream out;
    out.precision(10);
    out << value;
    return out.str();
}

bool is_whole(double value) { return std::abs(value - std::round(value)) <= 1e-9 * std::max(1.0, value); }

bool divides(double rate, double divisor) { return is_whole(rate / divisor); }

}  // namespace

double common_comparison_rate(const std::vector<double>& sample_rates_hz, std::optional<double> requested,
                              double window_s, std::size_t minimum_samples, double ceiling_hz) {
    double rate = 0.0;
    if (requested) {
        require_positive("--compare-rate", *requested);
        for (double fs : sample_rates_hz)
            if (!divides(fs, *requested))
                throw InputError(out_of_range_message("--compare-rate", *requested,
                                                      "must divide every sampling rate exactly, and fs = " +
                                                          ten_digits(fs) + " Hz is not a multiple of it"));
        rate = *requested;
    } else {
        long long common = 0;
        for (double fs : sample_rates_hz) {
            if (!is_whole(fs))
                throw InputError("no common comparison rate: fs = " + ten_digits(fs) +
                                 " Hz is not a whole number of Hz; choose whole rates or give --compare-rate");
            common = std::gcd(common, std::llround(fs));
        }
        // The largest divisor of the common rate that is not above the ceiling.
        long long step = std::max(1LL, static_cast<long long>(std::ceil(static_cast<double>(common) / ceiling_hz)));
        while (common % step != 0) ++step;
        rate = static_cast<double>(common / step);
    }
    const double samples = std::floor(window_s * rate + 1e-9) + 1.0;
    if (samples < static_cast<double>(minimum_samples))
        throw InputError("no common comparison rate: the sampling rates share only " + ten_digits(rate) + " Hz, which gives " +
                         ten_digits(samples) + " samples in the window of " + ten_digits(window_s) + " s (at least " +
                         std::to_string(minimum_samples) +
                         " are needed); choose rates with a larger common divisor (e.g. multiples of 1000 Hz)");
    return rate;
}

namespace {

struct PlannedRun {
    Case c;
    SampledSignal signal;
    double wall_seconds = 0.0;
};

void check_study(const ConvergenceStudy& s) {
    const std::string name = "--" + parameter_name(s.parameter);
    if (s.values.empty()) throw InputError(name + ": the list of levels is empty; give at least one value");
    for (double v : s.values) require_positive(name, v);
    if (s.reference) require_positive("--reference-" + parameter_name(s.parameter), *s.reference);
    require_positive("--window", s.window_s);
    if (s.duration_s) {
        require_positive("--duration", *s.duration_s);
        if (s.window_s > *s.duration_s)
            throw InputError(out_of_range_message("--window", s.window_s,
                                                  "must not exceed --duration = " + ten_digits(*s.duration_s) + " s"));
    }
    if (!(s.threshold > 0.0)) throw InputError(out_of_range_message("--threshold", s.threshold, "must be > 0"));
}

// Runs every case, at most `jobs` at a time; rethrows the first failure.
void run_all(std::vector<PlannedRun>& runs, std::size_t point_index, double window_s, unsigned jobs) {
    std::atomic<std::size_t> next{0};
    std::vector<std::exception_ptr> failures(runs.size());
    auto worker = [&] {
        for (std::size_t k = next++; k < runs.size(); k = next++) {
            try {
                ObservationRecorder recorder(point_index, window_s);
                RunObserver* observers[] = {&recorder};
                const auto start = std::chrono::steady_clock::now();
                simulate(runs[k].c, observers);
                runs[k].wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                runs[k].signal = recorder.signal();
            } catch (...) {
                failures[k] = std::current_exception();
            }
        }
    };
    {
        std::vector<std::jthread> workers;
        for (unsigned t = 0; t < jobs; ++t) workers.emplace_back(worker);
    }
    for (const std::exception_ptr& failure : failures)
        if (failure) std::rethrow_exception(failure);
}

}  // namespace

ConvergenceReport run_convergence(const ConvergenceStudy& study) {
    check_study(study);
    ConvergenceReport report;
    report.case_name = study.base.name;
    report.parameter = study.parameter;
    report.window_s = study.window_s;
    report.duration_s = study.duration_s.value_or(study.window_s);
    report.threshold = study.threshold;
    report.reference = study.reference.value_or(*std::max_element(study.values.begin(), study.values.end()));

    std::vector<double> levels;
    for (double v : study.values)
        if (v != report.reference) levels.push_back(v);
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    if (levels.empty())
        throw InputError("--" + parameter_name(study.parameter) +
                         ": every level equals the reference; give at least one level other than the reference");
    if (levels.back() > report.reference)
        throw InputError(out_of_range_message("--reference-" + parameter_name(study.parameter), report.reference,
                                              "must not be below the finest level " + ten_digits(levels.back())));

    Case base = study.base;
    report.observation_point_m = study.observation_point_m.value_or(
        base.observation_points_m.empty() ? 0.0 : base.observation_points_m.front());
    base.observation_points_m = {report.observation_point_m};
    base.run.duration_s = report.duration_s;
    // A study of fs measures the error that coarse rates make, aliasing included: no level is refused.
    base.run.allow_aliasing = true;
    report.fixed_sample_rate_hz = base.run.sample_rate_hz;

    std::vector<double> rates{base.run.sample_rate_hz};
    if (study.parameter == ConvergenceParameter::sample_rate) {
        rates = levels;
        rates.push_back(report.reference);
    }
    report.comparison_rate_hz = common_comparison_rate(rates, study.comparison_rate_hz, study.window_s);
    report.samples_compared = static_cast<std::size_t>(std::floor(study.window_s * report.comparison_rate_hz + 1e-9)) + 1;
    base.run.output_rate_hz = report.comparison_rate_hz;

    std::vector<PlannedRun> runs(levels.size() + 1, PlannedRun{base, {}, 0.0});  // the reference last
    for (std::size_t k = 0; k < runs.size(); ++k) {
        const double v = k < levels.size() ? levels[k] : report.reference;
        if (study.parameter == ConvergenceParameter::sample_rate)
            runs[k].c.run.sample_rate_hz = v;
        else
            runs[k].c.contact.stiffness = v;
        runs[k].c.validate();  // every level is checked before any runs
    }
    const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
    report.parallel_runs = static_cast<unsigned>(
        std::min<std::size_t>(runs.size(), std::min(hardware, study.jobs ? study.jobs : hardware)));
    run_all(runs, 0, study.window_s, report.parallel_runs);

    const SampledSignal& reference = runs.back().signal;
    report.reference_wall_seconds = runs.back().wall_seconds;
    for (std::size_t k = 0; k < levels.size(); ++k) {
        const SampledSignal& signal = runs[k].signal;
        if (signal.values.size() < report.samples_compared || reference.values.size() < report.samples_compared)
            throw SolverError("convergence: a run returned fewer samples than the window needs");
        ConvergenceLevel level;
        level.value = levels[k];
        level.relative_error = relative_l2_error(signal.values, reference.values, report.samples_compared);
        level.meets_threshold = level.relative_error < study.threshold;
        level.wall_seconds = runs[k].wall_seconds;
        if (k > 0) {
            const ConvergenceLevel& coarser = report.levels.back();
            const double order = observed_order(coarser.value, coarser.relative_error, level.value, level.relative_error);
            if (std::isfinite(order)) level.observed_order = order;
        }
        report.levels.push_back(level);
    }
    for (auto it = report.levels.rbegin(); it != report.levels.rend() && it->meets_threshold; ++it)
        report.threshold_met_from = it->value;
    return report;
}

}  // namespace fretbuzz
