#pragma once
// How much the real-time engine's sound depends on its internal rate: the same voice struck
// the same way, rendered at oversampling M and at a reference M, compared by
//   - the log-spectral distance: the RMS over 1/6-octave bands (50 Hz to 0.45 x the host
//     rate) of the difference of the band levels in dB, bands more than `floor_db` below the
//     reference's loudest band raised to that floor (so empty bands do not count), and
//   - the spectral centroid (the brightness the buzz adds) of each, from the same spectrum.
// The spectrum is that of the Hann-windowed signal. Used to choose the engine's default rate.
#include <span>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/realtime/Engine.hpp"

namespace fretbuzz {

struct BandSpectrum {
    std::vector<double> level_db;  // power per 1/6-octave band, dB (arbitrary reference)
    double centroid_hz = 0.0;      // power-weighted mean frequency over the same range
};

BandSpectrum band_spectrum(std::span<const double> signal, double rate_hz);

// RMS over bands of (a - reference) in dB, both floored at the reference's loudest band
// minus floor_db.
double log_spectral_distance_db(const BandSpectrum& a, const BandSpectrum& reference, double floor_db = 60.0);

// The engine's host-rate output for `seconds`, struck once at the start.
std::vector<double> render_struck(Engine& engine, const Strike& strike, double seconds);

struct RateError {
    int oversampling = 0;
    std::size_t modes = 0;
    double distance_db = 0.0;       // log-spectral distance to the reference rendering
    double centroid_error = 0.0;    // |centroid / reference centroid - 1|
};

// Renders the voice at oversampling m and at reference_m (same strike, same host rate) and
// compares the two.
RateError rate_error(const Case& c, const Strike& strike, int m, int reference_m, double seconds = 0.5,
                     double host_rate_hz = 48000.0);

}  // namespace fretbuzz
