#include "fretbuzz/analysis/Listener.hpp"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <numbers>
#include <stdexcept>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/numerics/SineTransform.hpp"

namespace fretbuzz {

namespace {

constexpr double kHighestHz = 20000.0;
constexpr double kLowestHz = 20.0;

struct FftwFree {
    void operator()(void* p) const { fftw_free(p); }
};

}  // namespace

double bark(double f) { return 13.0 * std::atan(0.00076 * f) + 3.5 * std::atan((f / 7500.0) * (f / 7500.0)); }

double threshold_in_quiet_db(double f) {
    const double k = f / 1000.0;
    return 3.64 * std::pow(k, -0.8) - 6.5 * std::exp(-0.6 * (k - 3.3) * (k - 3.3)) + 1e-3 * k * k * k * k;
}

double masking_spread_db(double dz) {
    const double d = dz + 0.474;
    return 15.81 + 7.5 * d - 17.5 * std::sqrt(1.0 + d * d);
}

// One FFTW plan for the frame length, executed on per-call buffers (new-array execution is
// thread-safe; the buffers come from fftw_malloc, aligned as the plan's were).
struct Listener::Plan {
    std::size_t n;
    fftw_plan plan = nullptr;
    explicit Plan(std::size_t length) : n(length) {
        std::unique_ptr<double, FftwFree> in(fftw_alloc_real(n));
        std::unique_ptr<fftw_complex, FftwFree> out(fftw_alloc_complex(n / 2 + 1));
        std::lock_guard lock(fftw_planner_mutex());
        plan = fftw_plan_dft_r2c_1d(static_cast<int>(n), in.get(), out.get(), FFTW_ESTIMATE);
        if (!plan) throw std::runtime_error("FFTW could not plan a listener's frame");
    }
    ~Plan() {
        std::lock_guard lock(fftw_planner_mutex());
        fftw_destroy_plan(plan);
    }
};

Listener::Listener(double rate_hz, std::size_t samples, double partial_spacing_hz, ListeningSettings settings)
    : rate_(rate_hz), samples_(samples), settings_(settings) {
    if (!(rate_hz >= 8000.0 && rate_hz <= 1e6))
        throw InputError(out_of_range_message("listener rate (Hz)", rate_hz, "must be in [8000, 1e6]"));
    if (!(partial_spacing_hz > 0.0 && std::isfinite(partial_spacing_hz)))
        throw InputError(out_of_range_message("listener partial spacing (Hz)", partial_spacing_hz, "must be > 0"));
    if (!(settings.integration_s > 0.0) || !(settings.shortest_frame_s > 0.0) || !(settings.bins_between_partials > 0.0))
        throw InputError("listener settings: integration, frame and bins must be > 0");
    const double frame_s = std::max(settings.shortest_frame_s, settings.bins_between_partials / partial_spacing_hz);
    frame_ = 2 * static_cast<std::size_t>(std::ceil(0.5 * frame_s * rate_hz));
    if (frame_ > (std::size_t{1} << 22)) throw InputError("listener: the note's frame would exceed 4 M samples");
    hop_ = frame_ / 2;
    // Whole frames from t = 0 (the note's onset is the first frame's start): the signal is cut
    // where the run ends, and a frame over that cut would hear it as a click.
    frames_ = samples_ <= frame_ ? 1 : 1 + (samples_ - frame_) / hop_;
    window_.resize(frame_);
    for (std::size_t i = 0; i < frame_; ++i)
        window_[i] = 0.5 * (1.0 - std::cos(2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(frame_)));
    // Bands one Bark apart, from 20 Hz to 20 kHz or the Nyquist rate, overlapping as the ear's
    // filters do: a bin at z Bark feeds the two bands whose centres (b + 1/2) lie either side
    // of it, in proportion to its nearness (triangles that sum to one). A partial moving or a
    // band edge crossing a partial then changes the bands' energies smoothly, and the cross
    // terms of neighbouring partials, which cancel over a whole main lobe, nearly cancel.
    const std::optional<ListeningRig> rig =
        settings.rig ? std::optional<ListeningRig>(std::in_place, *settings.rig) : std::nullopt;
    const double top = std::min(kHighestHz, 0.5 * rate_hz);
    const std::size_t bins = frame_ / 2 + 1;
    bin_band_.assign(bins, -1);
    bin_share_.assign(bins, 0.0);
    bin_weight_.assign(bins, 0.0);
    const double first_bark = bark(kLowestHz), last_bark = bark(top);
    const std::size_t count = static_cast<std::size_t>(std::floor(last_bark - first_bark)) + 1;
    quiet_db_.assign(count, std::numeric_limits<double>::infinity());
    for (std::size_t k = 1; k < bins; ++k) {
        const double f = static_cast<double>(k) * rate_hz / static_cast<double>(frame_);
        if (f < kLowestHz || f > top) continue;
        const double z = std::clamp(bark(f) - first_bark - 0.5, 0.0, static_cast<double>(count - 1));
        const auto b = std::min(static_cast<std::size_t>(z), count - 1);
        bin_band_[k] = static_cast<int>(b);
        bin_share_[k] = b + 1 < count ? z - static_cast<double>(b) : 0.0;  // the part that goes to band b + 1
        const double one_sided = 2 * k == frame_ ? 1.0 : 2.0;
        const double w = 2.0 * std::numbers::pi * f;
        bin_weight_[k] = one_sided * (settings.velocity ? w * w : 1.0) * (rig ? rig->power_gain(f) : 1.0);
        const std::size_t nearest = z - static_cast<double>(b) < 0.5 ? b : std::min(b + 1, count - 1);
        quiet_db_[nearest] = std::min(quiet_db_[nearest], threshold_in_quiet_db(f));
    }
    for (std::size_t b = 0; b < count; ++b) {
        band_bark_.push_back(first_bark + static_cast<double>(b) + 0.5);
        // The centre's frequency, by bisection on z(f) (increasing).
        double low = kLowestHz, high = top;
        for (int i = 0; i < 60; ++i) (bark(0.5 * (low + high)) < band_bark_.back() ? low : high) = 0.5 * (low + high);
        band_hz_.push_back(0.5 * (low + high));
        if (!std::isfinite(quiet_db_[b])) quiet_db_[b] = threshold_in_quiet_db(band_hz_.back());
    }
    spreading_.resize(count * count);
    for (std::size_t to = 0; to < count; ++to)
        for (std::size_t from = 0; from < count; ++from)
            spreading_[to * count + from] = std::pow(10.0, masking_spread_db(band_bark_[to] - band_bark_[from]) / 10.0);
    plan_ = std::make_unique<Plan>(frame_);
}

Listener::~Listener() = default;

std::vector<double> Listener::band_energies(std::span<const double> signal) const {
    const std::size_t count = bands();
    std::vector<double> energy(frames_ * count, 0.0);
    std::unique_ptr<double, FftwFree> in(fftw_alloc_real(frame_));
    std::unique_ptr<fftw_complex, FftwFree> out(fftw_alloc_complex(frame_ / 2 + 1));
    for (std::size_t f = 0; f < frames_; ++f) {
        const std::size_t start = f * hop_;
        for (std::size_t i = 0; i < frame_; ++i) {
            const std::size_t at = start + i;
            in.get()[i] = at < signal.size() && at < samples_ ? window_[i] * signal[at] : 0.0;
        }
        fftw_execute_dft_r2c(plan_->plan, in.get(), out.get());
        double* row = energy.data() + f * count;
        for (std::size_t k = 1; k < bin_band_.size(); ++k) {
            if (bin_band_[k] < 0) continue;
            const double re = out.get()[k][0], im = out.get()[k][1];
            const double e = bin_weight_[k] * (re * re + im * im);
            const auto b = static_cast<std::size_t>(bin_band_[k]);
            row[b] += (1.0 - bin_share_[k]) * e;
            if (bin_share_[k] > 0.0) row[b + 1] += bin_share_[k] * e;
        }
    }
    return energy;
}

std::vector<double> Listener::masked_threshold(std::span<const double> clean) const {
    const std::size_t count = bands();
    // The playback gain: the loudest frame of the clean note at the listening level.
    double loudest = 0.0;
    for (std::size_t f = 0; f < frames_; ++f) {
        double total = 0.0;
        for (std::size_t b = 0; b < count; ++b) total += clean[f * count + b];
        loudest = std::max(loudest, total);
    }
    std::vector<double> threshold(frames_ * count, 0.0);
    if (!(loudest > 0.0)) return threshold;
    const double per_spl = loudest / std::pow(10.0, settings_.level_db_spl / 10.0);  // band energy of 0 dB SPL
    for (std::size_t f = 0; f < frames_; ++f) {
        const double* e = clean.data() + f * count;
        for (std::size_t to = 0; to < count; ++to) {
            double spread = 0.0;
            for (std::size_t from = 0; from < count; ++from) spread += spreading_[to * count + from] * e[from];
            const double tonal = spread * std::pow(10.0, -(14.5 + band_bark_[to]) / 10.0);
            const double quiet = per_spl * std::pow(10.0, quiet_db_[to] / 10.0);
            threshold[f * count + to] = std::max(tonal, quiet);
        }
    }
    return threshold;
}

Listener::Clean Listener::hear_clean(std::span<const double> clean) const {
    Clean c;
    c.bands = band_energies(clean);
    c.threshold = masked_threshold(c.bands);
    return c;
}

AddedLevel Listener::added_level(std::span<const double> played, std::span<const double> clean) const {
    return added_level(played, hear_clean(clean));
}

AddedLevel Listener::added_level(std::span<const double> played, const Clean& clean, double energy_scale) const {
    const std::size_t count = bands();
    const std::vector<double> with = band_energies(played);
    const std::size_t window =
        std::clamp<std::size_t>(static_cast<std::size_t>(std::lround(settings_.integration_s / hop_s())), 1, frames_);
    AddedLevel result;
    double best = 0.0;
    for (std::size_t start = 0; start + window <= frames_; ++start) {
        double ratio = 0.0, band_best = 0.0;
        std::size_t loudest_band = 0;
        for (std::size_t b = 0; b < count; ++b) {
            double added = 0.0, masked = 0.0;
            for (std::size_t f = start; f < start + window; ++f) {
                added += with[f * count + b] - energy_scale * clean.bands[f * count + b];
                masked += energy_scale * clean.threshold[f * count + b];
            }
            if (!(added > 0.0) || !(masked > 0.0)) continue;
            ratio += added / masked;
            if (added / masked > band_best) {
                band_best = added / masked;
                loudest_band = b;
            }
        }
        ratio /= static_cast<double>(count);  // the mean over bands (ITU-R BS.1387-1, the total NMR)
        if (ratio > best) {
            best = ratio;
            result.window_start_s = static_cast<double>(start) * hop_s();
            result.loudest_band_hz = band_hz_[loudest_band];
        }
    }
    if (best > 0.0) result.level_db = 10.0 * std::log10(best);
    return result;
}

}  // namespace fretbuzz
