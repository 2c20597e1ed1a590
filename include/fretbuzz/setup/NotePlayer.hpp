#pragma once
// One pluck of a note, and how much it buzzed. The buzz level is the one of `fretbuzz sweep`
// (docs/sweeps.md): the high-frequency energy (above the buzz band's edge) the contacts
// added to the signal at the pickup, u - u_free, relative to the note's own, u_free, in dB;
// u_free is the same pluck with nothing to touch. On the stand-in the string is linear where
// it does not touch, so u_free comes in closed form (free_motion_at), and plucks of one shape
// share it, scaled. With the finger model it is a second run with the frets past the stop
// removed (the finger is not linear).
#include <cstddef>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/run/RunObserver.hpp"
#include "fretbuzz/setup/NoteCase.hpp"

namespace fretbuzz {

// Fret numbers in outcomes: a fret of the neck, the board or body, or nothing.
inline constexpr int kNoFret = -1;
inline constexpr int kBoard = 0;

// Contacts in one stretch of time (for drawing them over time): the impulse of the
// obstacle on the string in [time_s, time_s + bin) and the fret that took most of it.
struct ContactStretch {
    double time_s = 0.0;
    double impulse_n_s = 0.0;
    double peak_force_n = 0.0;
    int fret = kNoFret;
};

struct PluckOutcome {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::string error;              // not played (the pluck behind the fret) or failed: why
    bool simulated = false;         // false: provably clear of everything (never_touches), or not played
    bool touched = false;           // the obstacle pushed on the string (past the stopping fret)
    double buzz_db = nan;           // NaN when it touched nothing
    int buzz_fret = kNoFret;        // where the largest impulse went
    double first_contact_s = nan;
    double peak_force_n = 0.0;
    std::vector<ContactStretch> contacts;  // kept only when asked (keep_details)
    std::vector<double> signal;            // u at the pickup at the output rate (keep_details)
    double signal_rate_hz = 0.0;
    std::vector<double> audio;             // the same band-limited to 48 kHz (keep_details with a WAV)
    double audio_rate_hz = 0.0;
};

// Observes a note's run: the pickup signal and the obstacle's contacts, fret by fret (a
// contact point belongs to the nearest fret within two grid steps, else to the board or
// body). Contacts of a finger model's hand (its pads, everything up to the stopping fret:
// first_buzz_point) do not count.
class NoteContacts : public RunObserver {
public:
    // fret_x: the frets the note can buzz against, on its string (m); fret_number: theirs.
    NoteContacts(std::vector<double> fret_x, std::vector<std::size_t> fret_number, double bin_s = 5e-4);
    void begin(const RunLayout& layout) override;
    void observation(double t, std::span<const double> u) override;
    void contacts(double t, std::span<const std::pair<std::size_t, double>> forces) override;

    const std::vector<double>& signal() const { return signal_; }
    double output_rate_hz() const { return rate_; }
    bool touched() const { return steps_ > 0; }
    double first_contact_s() const { return first_; }
    double peak_force_n() const { return peak_; }
    int main_fret() const;
    const std::vector<ContactStretch>& stretches() const { return stretches_; }

private:
    std::vector<double> fret_x_;
    std::vector<std::size_t> fret_number_;
    double bin_s_;
    double rate_ = 0.0, dx_ = 0.0, dt_ = 0.0;
    std::vector<int> fret_of_point_;  // kNoFret: not counted (the hand)
    std::vector<double> impulse_;     // per fret number (0: board or body)
    std::vector<double> signal_;
    std::vector<ContactStretch> stretches_;
    std::vector<double> stretch_impulse_;  // per fret number, in the current stretch
    long steps_ = 0;
    double first_ = PluckOutcome::nan, peak_ = 0.0;
};

// What playing a note takes.
struct PluckRequest {
    bool finger = false;       // the finger model (else the stand-in)
    double band_hz = 2000.0;   // the buzz band's lower edge
    bool keep_details = false;  // keep the signal and the contacts over time in the outcome
};

// Plays member `pluck` of note `fret` once per attack; plucks of one shape share one
// obstacle-free reference. wav_paths: per attack, where to write its audio (empty: none),
// faded in over 5 ms and out over the last 50 ms. Throws Interrupted when a stop is asked.
std::vector<PluckOutcome> play_plucks(const NoteMaker& maker, std::size_t fret, std::span<const Attack> attacks,
                                      const PluckVariation& pluck, const PluckRequest& request,
                                      std::span<const std::filesystem::path> wav_paths = {});

// One pluck of a note (member `member` of its ensemble) with everything kept: the pickup
// signal, its audio at 48 kHz (as the note's WAV, before normalising) and the contacts over time.
PluckOutcome record_pluck(const Instrument& instrument, std::size_t string, std::size_t fret, const Attack& attack,
                          std::size_t member = 0, bool finger = false);

}  // namespace fretbuzz
