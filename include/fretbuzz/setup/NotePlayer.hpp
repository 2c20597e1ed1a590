#pragma once
// One pluck of a note, and how far its contacts are heard above what the clean note masks
// (analysis/Listener.hpp: the level in dB above the masked threshold of the signal at the
// pickup; 0 dB is just audible). Both are heard as the run's own band-limited audio. The clean
// note u_free is the same pluck with nothing to touch, run through the same audio path: on the
// stand-in the string is linear where it does not touch, so the plucks of one member of the
// ensemble share one such run, scaled to their size. With the finger model or a slap (the
// finger and the thumb are not linear) it is a second run of each pluck with the frets past
// the stop removed.
#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "fretbuzz/analysis/Listener.hpp"
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
    double buzz_db = nan;           // dB above the masked threshold; NaN when it touched nothing
    double size = 0.0;              // the attack's size it was played at (m or m/s)
    int buzz_fret = kNoFret;        // where the largest impulse went
    double first_contact_s = nan;
    double peak_force_n = 0.0;
    std::vector<ContactStretch> contacts;  // kept only when asked (keep_details)
    std::vector<double> signal;            // u at the pickup at the output rate (keep_details)
    double signal_rate_hz = 0.0;
    std::vector<double> audio;             // the same band-limited to 48 kHz (keep_details with a WAV)
    double audio_rate_hz = 0.0;
};

// Whether a pluck is heard to buzz: it was played, the obstacle pushed on the string, and the
// contacts' level reaches audible_db (BenchSettings::audible_db) above what the note masks.
// The one rule the verdicts, the deciding pluck and the studio's account of a pluck share.
bool heard_to_buzz(const PluckOutcome& o, double audible_db);

// Observes a note's run: the pickup signal and the obstacle's contacts, fret by fret (a
// contact point belongs to the nearest fret within two grid steps, else to the board or
// body). With an audio rate, also the pickup's displacement as the listener hears it: the
// run's own band-limited audio (libsoxr, run/Resampler.hpp), not the observation rows, which
// sample the run without an anti-alias filter (partials above half the output rate would
// fold into the band heard). Contacts under a finger's or a thumb's pad do not count, nor, on a note fretted by
// the finger model (`fretted`), everything up to the stopping fret (first_buzz_point).
class NoteContacts : public RunObserver {
public:
    // fret_x: the frets the note can buzz against, on its string (m); fret_number: theirs.
    // until_s: what comes after this time (a run going on for its sound) is not counted: the
    // contacts and the signal are those of a run of that length (0: the whole run).
    NoteContacts(std::vector<double> fret_x, std::vector<std::size_t> fret_number, bool fretted, double bin_s = 5e-4,
                 double until_s = 0.0, double audio_rate_hz = 0.0);
    void begin(const RunLayout& layout) override;
    AudioRequest audio_request() const override { return {audio_rate_hz_, AudioSignal::displacement, 0.0}; }
    void audio(long first_sample, std::span<const double> samples) override;
    void observation(double t, std::span<const double> u) override;
    void contacts(double t, std::span<const std::pair<std::size_t, double>> forces) override;

    const std::vector<double>& signal() const { return signal_; }
    double output_rate_hz() const { return rate_; }
    // The band-limited displacement at the pickup, at the audio rate (up to until_s).
    const std::vector<double>& heard() const { return heard_; }
    double audio_rate_hz() const { return audio_rate_hz_; }
    bool touched() const { return steps_ > 0; }
    double first_contact_s() const { return first_; }
    double peak_force_n() const { return peak_; }
    int main_fret() const;
    const std::vector<ContactStretch>& stretches() const { return stretches_; }

private:
    std::vector<double> fret_x_;
    std::vector<std::size_t> fret_number_;
    bool fretted_;
    double bin_s_;
    double until_s_;
    double audio_rate_hz_;
    std::size_t rows_ = 0;  // the signal's rows a run of until_s gives
    std::size_t heard_rows_ = 0, points_ = 1;
    std::vector<double> heard_;
    double rate_ = 0.0, dx_ = 0.0, dt_ = 0.0;
    std::vector<int> fret_of_point_;  // kNoFret: not counted (the hand)
    std::vector<double> impulse_;     // per fret number (0: board or body)
    std::vector<double> signal_;
    std::vector<ContactStretch> stretches_;
    std::vector<double> stretch_impulse_;  // per fret number, in the current stretch
    long steps_ = 0;
    double first_ = PluckOutcome::nan, peak_ = 0.0;
};

