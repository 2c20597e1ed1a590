#include "fretbuzz/analysis/SubbandFilter.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <mutex>
#include <stdexcept>

#include "FastLength.hpp"
#include "fretbuzz/numerics/SineTransform.hpp"

namespace fretbuzz {

namespace {

using std::numbers::pi;

double median(std::vector<double> v) {
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

double interpolate(const std::vector<double>& x, const std::vector<double>& y, double at) {
    if (x.empty()) return 1.0;
    if (at <= x.front()) return y.front();
    if (at >= x.back()) return y.back();
    const auto upper = static_cast<std::size_t>(std::upper_bound(x.begin(), x.end(), at) - x.begin());
    const double w = (at - x[upper - 1]) / (x[upper] - x[upper - 1]);
    return (1.0 - w) * y[upper - 1] + w * y[upper];
}

}  // namespace

double BasebandSignal::gain_at(double frequency_hz) const {
    return interpolate(gain_frequency_hz, gain, frequency_hz);
}

SubbandFilter::SubbandFilter(std::span<const double> signal, double rate_hz) : rate_(rate_hz), size_(signal.size()) {
    if (size_ < 4) throw std::invalid_argument("SubbandFilter: signal too short");
    std::vector<double> input(signal.begin(), signal.end());
    spectrum_.resize(size_ / 2 + 1);
    const int n = static_cast<int>(size_);
    fftw_plan plan = nullptr;
    {
        std::lock_guard lock(fftw_planner_mutex());
        plan = fftw_plan_dft_r2c_1d(n, input.data(), reinterpret_cast<fftw_complex*>(spectrum_.data()), FFTW_ESTIMATE);
    }
    fftw_execute(plan);
    std::lock_guard lock(fftw_planner_mutex());
    fftw_destroy_plan(plan);
}

BasebandSignal SubbandFilter::extract(const FrequencyBand& band, double whitening_window_hz) const {
    const double df = rate_ / static_cast<double>(size_);
    const auto last_bin = static_cast<long>(spectrum_.size()) - 1;
    const long k_lo = std::clamp(static_cast<long>(std::floor((band.low_hz - band.taper_hz) / df)), 1L, last_bin);
    const long k_hi = std::clamp(static_cast<long>(std::ceil((band.high_hz + band.taper_hz) / df)), k_lo, last_bin);
    const long k_c = (k_lo + k_hi) / 2;
    const std::size_t length = smooth_length(static_cast<std::size_t>(std::ceil(1.25 * static_cast<double>(k_hi - k_lo + 1))));

    BasebandSignal out;
    out.rate_hz = static_cast<double>(length) * df;
    out.center_hz = static_cast<double>(k_c) * df;

    // Noise floor on a coarse grid: the median of the periodogram over the window.
    std::vector<double> floor_at_bin;
    if (whitening_window_hz > 0.0) {
        const long half = std::max(2L, static_cast<long>(whitening_window_hz / (2.0 * df)));
        const long step = std::max(1L, half / 4);
        for (long k = k_lo; k <= k_hi + step; k += step) {
            const long a = std::max(1L, k - half), b = std::min(last_bin, k + half);
            std::vector<double> power;
            for (long i = a; i <= b; ++i) power.push_back(std::norm(spectrum_[static_cast<std::size_t>(i)]));
            out.gain_frequency_hz.push_back(static_cast<double>(k) * df);
            out.gain.push_back(std::sqrt(std::max(median(power), 1e-300)));
        }
        double mean = 0.0;
        for (double g : out.gain) mean += g;
        mean /= static_cast<double>(out.gain.size());
        for (double& g : out.gain) g /= mean;
    }

    std::vector<std::complex<double>> buffer(length, 0.0);
    for (long k = k_lo; k <= k_hi; ++k) {
        const double f = static_cast<double>(k) * df;
        double mask = 1.0;
        if (f < band.low_hz) mask = 0.5 * (1.0 + std::cos(pi * (band.low_hz - f) / band.taper_hz));
        if (f > band.high_hz) mask = 0.5 * (1.0 + std::cos(pi * (f - band.high_hz) / band.taper_hz));
        if (f < band.low_hz - band.taper_hz || f > band.high_hz + band.taper_hz) mask = 0.0;
        const double gain = out.gain.empty() ? 1.0 : out.gain_at(f);
        const auto index = static_cast<std::size_t>((k - k_c + static_cast<long>(length)) % static_cast<long>(length));
        buffer[index] = 2.0 * spectrum_[static_cast<std::size_t>(k)] * mask / gain / static_cast<double>(size_);
    }
    auto* data = reinterpret_cast<fftw_complex*>(buffer.data());
    fftw_plan plan = nullptr;
    {
        std::lock_guard lock(fftw_planner_mutex());
        plan = fftw_plan_dft_1d(static_cast<int>(length), data, data, FFTW_BACKWARD, FFTW_ESTIMATE);
    }
    fftw_execute(plan);
    {
        std::lock_guard lock(fftw_planner_mutex());
        fftw_destroy_plan(plan);
    }
    out.samples = std::move(buffer);
    return out;
}

}  // namespace fretbuzz
