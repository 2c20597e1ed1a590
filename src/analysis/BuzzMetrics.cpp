#include "fretbuzz/analysis/BuzzMetrics.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/numerics/SineTransform.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"

namespace fretbuzz {

std::vector<std::size_t> obstacle_features(std::span<const double> g) {
    const std::size_t n = g.size();
    std::vector<std::size_t> centre;  // grid index of each feature's plateau centre
    for (std::size_t i = 1; i + 1 < n;) {
        std::size_t j = i;
        while (j + 1 < n && g[j + 1] == g[i]) ++j;  // the plateau [i, j]
        if (std::isfinite(g[i]) && j + 1 < n && g[i - 1] < g[i] && g[j + 1] < g[i]) centre.push_back((i + j) / 2);
        i = j + 1;
    }
    std::vector<std::size_t> feature(n, 0);
    if (centre.empty()) return feature;
    const auto distance = [](std::size_t a, std::size_t b) { return a > b ? a - b : b - a; };
    std::size_t k = 0;
    for (std::size_t i = 0; i < n; ++i) {
        while (k + 1 < centre.size() && distance(centre[k + 1], i) < distance(centre[k], i)) ++k;
        feature[i] = k + 1;
    }
    return feature;
}

std::vector<double> hann_power_spectrum(std::span<const double> signal) {
    const std::size_t n = signal.size();
    double* in = fftw_alloc_real(n);
    fftw_complex* out = fftw_alloc_complex(n / 2 + 1);
    fftw_plan plan = nullptr;
    {
        std::lock_guard lock(fftw_planner_mutex());
        plan = fftw_plan_dft_r2c_1d(static_cast<int>(n), in, out, FFTW_ESTIMATE);
    }
    // Hann window: the fundamental's leakage falls as 1/f^3 and stays far below the buzz.
    for (std::size_t i = 0; i < n; ++i)
        in[i] = signal[i] * 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n)));
    fftw_execute(plan);
    std::vector<double> power(n / 2 + 1);
    for (std::size_t k = 0; k <= n / 2; ++k) power[k] = out[k][0] * out[k][0] + out[k][1] * out[k][1];
    std::lock_guard lock(fftw_planner_mutex());
    fftw_destroy_plan(plan);
    fftw_free(in);
    fftw_free(out);
    return power;
}

double high_frequency_energy(std::span<const double> signal, double rate_hz, double band_hz) {
    const std::size_t n = signal.size();
    if (n < 2 || !(band_hz < 0.5 * rate_hz)) return std::numeric_limits<double>::quiet_NaN();
    const std::vector<double> power = hann_power_spectrum(signal);
    double energy = 0.0;
    const double bin_hz = rate_hz / static_cast<double>(n);
    for (std::size_t k = 0; k <= n / 2; ++k) {
        if (static_cast<double>(k) * bin_hz < band_hz) continue;
        const double weight = (k == 0 || 2 * k == n) ? 1.0 : 2.0;  // one-sided spectrum
        energy += weight * power[k];
    }
    return energy / static_cast<double>(n);  // Parseval: sum |u_i|^2 = (1/n) sum |U_k|^2
}

std::size_t first_buzz_point(const Case& c) {
    if (c.fingers.empty()) return 0;
    double edge = 0.0;
    for (const FingerSpec& f : c.fingers) edge = std::max(edge, f.position_m + 0.5 * f.width_m);
    const std::vector<std::size_t> feature = obstacle_features(c.obstacle_on_grid());
    const std::size_t n = c.obstacle_height_m.size();
    const auto point_at = [&](double x) {
        const double i = std::round(x / c.grid_step()) - 1.0;
        return static_cast<std::size_t>(std::clamp(i, 0.0, static_cast<double>(n - 1)));
    };
    const auto stop = std::lower_bound(c.fret_positions_m.begin(), c.fret_positions_m.end(), edge);
    if (stop == c.fret_positions_m.end() || feature.empty()) return std::min(point_at(edge) + 1, n);
    const std::size_t stopping = feature[point_at(*stop)];
    std::size_t i = point_at(*stop);
    while (i < n && feature[i] <= stopping) ++i;
    return i;
}

