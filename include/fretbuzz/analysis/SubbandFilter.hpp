#pragma once
// One frequency band of a real signal as a complex baseband signal at a low rate: the
// band of the signal's spectrum (FFTW, computed once for every band) is cut out with
// raised-cosine edges, shifted to 0 Hz and transformed back on a short grid. That is a
// band-pass filter, a mixer and a decimator in one exact step; each partial in the band
// stays one damped complex exponential, with its amplitude and phase.
// Optionally the band is whitened first: divided by the square root of a running median
// of the periodogram, which follows the noise floor between the partials, so that the
// subspace method sees white noise (the gain is smooth in frequency, so it leaves every
// pole where it is and only scales amplitudes; gain_at() undoes that).
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace fretbuzz {

struct FrequencyBand {
    double low_hz = 0.0;    // pass band, gain 1 (before whitening)
    double high_hz = 0.0;
    double taper_hz = 0.0;  // raised-cosine edge width outside the pass band
};

struct BasebandSignal {
    std::vector<std::complex<double>> samples;
    double rate_hz = 0.0;    // sample rate of `samples`
    double center_hz = 0.0;  // the frequency that maps to 0 Hz
    // Whitening gain applied at each frequency (1 when not whitened).
    double gain_at(double frequency_hz) const;

    std::vector<double> gain_frequency_hz;
    std::vector<double> gain;
};

class SubbandFilter {
public:
    SubbandFilter(std::span<const double> signal, double rate_hz);

    // whitening_window_hz > 0 whitens with a running median that wide (a few partial spacings).
    BasebandSignal extract(const FrequencyBand& band, double whitening_window_hz) const;
    double rate_hz() const { return rate_; }
    std::size_t size() const { return size_; }
    // The signal's spectrum, bins 0..N/2 (unnormalised FFT).
    const std::vector<std::complex<double>>& spectrum() const { return spectrum_; }

private:
    double rate_;
    std::size_t size_;
    std::vector<std::complex<double>> spectrum_;  // bins 0..N/2
};

}  // namespace fretbuzz
