#include "fretbuzz/analysis/ModalEstimation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <sstream>
#include <string>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/DecaySpectrum.hpp"
#include "fretbuzz/analysis/DoubletResolution.hpp"
#include "fretbuzz/analysis/Esprit.hpp"
#include "fretbuzz/analysis/ModelFit.hpp"
#include "fretbuzz/model/ModalDamping.hpp"
#include "fretbuzz/analysis/SubbandFilter.hpp"
#include "fretbuzz/SubnormalFlush.hpp"

namespace fretbuzz {

namespace {

using std::numbers::pi;

// ESTER keeps the largest order whose J is at least this fraction of the best one: low
// enough that a close doublet's weaker partial gets its pole (an order one too low merges
// the pair into one partial with a wrong damping), while a pole too many is caught by the
// tests below (it explains no energy of its own).
constexpr double kOrderFraction = 0.01;

// Runs of 3 or more equal samples at the peak: a clipped recording.
std::size_t clipped_runs(std::span<const double> x, double peak) {
    std::size_t runs = 0, length = 0;
    for (double v : x) {
        length = std::abs(v) == peak ? length + 1 : 0;
        if (length == 3) ++runs;
    }
    return runs;
}

void check_signal(std::span<const double> x, double rate_hz, const EstimationOptions& o, double& peak) {
    if (!(std::isfinite(rate_hz) && rate_hz >= 1000.0))
        throw InputError(out_of_range_message("recording sample rate (Hz)", rate_hz, "must be at least 1000"));
    peak = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (!std::isfinite(x[i]))
            throw InputError("recording: sample " + std::to_string(i) + " is not a finite number");
        peak = std::max(peak, std::abs(x[i]));
    }
    const double silence = o.full_scale ? *o.full_scale * 1e-5 : 0.0;  // -100 dB full scale
    if (!(peak > silence))
        throw InputError("recording: silent (peak " + number_text(peak) + "; a decay above " + number_text(silence) +
                         " is needed)");
    if (clipped_runs(x, peak) >= 2 && (!o.full_scale || peak >= 0.99 * *o.full_scale))
        throw InputError("recording: clipped (runs of equal samples at the peak " + number_text(peak) +
                         "); record with headroom: every sample must stay below full scale");
}

// A free decay loses level: a steady or growing sound (a sustained tone, a drone, a
// recording of noise) has no dampings to measure, and ESPRIT would still return poles.
void check_free_decay(std::span<const double> decay, const ModalEstimate& e) {
    const std::size_t quarter = decay.size() / 4;
    double first = 0.0, last = 0.0;
    for (std::size_t i = 0; i < quarter; ++i) {
        first += decay[i] * decay[i];
        last += decay[decay.size() - quarter + i] * decay[decay.size() - quarter + i];
    }
    const double loss_db = 10.0 * std::log10(std::max(first, 1e-300) / std::max(last, 1e-300));
    if (!(loss_db >= ModalEstimation::kMinDecayLossDb))
        throw InputError("recording: not a free decay: from the first to the last quarter of the " +
                         number_text(e.duration_s) + " s after the attack peak at " + number_text(e.start_s) +
                         " s its level changes by " + number_text(-loss_db) +
                         " dB (a plucked string's decay loses at least " + number_text(ModalEstimation::kMinDecayLossDb) +
                         " dB); a steady or growing sound has no dampings to measure: record a note left to ring "
                         "freely");
}

// f0 by harmonic summation on the spectrum: the candidate whose first ten multiples sit
// highest above the noise floor (levels in dB, clipped at the floor, so one huge partial
// cannot win alone and half the true f0 scores lower, its odd multiples being noise).
double find_f0(const SubbandFilter& filter, double low_hz, double high_hz) {
    const auto& spectrum = filter.spectrum();
    const double df = filter.rate_hz() / static_cast<double>(filter.size());
    std::vector<double> level(spectrum.size());
    for (std::size_t k = 0; k < spectrum.size(); ++k) level[k] = 10.0 * std::log10(std::norm(spectrum[k]) + 1e-300);
    std::vector<double> sorted(level.begin() + 1, level.end());
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    const double floor = sorted[sorted.size() / 2];
    const auto peak_near = [&](double f) {
        const double half = std::max(2.0 * df, 0.01 * f);
        const auto a = static_cast<std::size_t>(std::max(1.0, (f - half) / df));
        const auto b = std::min(spectrum.size() - 1, static_cast<std::size_t>((f + half) / df));
        double best = floor;
        for (std::size_t k = a; k <= b; ++k) best = std::max(best, level[k]);
        return best - floor;
    };
    double best_f0 = 0.0, best_score = -1.0;
    for (double f0 = std::max(low_hz, 4.0 * df); f0 <= high_hz; f0 *= 1.002) {
        double score = 0.0;
        for (int k = 1; k <= 10 && k * f0 < 0.5 * filter.rate_hz(); ++k) score += peak_near(k * f0);
        if (score > best_score) {
            best_score = score;
            best_f0 = f0;
        }
    }
    if (best_score <= 0.0)
        throw InputError("recording: no partials above the noise floor between " + number_text(low_hz) + " and " +
                         number_text(high_hz) + " Hz (give --f0 if the note is known)");
    return best_f0;
}

struct Candidate {
    double frequency_hz, sigma, amplitude, phase, snr_db, own_snr_db, energy;
};

}  // namespace