// How one pluck is played.
struct PluckOptions {
    bool keep_details = false;  // keep the signal and the contacts over time in the outcome
    Polarisations polarisations = Polarisations::z_only;
    // Where its sound goes (empty: none): the pickup's velocity (what a magnetic pickup sends, and
    // what the listener hears), faded in over 5 ms and out at its end.
    std::filesystem::path wav;
    // The sound's length: the run goes on this long (the string may touch again, as it would),
    // and the pluck is judged on the bench's duration alone, as every other pluck.
    double sound_s = 0.0;
};

// Plays the plucks of one note (string, fret) and judges each by ear: the listener planned
// once for the note, and each member's clean note (its obstacle-free reference) kept for the
// note's other sizes. One object per thread.
class NotePlayer {
public:
    NotePlayer(const NoteMaker& maker, std::size_t fret, bool finger, const ListeningSettings& listening);
    // Member `member` of the ensemble (`pluck` its variation) of `attack`, its size replaced by
    // `size`. Throws Interrupted when a stop is asked.
    PluckOutcome play(const Attack& attack, double size, std::size_t member, const PluckVariation& pluck,
                      const PluckOptions& options = {});
    // The factor of `attack`'s size below which member `pluck` touches nothing (0: no bound).
    double touch_free_size(const Attack& attack, const PluckVariation& pluck) const;
    // The listener, planned at the first pluck for the note's rate and length.
    const Listener* listener() const { return listener_ ? &*listener_ : nullptr; }

private:
    struct Reference {
        Gesture gesture;
        std::size_t member;
        double z_share;                 // of the run it was made from
        Listener::Clean clean;          // its band energies and masked threshold
        std::vector<double> shape;      // the initial modal displacement it was made from
    };
    const Reference* reference(const Attack& attack, std::size_t member, const Case& played, double z_share,
                               double judged_s);
    PluckOutcome judge(const Case& c, const Attack& attack, std::size_t member, const PluckVariation& pluck,
                       const PluckOptions& options, double judged_s);

    const NoteMaker& maker_;
    std::size_t fret_;
    bool finger_;
    ListeningSettings listening_;
    std::optional<Listener> listener_;
    std::vector<Reference> references_;
    Reference scratch_;                          // a pluck's own, when it rests on a fret at release
    std::vector<PluckVariation> members_at_;     // each member's variation, as played
};

// One pluck of a note (member `member` of its ensemble) with everything kept, in both
// polarisations: the pickup signal, its audio at 48 kHz (as the note's WAV, before
// normalising) and the contacts over time. wav: also its sound, as a map writes a note's,
// sound_s long (the pluck is judged on the bench's duration all the same).
PluckOutcome record_pluck(const Instrument& instrument, std::size_t string, std::size_t fret, const Attack& attack,
                          std::size_t member = 0, bool finger = false, const std::filesystem::path& wav = {},
                          double sound_s = 0.0);

// How the bench listens (BenchSettings' listening level).
ListeningSettings listening_settings(const BenchSettings& bench);

// The pickup's displacement of a run of `c` as the bench's listener hears it: the run's own
// audio, band-limited and resampled to `rate_hz` (libsoxr), round(duration x rate) + 1
// samples. What a note's clean reference is made of (its obstacle removed), the same path as
// the note played.
std::vector<double> pickup_audio(const Case& c, double rate_hz);

}  // namespace fretbuzz
