#include "fretbuzz/run/ConvergenceSignal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

ObservationRecorder::ObservationRecorder(std::size_t point_index, double until_s)
    : point_(point_index), until_(until_s) {}

void ObservationRecorder::begin(const RunLayout& layout) {
    if (point_ >= layout.observation_points_m.size())
        throw InputError("observation point index " + std::to_string(point_) + " is out of range: the run has " +
                         std::to_string(layout.observation_points_m.size()) + " points");
    signal_.rate_hz = layout.output_rate_hz;
    signal_.values.clear();
    signal_.values.reserve(static_cast<std::size_t>(until_ * layout.output_rate_hz) + 2);
}

void ObservationRecorder::observation(double t, std::span<const double> u) {
    // Half a sample of slack: t is n dt in floating point.
    if (t <= until_ + 0.5 / signal_.rate_hz) signal_.values.push_back(u[point_]);
}

double relative_l2_error(std::span<const double> a, std::span<const double> reference, std::size_t count) {
    const std::size_t n = count ? count : std::min(a.size(), reference.size());
    if (n > a.size() || n > reference.size()) throw std::invalid_argument("relative_l2_error: signals too short");
    double difference = 0.0, norm = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        difference += (a[k] - reference[k]) * (a[k] - reference[k]);
        norm += reference[k] * reference[k];
    }
    return norm > 0.0 ? std::sqrt(difference / norm) : std::numeric_limits<double>::quiet_NaN();
}

double observed_order(double coarse_parameter, double coarse_error, double fine_parameter, double fine_error) {
    if (!(coarse_error > 0.0 && fine_error > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return std::log(coarse_error / fine_error) / std::log(fine_parameter / coarse_parameter);
}

}  // namespace fretbuzz
