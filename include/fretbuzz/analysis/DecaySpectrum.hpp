#pragma once
// The spectrum of a free decay, fitted a few partials at a time. A damped partial
//   x[n] = c z^n + conj(c z^n),  z = exp(-alpha + i theta),  n = 0 .. N-1,
// has the N-point DFT
//   X[k] = c (1 - z^N) / (1 - z u_k) + conj(c) (1 - conj(z)^N) / (1 - conj(z) u_k),  u_k = exp(-2 pi i k / N),
// in closed form, the record's abrupt start included: fitting it to the bins around a mode
// uses every sample of the decay from its first (a band filter's ringing costs the start,
// where a fast partial holds most of its energy), and the other partials' leakage into
// those bins is subtracted exactly from their estimates. The DFT of white noise is white,
// so the least-squares fit (Levenberg-Marquardt, Eigen) is the maximum-likelihood one, and
// the Fisher information at the fit gives each parameter's Cramer-Rao standard deviation.
#include <complex>
#include <cstddef>
#include <span>
#include <vector>

namespace fretbuzz {

struct DampedPartial {
    double decay = 0.0;              // alpha, per sample (sigma / fs)
    double angle = 0.0;              // theta, rad per sample (2 pi f_d / fs)
    std::complex<double> amplitude;  // c: half the cosine's amplitude at n = 0, with its phase
    // Cramer-Rao standard deviations at the fit (0 until fitted).
    double decay_sd = 0.0, angle_sd = 0.0;
};

struct SpectrumFit {
    std::vector<DampedPartial> partials;
    double angle_difference_sd = 0.0;  // of partials[1].angle - partials[0].angle (two partials)
    double residual = 0.0;             // sum of |X - model|^2 over the fitted bins
    double noise_per_bin = 0.0;        // E|noise|^2 per bin, from that residual (at least round-off's)
    std::size_t bins = 0;
    bool valid = false;  // converged, every partial decaying and inside the bins fitted
};

class DecaySpectrum {
public:
    // The DFT of the decay (bins 0..N/2, unnormalised, as FFTW's r2c gives it) and N.
    DecaySpectrum(std::span<const std::complex<double>> spectrum, std::size_t length);

    std::size_t length() const { return length_; }
    std::size_t last_bin() const { return spectrum_.size() - 1; }
    // X[k] of one partial.
    std::complex<double> of(const DampedPartial& p, std::size_t k) const;
    // Bins first..last of the spectrum less the partials `others`.
    std::vector<std::complex<double>> bins_without(std::size_t first, std::size_t last,
                                                   std::span<const DampedPartial> others) const;
    // Least squares of `start`'s partials (their amplitudes refitted first, for the poles
    // given) plus a straight complex background (the leakage of whatever is not modelled)
    // to `bins`, the bins from `first` on (as bins_without gives them).
    SpectrumFit fit(std::size_t first, std::span<const std::complex<double>> bins,
                    std::span<const DampedPartial> start) const;
    // The residual of that fit with the poles held where they are: a cheap comparison of starts.
    double residual_with(std::size_t first, std::span<const std::complex<double>> bins,
                         std::span<const DampedPartial> poles) const;

private:
    SpectrumFit solve(std::size_t first, std::span<const std::complex<double>> bins,
                      std::span<const DampedPartial> start, bool move_poles) const;
    std::span<const std::complex<double>> spectrum_;
    std::size_t length_;
    double floor_per_bin_ = 0.0;  // the least noise per bin believed: the spectrum's round-off
};

}  // namespace fretbuzz
