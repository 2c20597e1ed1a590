#pragma once
// Convergence studies: one case run at several sampling rates (or penalty stiffnesses) and
// at a reference level, the observation signal of each compared with the reference by its
// relative L2 error over [0, window] (Issanchou et al. 2017: 0.3 s, threshold 0.1), and the
// observed order between successive levels. Runs go in parallel.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

enum class ConvergenceParameter { sample_rate, stiffness };

// "fs" or "K", as on the command line.
std::string parameter_name(ConvergenceParameter parameter);

struct ConvergenceStudy {
    Case base;
    ConvergenceParameter parameter = ConvergenceParameter::sample_rate;
    std::vector<double> values;               // the levels studied
    std::optional<double> reference;          // default: the largest value (then not studied itself)
    double window_s = 0.0;                    // errors over [0, window_s]
    std::optional<double> duration_s;         // simulated time, default window_s
    std::optional<double> observation_point_m;  // default: the case's first observation point
    double threshold = 0.1;
    std::optional<double> comparison_rate_hz;   // default: chosen from the sampling rates
    unsigned jobs = 0;                          // parallel runs; 0: the hardware's threads
};

struct ConvergenceLevel {
    double value = 0.0;
    double relative_error = 0.0;
    std::optional<double> observed_order;  // against the previous (coarser) level
    bool meets_threshold = false;
    double wall_seconds = 0.0;
};

struct ConvergenceReport {
    std::string case_name;
    ConvergenceParameter parameter = ConvergenceParameter::sample_rate;
    double reference = 0.0;
    double reference_wall_seconds = 0.0;
    double fixed_sample_rate_hz = 0.0;  // the rate of a stiffness study
    double window_s = 0.0;
    double duration_s = 0.0;
    double observation_point_m = 0.0;
    double comparison_rate_hz = 0.0;
    std::size_t samples_compared = 0;
    double threshold = 0.0;
    unsigned parallel_runs = 1;
    std::vector<ConvergenceLevel> levels;  // increasing value
    // The smallest level from which every finer level meets the threshold.
    std::optional<double> threshold_met_from;
};

// Checks the study (InputError naming the option at fault), runs it, compares.
ConvergenceReport run_convergence(const ConvergenceStudy& study);

// The rate at which runs at all these sampling rates can be compared sample for sample:
// `requested` if it divides every rate, else the largest divisor of their greatest common
// divisor not above `ceiling_hz`. Throws InputError when none gives `minimum_samples` in the window.
double common_comparison_rate(const std::vector<double>& sample_rates_hz, std::optional<double> requested,
                              double window_s, std::size_t minimum_samples = 100, double ceiling_hz = 48000.0);

}  // namespace fretbuzz
