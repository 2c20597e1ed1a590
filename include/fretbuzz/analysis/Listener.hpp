#pragma once
// Whether the contacts of a note can be heard: a model listener that compares the short-time
// spectra of the note as played (u, with its contacts) and of the same note with nothing to
// touch (u_free), at the pickup, and weighs the energy the contacts add in each critical band
// against the masking threshold that the clean note itself sets there.
//
//  - Spectra: Hann frames long enough to hold every partial of the note apart (5 bins between
//    neighbouring partials, at least 40 ms: 121 ms for E1, 51 ms for G2), hop half a frame,
//    whole frames only (the signal's end is where the run stops, not a sound);
//    band energies in the critical bands of Zwicker & Terhardt (JASA 68(5), 1980: z(f) =
//    13 atan(0.00076 f) + 3.5 atan((f / 7500)^2) Bark), one band per Bark up to 20 kHz,
//    overlapping (triangles one Bark either side of each band's centre, summing to one). A
//    magnetic pickup's voltage follows the string's velocity: each bin is weighted by
//    (2 pi f)^2 (option `velocity`).
//  - Masking threshold of each frame and band: the clean note's band energies spread across
//    bands by the spreading function of Schroeder, Atal & Hall (JASA 66(6), 1979), lowered by
//    the offset of a tonal masker, 14.5 + z dB (Johnston, IEEE JSAC 6(2), 1988: a tone masks
//    noise down to about that far below it), and never below the threshold in quiet
//    (Terhardt 1979, as in Painter & Spanias, Proc. IEEE 88(4), 2000) at a stated listening
//    level: the clean note's loudest frame at `level_db_spl`.
//  - What the contacts add: E_u - E_free in each band and frame. Band energies do not care
//    about phase, so a touch that only shifts the phases of the partials (the trajectory
//    drifts after any contact) adds nothing; a waveform difference u - u_free would grow to
//    the size of the note itself.
//  - The level: over every window of `integration_s` (the ear integrates the energy of short
//    sounds over about 200 ms: Zwicker & Fastl, Psychoacoustics, ch. 4 and 12), the added
//    energy of each band summed over the window's frames and divided by its threshold over
//    the same frames, averaged over the bands (the noise-to-mask ratio of Brandenburg, AES
//    82nd Convention, 1987, as ITU-R BS.1387-1 computes its total NMR: the mean over bands
//    of noise over mask, not their sum, which with 25 bands read 14 dB higher), integrated
//    in time; the largest window's, in dB. 0 dB: just audible. -inf when the contacts add
//    energy to no band.
// The listener is planned once for a rate, a frame length and a signal length (FFTW's plan);
// added_level() may be called from several threads at once.
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "fretbuzz/model/ListeningRig.hpp"

namespace fretbuzz {

struct ListeningSettings {
    double level_db_spl = 85.0;   // the clean note's loudest frame, as played back
    double integration_s = 0.2;   // the ear's temporal integration
    double shortest_frame_s = 0.04;
    double bins_between_partials = 5.0;
    bool velocity = true;         // a magnetic pickup (velocity); false: the displacement (an optical sensor)
    // The rate its signals come at: the bench hears the pickup band-limited and resampled to
    // it (the run's libsoxr path), never sampled from the simulation without a filter. 96 kHz,
    // not 48: in free flight a run feeds its audio only the modes below 0.6 x the audio rate,
    // and switching the others off and on at a flight's edges leaves a trace in the band; at
    // 48 kHz it is 2.5e-7 of the note's rms at the pickup (G17 of the quick bass, just
    // touching), which the listener's interference term hears at -36 dB whatever the touch;
    // at 96 kHz it is 1.1e-9.
    double rate_hz = 96000.0;
    // What the pickup is heard through (a rig: its power gain weighs every bin); none: the
    // pickup's full range, the strictest listener.
    std::optional<RigSettings> rig;
};

struct AddedLevel {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    double level_db = -std::numeric_limits<double>::infinity();  // above the masked threshold
    double window_start_s = nan;  // where the loudest window starts
    double loudest_band_hz = nan;  // the centre of the band that adds most there
};

class Listener {
public:
    // Signals sampled at rate_hz, `samples` long, of a note whose partials lie at least
    // `partial_spacing_hz` apart (its fundamental).
    Listener(double rate_hz, std::size_t samples, double partial_spacing_hz, ListeningSettings settings = {});
    ~Listener();
    Listener(const Listener&) = delete;
    Listener& operator=(const Listener&) = delete;

    double rate_hz() const { return rate_; }
    std::size_t samples() const { return samples_; }
    std::size_t frame() const { return frame_; }
    std::size_t bands() const { return band_hz_.size(); }
    const std::vector<double>& band_centres_hz() const { return band_hz_; }
    const ListeningSettings& settings() const { return settings_; }

    // A clean note as the listener hears it: its band energies and the threshold it masks.
    // Both scale with the square of the signal (a note played twice as hard: 4 times both).
    struct Clean {
        std::vector<double> bands, threshold;  // frames x bands
    };
    Clean hear_clean(std::span<const double> clean) const;

    // How far above the threshold that `clean` sets the contacts of `played` are heard: both
    // signals `samples()` long (shorter ones are padded with zeros, longer ones cut).
    AddedLevel added_level(std::span<const double> played, std::span<const double> clean) const;
    // The same against a clean note heard before, whose energies are scaled by `energy_scale`.
    AddedLevel added_level(std::span<const double> played, const Clean& clean, double energy_scale = 1.0) const;

    // Band energies per frame (frame-major: frames x bands), as added_level() weighs them.
    std::vector<double> band_energies(std::span<const double> signal) const;
    std::size_t frames() const { return frames_; }
    double hop_s() const { return static_cast<double>(hop_) / rate_; }
    // The masked threshold per frame and band of a clean note's band energies.
    std::vector<double> masked_threshold(std::span<const double> clean_bands) const;

private:
    struct Plan;
    double rate_;
    std::size_t samples_, frame_, hop_, frames_;
    ListeningSettings settings_;
    std::vector<double> window_, bin_weight_;
    std::vector<int> bin_band_;          // the lower of the two bands each bin feeds (-1: none)
    std::vector<double> bin_share_;      // its share in the upper one
    std::vector<double> band_hz_, band_bark_, quiet_db_;  // centre, Bark, threshold in quiet (dB SPL)
    std::vector<double> spreading_;      // bands x bands, linear (maskee-major)
    std::unique_ptr<Plan> plan_;
};

// Critical-band rate (Bark) of a frequency (Zwicker & Terhardt 1980).
double bark(double frequency_hz);
// Threshold in quiet of a tone (dB SPL; Terhardt 1979).
double threshold_in_quiet_db(double frequency_hz);
// Spreading of masking from a masker to a maskee dz Bark above it (dB; Schroeder et al. 1979).
double masking_spread_db(double dz);

}  // namespace fretbuzz