Case without_obstacle_from(const Case& c, std::size_t first) {
    Case free = c;
    for (std::size_t i = first; i < free.obstacle_height_m.size(); ++i)
        free.obstacle_height_m[i] = -std::numeric_limits<double>::infinity();
    const double from = first == 0 ? -std::numeric_limits<double>::infinity() : c.grid_point(first) - 0.5 * c.grid_step();
    std::erase_if(free.point_obstacles, [&](const PointObstacle& p) { return p.x_m >= from; });
    return free;
}

void BuzzMetrics::begin(const RunLayout& layout) {
    dt_ = layout.dt;
    output_rate_ = layout.output_rate_hz;
    dx_ = layout.source->grid_step();
    feature_of_point_ = obstacle_features(layout.source->obstacle_on_grid());
    const std::size_t features =
        feature_of_point_.empty() ? 0 : *std::max_element(feature_of_point_.begin(), feature_of_point_.end());
    feature_impulse_.assign(features + 1, 0.0);
    touched_.assign(layout.source->mode_count(), 0);
    first_counted_ = first_buzz_point(*layout.source);
    // The pads of fingers and gestures carry the hand's forces, not the obstacle's.
    hand_.assign(layout.source->mode_count(), 0);
    const auto mark = [&](double centre, double width) {
        for (std::size_t i : pad_points(centre, width, dx_, hand_.size())) hand_[i] = 1;
    };
    for (const FingerSpec& f : layout.source->fingers) mark(f.position_m, f.width_m);
    for (const ForceSpec& f : layout.source->forces) mark(f.position_m, f.width_m);
    signal_.clear();
    report_ = {};
}

void BuzzMetrics::observation(double, std::span<const double> u) {
    if (!u.empty()) signal_.push_back(u[0]);
}

void BuzzMetrics::energy(double, double, double, double dissipated) {
    if (have_dissipated_ && contact_since_energy_) report_.energy_lost_in_contact_j += dissipated - last_dissipated_;
    last_dissipated_ = dissipated;
    have_dissipated_ = true;
    contact_since_energy_ = false;
}

void BuzzMetrics::contacts(double t, std::span<const std::pair<std::size_t, double>> forces) {
    const auto counted = [this](std::size_t i) { return i >= first_counted_ && hand_[i] == 0; };
    if (std::none_of(forces.begin(), forces.end(), [&](const auto& p) { return counted(p.first); }))
        return;  // only the hand's forces: no buzz at this step
    // A gap longer than episode_gap_s since the last contact step starts a new episode.
    if (report_.contact_steps == 0 || t - last_contact_t_ > std::max(episode_gap_s_, 1.5 * dt_)) ++report_.episodes;
    if (report_.contact_steps == 0) report_.first_contact_s = t;
    report_.last_contact_s = t;
    last_contact_t_ = t;
    ++report_.contact_steps;
    contact_since_energy_ = true;
    double total = 0.0;
    for (const auto& [i, f] : forces) {
        if (!counted(i)) continue;
        total += f * dx_;
        touched_[i] = 1;
        feature_impulse_[feature_of_point_[i]] += f * dx_ * dt_;
    }
    report_.peak_force_n = std::max(report_.peak_force_n, total);
    report_.impulse_n_s += total * dt_;
}

void BuzzMetrics::finish(const RunSummary&) {
    report_.contact_time_s = static_cast<double>(report_.contact_steps) * dt_;
    for (std::size_t i = 0; i < touched_.size(); ++i) {
        if (!touched_[i]) continue;
        const double x = static_cast<double>(i + 1) * dx_;
        if (report_.touched_points == 0) report_.touched_x_min_m = x;
        report_.touched_x_max_m = x;
        ++report_.touched_points;
        const std::size_t f = feature_of_point_[i];
        if (f != 0 && (report_.touched_features.empty() || report_.touched_features.back() != f))
            report_.touched_features.push_back(f);
    }
    double largest = 0.0;
    for (std::size_t f = 1; f < feature_impulse_.size(); ++f)
        if (feature_impulse_[f] > largest) {
            largest = feature_impulse_[f];
            report_.main_feature = f;
        }
    report_.high_frequency_energy = high_frequency_energy(signal_, output_rate_, band_hz_);
}

double buzz_level_db(double with_obstacle, double without_obstacle) {
    if (!(with_obstacle > 0.0) || !(without_obstacle > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return 10.0 * std::log10(with_obstacle / without_obstacle);
}

}  // namespace fretbuzz
