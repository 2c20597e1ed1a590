#pragma once
// Frequencies, dampings and amplitudes of the partials of a freely decaying string,
// the measurement step of Issanchou et al. 2017 (section 4), done the way their
// references do it: the decay after the attack is split into bands of a few partials
// (SubbandFilter: band-pass, shift, decimate, whiten), ESPRIT with its order chosen by
// ESTER runs in each band, poles that cannot be partials are rejected (growing or
// strongly damped, outside the band's kept range, too weak against the noise, off the
// inharmonicity law) and the others get their mode number from that law, refitted after
// every band so the bands follow the stretched partial series up. Each mode is then
// settled on the whole decay's spectrum (DoubletResolution): one partial, a resolved
// doublet or a merged one, with Cramer-Rao standard deviations and a reliability flag.
#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <vector>

namespace fretbuzz {

struct EstimationOptions {
    std::optional<double> f0_hz;           // fundamental; found from the spectrum when absent
    double band_low_hz = 20.0;             // analysed range
    std::optional<double> band_high_hz;    // default min(0.45 fs, 20 kHz)
    std::size_t partials_per_band = 5;
    std::size_t max_partials = 200;        // highest mode number searched
    double min_snr_db = 20.0;              // a pole weaker than this against the noise is rejected
    double min_quality_factor = 20.0;      // Q below this: not a string partial
    // Each mode's partials, settled on the decay's spectrum (DoubletResolution.hpp, where
    // the rules and their sources are): a second partial is detected when it lowers the
    // residual by `doublet_detection` in the likelihood-ratio statistic; it is resolved when
    // the two frequencies lie `resolution_sd` Cramer-Rao standard deviations of their
    // difference apart (else the pair is reported merged); a partial is reliable when the
    // standard deviation of its damping is at most `reliable_sigma_sd` of it.
    double doublet_detection = 40.0;
    double resolution_sd = 3.0;
    double reliable_sigma_sd = 0.03;
    bool whiten = true;
    std::optional<double> full_scale;      // for files: 1; enables the clipping and silence levels
    // Called between bands (a fraction of a second apart): a caller that must be able to stop
    // the estimate (Ctrl-C in Python) throws from it, and the estimate ends with that exception.
    std::function<void()> checkpoint;
};

struct EstimatedPartial {
    std::size_t mode = 0;         // j
    double frequency_hz = 0.0;    // nu_j (undamped: sqrt(f_d^2 + (sigma/2pi)^2))
    double sigma_per_s = 0.0;     // amplitude decay rate
    double amplitude = 0.0;       // at the start of the analysed decay, signal units
    double phase_rad = 0.0;       // of the cosine at that time
    double snr_db = 0.0;          // the partial's energy over the band's noise per sample
    std::size_t band = 0;
    bool reliable = false;
    // 1: the mode's stronger partial; 2: the weaker one of a resolved doublet, the string's
    // other polarisation (the two ring at slightly different frequencies and beat).
    std::size_t polarisation = 1;
    // Cramer-Rao standard deviations of frequency and damping at the fit (docs/estimation.md).
    double frequency_sd_hz = 0.0;
    double sigma_sd_per_s = 0.0;
    // One partial standing for a doublet too close to resolve in this record: its damping is
    // that of the pair's beating envelope, not either polarisation's (never reliable).
    bool merged = false;
};

struct ModalEstimate {
    double rate_hz = 0.0;
    double f0_hz = 0.0;            // of the fitted inharmonicity law
    double inharmonicity = 0.0;    // B of that law
    double start_s = 0.0;          // where the analysed decay starts (after the attack peak)
    double duration_s = 0.0;       // its length
    double band_low_hz = 0.0, band_high_hz = 0.0;
    std::size_t bands = 0;
    std::size_t poles = 0;          // found by ESPRIT in the kept ranges
    std::size_t rejected_poles = 0; // of those, rejected
    std::vector<EstimatedPartial> partials;  // by mode number, then polarisation
};

class ModalEstimation {
public:
    explicit ModalEstimation(EstimationOptions options);

    // Throws InputError for a recording that cannot be analysed (silent, clipped, too
    // short, not decaying, non-finite, f0 outside the band), naming the problem and the
    // allowed range.
    ModalEstimate estimate(std::span<const double> signal, double rate_hz) const;

    static constexpr double kMinDecaySeconds = 0.2;
    // The level of the decay's last quarter must lie this far below its first quarter's.
    static constexpr double kMinDecayLossDb = 0.5;

private:
    EstimationOptions options_;
};

}  // namespace fretbuzz