ModalEstimation::ModalEstimation(EstimationOptions options) : options_(std::move(options)) {}

ModalEstimate ModalEstimation::estimate(std::span<const double> signal, double rate_hz) const {
    const SubnormalFlush flushed;  // the filters' and the fits' decaying tails, on this thread
    const EstimationOptions& o = options_;
    double peak = 0.0;
    check_signal(signal, rate_hz, o, peak);

    ModalEstimate result;
    result.rate_hz = rate_hz;
    result.band_low_hz = o.band_low_hz;
    result.band_high_hz = o.band_high_hz.value_or(std::min(0.45 * rate_hz, 20000.0));
    if (!(o.band_low_hz >= 0.0 && result.band_high_hz > o.band_low_hz && result.band_high_hz <= 0.5 * rate_hz))
        throw InputError("--band " + number_text(o.band_low_hz) + " " + number_text(result.band_high_hz) +
                         ": must satisfy 0 <= low < high <= fs/2 = " + number_text(0.5 * rate_hz) + " Hz");
    if (o.f0_hz && !(*o.f0_hz >= result.band_low_hz && *o.f0_hz <= result.band_high_hz))
        throw InputError(out_of_range_message("--f0 (Hz)", *o.f0_hz,
                                              "must lie in the analysed band [" + number_text(result.band_low_hz) + ", " +
                                                  number_text(result.band_high_hz) + "] Hz"));

    // The free decay: from just after the attack peak to the end.
    const auto peak_at = static_cast<std::size_t>(
        std::max_element(signal.begin(), signal.end(), [](double a, double b) { return std::abs(a) < std::abs(b); }) -
        signal.begin());
    const std::size_t start = std::min(signal.size(), peak_at + static_cast<std::size_t>(0.005 * rate_hz));
    result.start_s = static_cast<double>(start) / rate_hz;
    result.duration_s = static_cast<double>(signal.size() - start) / rate_hz;
    if (result.duration_s < kMinDecaySeconds)
        throw InputError("recording: " + number_text(result.duration_s) + " s of decay after the attack peak at " +
                         number_text(result.start_s) + " s; at least " + number_text(kMinDecaySeconds) + " s are needed");

    check_free_decay(signal.subspan(start), result);

    const SubbandFilter filter(signal.subspan(start), rate_hz);
    FrequencyLaw law;
    law.f0_hz = o.f0_hz ? *o.f0_hz
                        : find_f0(filter, std::max(o.band_low_hz, 20.0), std::min(2000.0, 0.5 * result.band_high_hz));

    std::map<std::size_t, std::vector<EstimatedPartial>> found;
    std::size_t empty_bands = 0;
    for (std::size_t j1 = 1; j1 <= o.max_partials; j1 += o.partials_per_band) {
        if (o.checkpoint) o.checkpoint();
        const std::size_t j2 = std::min(o.max_partials, j1 + o.partials_per_band - 1);
        const double below = j1 > 1 ? law.frequency_hz(j1) - law.frequency_hz(j1 - 1) : law.frequency_hz(1);
        const double above = law.frequency_hz(j2 + 1) - law.frequency_hz(j2);
        const double keep_low = law.frequency_hz(j1) - 0.5 * below;
        const double keep_high = law.frequency_hz(j2) + 0.5 * above;
        if (keep_low >= result.band_high_hz) break;
        if (keep_high <= result.band_low_hz) continue;
        const FrequencyBand band{keep_low - below, keep_high + above, 0.5 * std::min(below, above)};
        const BasebandSignal baseband = filter.extract(band, o.whiten ? 3.0 * above : 0.0);
        // Skip the filter's ringing at both ends of the decay.
        const auto guard = static_cast<std::size_t>(std::ceil(std::max(0.02, 4.0 / band.taper_hz) * baseband.rate_hz));
        if (baseband.samples.size() < 2 * guard + 48) break;
        const std::span<const std::complex<double>> y(baseband.samples.data() + guard,
                                                      baseband.samples.size() - 2 * guard);
        const std::size_t max_order = 2 * (j2 - j1 + 3) + 10;  // doublets of the band's partials and its neighbours
        const Esprit esprit(y, y.size() / 3, max_order);
        const std::size_t chosen = esprit.choose_order(max_order, kOrderFraction);
        const ExponentialFit fit = esprit.fit(chosen);
        const double noise = std::max(fit.residual_variance, 1e-300);
        const double guard_s = static_cast<double>(guard) / baseband.rate_hz;

        std::vector<Candidate> candidates;
        for (const ExponentialComponent& c : fit.components) {
            const double fd = baseband.center_hz + std::arg(c.pole) * baseband.rate_hz / (2.0 * pi);
            if (fd < keep_low || fd >= keep_high || fd < result.band_low_hz || fd > result.band_high_hz) continue;
            ++result.poles;
            const double sigma = -std::log(std::abs(c.pole)) * baseband.rate_hz;
            const double snr_db = 10.0 * std::log10(c.energy / noise);
            if (!(sigma > 0.0 && quality_factor(fd, sigma) >= o.min_quality_factor && snr_db >= o.min_snr_db)) {
                ++result.rejected_poles;
                continue;
            }
            // Back to the start of the decay: undo the guard's delay, the mixer and the whitening.
            const double amplitude = std::abs(c.amplitude) * baseband.gain_at(fd) * std::exp(sigma * guard_s);
            const double phase = std::remainder(
                std::arg(c.amplitude) + 2.0 * pi * (baseband.center_hz - fd) * guard_s, 2.0 * pi);
            candidates.push_back({std::hypot(fd, sigma / (2.0 * pi)), sigma, amplitude, phase, snr_db,
                                  10.0 * std::log10(std::max(c.own_energy, 1e-300) / noise), c.energy});
        }
        // Mode numbers from the law. A mode keeps at most two poles, its two polarisations,
        // the stronger first; the weaker one only if the energy it alone explains stands
        // above the noise (a pole that merely shares a partial's energy is no second partial).
        std::map<std::size_t, std::vector<Candidate>> assigned;
        for (const Candidate& c : candidates) {
            std::size_t best = 0;
            double distance = 0.0;
            for (std::size_t j = j1 > 1 ? j1 - 1 : 1; j <= j2 + 1; ++j) {
                const double d = std::abs(c.frequency_hz - law.frequency_hz(j));
                if (best == 0 || d < distance) best = j, distance = d;
            }
            const double spacing = law.frequency_hz(best + 1) - law.frequency_hz(best);
            if (distance > 0.25 * spacing || found.count(best)) {
                ++result.rejected_poles;
                continue;
            }
            assigned[best].push_back(c);
        }
        for (auto& [j, poles] : assigned) {
            // Stronger: the larger amplitude at the start of the analysed decay.
            std::sort(poles.begin(), poles.end(),
                      [](const Candidate& a, const Candidate& b) { return a.amplitude > b.amplitude; });
            const std::size_t kept = poles.size() > 1 && poles[1].own_snr_db >= o.min_snr_db ? 2 : 1;
            result.rejected_poles += poles.size() - kept;
            auto& partials = found[j];
            for (std::size_t k = 0; k < kept; ++k) {
                const Candidate& c = poles[k];
                const double snr = kept == 2 ? c.own_snr_db : c.snr_db;
                partials.push_back({j, c.frequency_hz, c.sigma, c.amplitude, c.phase, snr, result.bands, false, k + 1});
            }
        }
        ++result.bands;
        empty_bands = assigned.empty() ? empty_bands + 1 : 0;
        if (empty_bands >= 3) break;  // into the noise: nothing more to find above

        std::vector<std::size_t> band_modes;
        std::vector<double> band_frequencies;
        for (const auto& [j, p] : found) {
            band_modes.push_back(j);
            band_frequencies.push_back(p.front().frequency_hz);
        }
        if (!band_modes.empty()) law = fit_frequency_law(band_modes, band_frequencies);
    }
    if (found.empty())
        throw InputError("recording: no partial of f0 = " + number_text(law.f0_hz) + " Hz found in the band [" +
                         number_text(result.band_low_hz) + ", " + number_text(result.band_high_hz) +
                         "] Hz (check --f0 and --band)");
    for (auto& [j, p] : found) result.partials.insert(result.partials.end(), p.begin(), p.end());
    if (o.checkpoint) o.checkpoint();
    result.rejected_poles += resolve_doublets(result.partials, DecaySpectrum(filter.spectrum(), filter.size()), rate_hz, law, o);
    if (result.partials.empty())
        throw InputError("recording: no partial of f0 = " + number_text(law.f0_hz) + " Hz confirmed by the fit of the "
                         "decay's spectrum (check --f0 and --band)");
    std::vector<std::size_t> modes;
    std::vector<double> frequencies;
    for (const EstimatedPartial& p : result.partials)
        if (p.polarisation == 1) {
            modes.push_back(p.mode);
            frequencies.push_back(p.frequency_hz);
        }
    law = fit_frequency_law(modes, frequencies);
    result.f0_hz = law.f0_hz;
    result.inharmonicity = law.inharmonicity;
    return result;
}

}  // namespace fretbuzz
