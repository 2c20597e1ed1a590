#include "fretbuzz/analysis/DoubletResolution.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <optional>

namespace fretbuzz {

namespace {

using std::numbers::pi;

// Starts for a second partial beside a single one: separations in bins (beats in the record).
constexpr double kSplits[] = {0.5, 1.0, 2.0, 4.0};

struct Mode {
    std::size_t mode = 0, band = 0;
    std::vector<DampedPartial> poles;  // the stronger first
    std::size_t first = 0, last = 0;   // bins fitted
    bool merged = false, fitted = false;
    double noise_per_bin = 0.0;  // of the last fit
};

DampedPartial damped(const EstimatedPartial& p, double rate_hz) {
    const double s = p.sigma_per_s / (2.0 * pi);
    const double damped_hz = std::sqrt(std::max(0.0, p.frequency_hz * p.frequency_hz - s * s));
    DampedPartial d;
    d.decay = p.sigma_per_s / rate_hz;
    d.angle = 2.0 * pi * damped_hz / rate_hz;
    d.amplitude = std::polar(0.5 * p.amplitude, p.phase_rad);
    return d;
}

void sort_stronger_first(std::vector<DampedPartial>& poles) {
    std::sort(poles.begin(), poles.end(),
              [](const DampedPartial& a, const DampedPartial& b) { return std::abs(a.amplitude) > std::abs(b.amplitude); });
}

// The mode's partials as fitted, or nothing where the fit failed.
std::optional<SpectrumFit> fitted(const DecaySpectrum& spectrum, const Mode& m, const std::vector<std::complex<double>>& bins,
                                  std::vector<DampedPartial> start, double min_quality) {
    SpectrumFit f = spectrum.fit(m.first, bins, start);
    if (!f.valid) return std::nullopt;
    for (const DampedPartial& p : f.partials)
        if (!(p.angle / (2.0 * p.decay) >= min_quality)) return std::nullopt;  // Q = pi f / sigma
    return f;
}

}  // namespace

std::size_t resolve_doublets(std::vector<EstimatedPartial>& partials, const DecaySpectrum& spectrum, double rate_hz,
                             const FrequencyLaw& law, const EstimationOptions& options) {
    std::vector<Mode> modes;
    for (const EstimatedPartial& p : partials) {
        if (modes.empty() || modes.back().mode != p.mode) modes.push_back({p.mode, p.band, {}, 0, 0, false, false, 0.0});
        modes.back().poles.push_back(damped(p, rate_hz));
    }
    const double bins_per_hz = static_cast<double>(spectrum.length()) / rate_hz;
    for (Mode& m : modes) {
        sort_stronger_first(m.poles);
        const double f = m.poles.front().angle * rate_hz / (2.0 * pi);
        const double below = law.frequency_hz(m.mode) - (m.mode > 1 ? law.frequency_hz(m.mode - 1) : 0.0);
        const double above = law.frequency_hz(m.mode + 1) - law.frequency_hz(m.mode);
        m.first = static_cast<std::size_t>(std::max(1.0, std::floor((f - 0.5 * below) * bins_per_hz)));
        m.last = std::min(spectrum.last_bin(), static_cast<std::size_t>(std::ceil((f + 0.5 * above) * bins_per_hz)));
    }
    // The mode's bins less every other fitted partial (a pole that no fit confirmed, such as
    // a strongly damped one whose amplitude at the decay's start is huge, is not subtracted).
    const auto bins_of = [&](std::size_t i) {
        std::vector<DampedPartial> others;
        for (std::size_t j = 0; j < modes.size(); ++j)
            if (j != i && modes[j].fitted) others.insert(others.end(), modes[j].poles.begin(), modes[j].poles.end());
        return spectrum.bins_without(modes[i].first, modes[i].last, others);
    };
    const double q = options.min_quality_factor;

    // 1. Every mode refined as ESPRIT found it, so that the leakage subtracted next is right:
    //    twice, the second time beside fitted neighbours.
    for (int pass = 0; pass < 2; ++pass)
        for (std::size_t i = 0; i < modes.size(); ++i)
            if (auto f = fitted(spectrum, modes[i], bins_of(i), modes[i].poles, q)) {
                modes[i].poles = f->partials;
                modes[i].fitted = true;
            }

    // 2. One partial or two, resolved or merged.
    for (std::size_t i = 0; i < modes.size(); ++i) {
        Mode& m = modes[i];
        if (!m.fitted) continue;
        const std::vector<std::complex<double>> bins = bins_of(i);
        const auto one = fitted(spectrum, m, bins, {m.poles.front()}, q);
        if (!one) continue;
        std::optional<SpectrumFit> two;
        const auto consider = [&](std::vector<DampedPartial> start) {
            auto f = fitted(spectrum, m, bins, std::move(start), q);
            if (f && (!two || f->residual < two->residual)) two = f;
        };
        if (m.poles.size() == 2) consider(m.poles);
        // Of the splits of the single partial, the one that fits best with its poles held.
        const DampedPartial single = one->partials.front();
        std::vector<DampedPartial> split_start;
        double best = std::numeric_limits<double>::infinity();
        for (double split : kSplits) {
            const double half = pi * split / static_cast<double>(spectrum.length());  // half the split, in rad/sample
            DampedPartial lower = single, upper = single;
            lower.angle -= half;
            upper.angle += half;
            const std::vector<DampedPartial> start{lower, upper};
            const double r = spectrum.residual_with(m.first, bins, start);
            if (r < best) best = r, split_start = start;
        }
        if (!split_start.empty()) consider(split_start);
        const double statistic = two ? 2.0 * (one->residual - two->residual) / two->noise_per_bin : 0.0;
        m.merged = false;
        if (statistic < options.doublet_detection) {
            m.poles = one->partials;
        } else {
            const double separation = std::abs(two->partials[1].angle - two->partials[0].angle);
            if (separation >= options.resolution_sd * two->angle_difference_sd) {
                m.poles = two->partials;
            } else {
                m.poles = one->partials;
                m.merged = true;
            }
        }
        sort_stronger_first(m.poles);
    }

    // 3. The settled partials refitted once more beside their settled neighbours.
    for (std::size_t i = 0; i < modes.size(); ++i) {
        Mode& m = modes[i];
        if (!m.fitted) continue;
        if (auto f = fitted(spectrum, m, bins_of(i), m.poles, q)) {
            m.poles = f->partials;
            m.noise_per_bin = f->noise_per_bin;
            sort_stronger_first(m.poles);
        } else {
            m.fitted = false;
        }
    }

    partials.clear();
    const double n = static_cast<double>(spectrum.length());
    std::size_t dropped = 0;
    for (const Mode& m : modes) {
        if (!m.fitted) {  // no fit confirms the pole: not a partial
            dropped += m.poles.size();
            continue;
        }
        for (std::size_t k = 0; k < m.poles.size(); ++k) {
            const DampedPartial& d = m.poles[k];
            EstimatedPartial p;
            p.mode = m.mode;
            p.band = m.band;
            p.polarisation = k + 1;
            p.sigma_per_s = d.decay * rate_hz;
            p.frequency_hz = std::hypot(d.angle * rate_hz / (2.0 * pi), p.sigma_per_s / (2.0 * pi));
            p.amplitude = 2.0 * std::abs(d.amplitude);
            p.phase_rad = std::arg(d.amplitude);
            p.sigma_sd_per_s = d.decay_sd * rate_hz;
            p.frequency_sd_hz = d.angle_sd * rate_hz / (2.0 * pi);
            p.merged = m.merged;
            // Energy over the record against the noise per sample (E|noise|^2 per bin / N).
            const double energy = 2.0 * std::norm(d.amplitude) * -std::expm1(-2.0 * d.decay * n) / -std::expm1(-2.0 * d.decay);
            p.snr_db = 10.0 * std::log10(energy * n / std::max(m.noise_per_bin, 1e-300));
            p.reliable = !m.merged && p.sigma_sd_per_s <= options.reliable_sigma_sd * p.sigma_per_s;
            partials.push_back(p);
        }
    }
    return dropped;
}

}  // namespace fretbuzz
