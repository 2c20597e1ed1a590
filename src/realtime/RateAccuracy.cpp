#include "fretbuzz/realtime/RateAccuracy.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fretbuzz/analysis/BuzzMetrics.hpp"

namespace fretbuzz {

namespace {
constexpr double kLowestBandHz = 50.0;
constexpr double kBandsPerOctave = 6.0;
constexpr double kTopFraction = 0.45;  // of the host rate: the decimator's pass band
}  // namespace

BandSpectrum band_spectrum(std::span<const double> signal, double rate_hz) {
    const std::size_t n = signal.size();
    const std::vector<double> power = n >= 2 ? hann_power_spectrum(signal) : std::vector<double>{};
    BandSpectrum s;
    const double bin_hz = rate_hz / static_cast<double>(std::max<std::size_t>(n, 1));
    const double top_hz = kTopFraction * rate_hz;
    const std::size_t bands = static_cast<std::size_t>(std::floor(kBandsPerOctave * std::log2(top_hz / kLowestBandHz)));
    std::vector<double> band(bands, 0.0);
    double total = 0.0, moment = 0.0;
    for (std::size_t k = 1; k < power.size(); ++k) {
        const double f = static_cast<double>(k) * bin_hz;
        if (f < kLowestBandHz || f >= top_hz) continue;
        const auto b = static_cast<std::size_t>(kBandsPerOctave * std::log2(f / kLowestBandHz));
        if (b < bands) band[b] += power[k];
        total += power[k];
        moment += f * power[k];
    }
    s.level_db.resize(bands);
    for (std::size_t b = 0; b < bands; ++b) s.level_db[b] = 10.0 * std::log10(std::max(band[b], 1e-300));
    s.centroid_hz = total > 0.0 ? moment / total : 0.0;
    return s;
}

double log_spectral_distance_db(const BandSpectrum& a, const BandSpectrum& reference, double floor_db) {
    const std::size_t bands = std::min(a.level_db.size(), reference.level_db.size());
    if (bands == 0) return 0.0;
    const double floor = *std::max_element(reference.level_db.begin(), reference.level_db.end()) - floor_db;
    double sum = 0.0;
    for (std::size_t b = 0; b < bands; ++b) {
        const double d = std::max(a.level_db[b], floor) - std::max(reference.level_db[b], floor);
        sum += d * d;
    }
    return std::sqrt(sum / static_cast<double>(bands));
}

std::vector<double> render_struck(Engine& engine, const Strike& strike, double seconds) {
    engine.strike(strike);
    std::vector<float> block(static_cast<std::size_t>(std::lround(seconds * engine.host_rate_hz())));
    engine.process(block);
    return {block.begin(), block.end()};
}

RateError rate_error(const Case& c, const Strike& strike, int m, int reference_m, double seconds, double host_rate_hz) {
    EngineOptions o;
    o.host_rate_hz = host_rate_hz;
    o.oversampling = reference_m;
    Engine fine(c, o);
    const BandSpectrum reference = band_spectrum(render_struck(fine, strike, seconds), host_rate_hz);
    o.oversampling = m;
    Engine coarse(c, o);
    const BandSpectrum at_m = band_spectrum(render_struck(coarse, strike, seconds), host_rate_hz);
    RateError e;
    e.oversampling = m;
    e.modes = coarse.mode_count();
    e.distance_db = log_spectral_distance_db(at_m, reference);
    e.centroid_error = reference.centroid_hz > 0.0 ? std::abs(at_m.centroid_hz / reference.centroid_hz - 1.0) : 0.0;
    return e;
}

}  // namespace fretbuzz
