#pragma once
// Signals compared by convergence studies: the displacement at one observation point,
// sampled at a rate every run shares, and the relative L2 distance between two of them.
#include <cstddef>
#include <span>
#include <vector>

#include "fretbuzz/run/RunObserver.hpp"

namespace fretbuzz {

struct SampledSignal {
    double rate_hz = 0.0;        // samples at t_k = k / rate_hz, k = 0, 1, ...
    std::vector<double> values;
};

// Keeps u at one observation point at the run's output rate, up to a time limit.
class ObservationRecorder : public RunObserver {
public:
    ObservationRecorder(std::size_t point_index, double until_s);
    void begin(const RunLayout& layout) override;
    void observation(double t, std::span<const double> u) override;
    const SampledSignal& signal() const { return signal_; }

private:
    std::size_t point_;
    double until_;
    SampledSignal signal_;
};

// sqrt(sum (a_k - r_k)^2 / sum r_k^2) over the first `count` samples (0: all of the shorter).
double relative_l2_error(std::span<const double> a, std::span<const double> reference, std::size_t count = 0);

// Observed order between two levels: log(e_coarse / e_fine) / log(p_fine / p_coarse).
double observed_order(double coarse_parameter, double coarse_error, double fine_parameter, double fine_error);

}  // namespace fretbuzz
