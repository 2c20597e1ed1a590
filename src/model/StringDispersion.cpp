#include "fretbuzz/model/StringDispersion.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fretbuzz/Error.hpp"

namespace fretbuzz {

namespace {
// Least-squares slope of y against x (0 with fewer than two distinct x).
double fitted_slope(const std::vector<double>& x, const std::vector<double>& y, std::size_t from) {
    const auto n = static_cast<double>(x.size() - from);
    double mx = 0.0, my = 0.0;
    for (std::size_t i = from; i < x.size(); ++i) {
        mx += x[i] / n;
        my += y[i] / n;
    }
    double sxy = 0.0, sxx = 0.0;
    for (std::size_t i = from; i < x.size(); ++i) {
        sxy += (x[i] - mx) * (y[i] - my);
        sxx += (x[i] - mx) * (x[i] - mx);
    }
    return sxx > 0.0 ? sxy / sxx : 0.0;
}
}  // namespace

StringDispersion::StringDispersion(const ModeTable& modes, double length_m) : length_m_(length_m) {
    require_positive("string length (m)", length_m);
    if (modes.size() == 0) throw InputError("mode table: at least one mode is needed for the string's dispersion");
    const std::size_t n = modes.size();
    std::vector<double> squared_wavenumber(n);
    for (std::size_t j = 0; j < n; ++j) {
        const double k = static_cast<double>(j + 1) * std::numbers::pi / length_m;
        const double c = 2.0 * std::numbers::pi * modes.frequency_hz[j] / k;
        wavenumber_.push_back(k);
        squared_wavenumber[j] = k * k;
        squared_speed_.push_back(c * c);
    }
    sigma_ = modes.sigma_per_s;
    source_ = modes.source;
    const std::size_t from = n - std::min(n, std::max<std::size_t>(2, n / 8));
    speed_beyond_.slope = std::max(0.0, fitted_slope(squared_wavenumber, squared_speed_, from));
    sigma_beyond_.slope = std::max(0.0, fitted_slope(squared_wavenumber, sigma_, from));
}

double StringDispersion::interpolate(const std::vector<double>& values, const Line& beyond, double wavenumber) const {
    const double x = wavenumber * wavenumber;
    const std::size_t n = values.size();
    if (wavenumber >= wavenumber_.back()) return values.back() + beyond.slope * (x - wavenumber_.back() * wavenumber_.back());
    if (wavenumber <= wavenumber_.front()) return values.front();
    // k_j = j pi / L: the interval holding k is found, not searched.
    auto j = static_cast<std::size_t>(std::floor(wavenumber * length_m_ / std::numbers::pi)) - 1;
    j = std::min(j, n - 2);
    const double x0 = wavenumber_[j] * wavenumber_[j], x1 = wavenumber_[j + 1] * wavenumber_[j + 1];
    const double s = (x - x0) / (x1 - x0);
    return (1.0 - s) * values[j] + s * values[j + 1];
}

double StringDispersion::frequency_hz(double wavenumber) const {
    return wavenumber * std::sqrt(interpolate(squared_speed_, speed_beyond_, wavenumber)) / (2.0 * std::numbers::pi);
}

double StringDispersion::sigma_per_s(double wavenumber) const {
    return std::max(0.0, interpolate(sigma_, sigma_beyond_, wavenumber));
}

ModeTable StringDispersion::pinned_modes(double length_m, std::size_t count) const {
    require_positive("pinned length (m)", length_m);
    ModeTable t;
    for (std::size_t m = 1; m <= count; ++m) {
        const double k = static_cast<double>(m) * std::numbers::pi / length_m;
        t.frequency_hz.push_back(frequency_hz(k));
        t.sigma_per_s.push_back(sigma_per_s(k));
        const auto nearest = static_cast<std::size_t>(std::max(1L, std::lround(k * length_m_ / std::numbers::pi)));
        t.source.push_back(source_[std::min(nearest, source_.size()) - 1]);
    }
    return t;
}

}  // namespace fretbuzz
