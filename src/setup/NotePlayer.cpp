#include "fretbuzz/setup/NotePlayer.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <stdexcept>

#include "fretbuzz/Error.hpp"
#include "fretbuzz/analysis/BuzzMetrics.hpp"
#include "fretbuzz/output/AudioWriter.hpp"
#include "fretbuzz/run/Simulation.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"

namespace fretbuzz {

namespace {

constexpr double kFadeIn = 0.005;   // s: a plucked string starts displaced
constexpr double kFadeOut = 0.05;   // s: a note cut at the end of the run must not click
constexpr double kSoundFadeOut = 0.3;  // s: a note played on for the ear dies away rather than stops
// The output rows of a pluck no one looks at (only the listener's audio and the contacts are
// read): a free flight jumps one row interval at a time, and each jump costs about two steps
// of every mode, so a map's plucks run with few rows.
constexpr double kUnreadRowRateHz = 12000.0;

}  // namespace

NoteContacts::NoteContacts(std::vector<double> fret_x, std::vector<std::size_t> fret_number, bool fretted,
                           double bin_s, double until_s, double audio_rate_hz)
    : fret_x_(std::move(fret_x)),
      fret_number_(std::move(fret_number)),
      fretted_(fretted),
      bin_s_(bin_s),
      until_s_(until_s),
      audio_rate_hz_(audio_rate_hz) {}

void NoteContacts::begin(const RunLayout& layout) {
    const Case& c = *layout.source;
    rate_ = layout.output_rate_hz;
    dx_ = c.grid_step();
    dt_ = layout.dt;
    const std::size_t n = c.mode_count();
    const std::size_t highest = fret_number_.empty() ? 0 : fret_number_.back();
    impulse_.assign(highest + 1, 0.0);
    stretch_impulse_.assign(highest + 1, 0.0);
    fret_of_point_.assign(n, kBoard);
    for (std::size_t i = 0; i < n; ++i) {
        const double x = c.grid_point(i);
        double best = 2.0 * dx_;
        for (std::size_t f = 0; f < fret_x_.size(); ++f)
            if (std::abs(fret_x_[f] - x) < best) {
                best = std::abs(fret_x_[f] - x);
                fret_of_point_[i] = static_cast<int>(fret_number_[f]);
            }
    }
    // The hand's contacts (finger pads, force pads, the stopping fret and all before it) are the fretting.
    const std::size_t first = fretted_ ? first_buzz_point(c) : 0;
    for (std::size_t i = 0; i < std::min(first, n); ++i) fret_of_point_[i] = kNoFret;
    const auto mark = [&](double centre, double width) {
        for (std::size_t i : pad_points(centre, width, dx_, n)) fret_of_point_[i] = kNoFret;
    };
    for (const FingerSpec& f : c.fingers) mark(f.position_m, f.width_m);
    for (const ForceSpec& f : c.forces) mark(f.position_m, f.width_m);
    // The rows a run of until_s would give: one at t = 0, then one every stride.
    const long steps = until_s_ > 0.0 ? std::min(layout.steps, std::lround(until_s_ / layout.dt)) : layout.steps;
    rows_ = static_cast<std::size_t>(steps / layout.output_stride) + 1;
    signal_.clear();
    signal_.reserve(rows_ + 1);
    points_ = std::max<std::size_t>(layout.observation_points_m.size(), 1);
    const double run_s = static_cast<double>(layout.steps) * layout.dt;
    const double heard_s = until_s_ > 0.0 ? std::min(until_s_, run_s) : run_s;
    heard_rows_ = static_cast<std::size_t>(std::lround(heard_s * audio_rate_hz_)) + 1;
    heard_.clear();
    if (audio_rate_hz_ > 0.0) heard_.reserve(heard_rows_);
    stretches_.clear();
    steps_ = 0;
}

void NoteContacts::observation(double, std::span<const double> u) {
    if (!u.empty() && signal_.size() < rows_) signal_.push_back(u[0]);
}

void NoteContacts::audio(long, std::span<const double> samples) {
    for (std::size_t i = 0; i < samples.size() && heard_.size() < heard_rows_; i += points_) heard_.push_back(samples[i]);
}

void NoteContacts::contacts(double t, std::span<const std::pair<std::size_t, double>> forces) {
    if (until_s_ > 0.0 && t > until_s_ + 0.5 * dt_) return;
    double total = 0.0;
    for (const auto& [i, f] : forces)
        if (fret_of_point_[i] != kNoFret) total += f * dx_;
    if (!(total > 0.0)) return;
    if (steps_ == 0) first_ = t;
    ++steps_;
    peak_ = std::max(peak_, total);
    const double start = bin_s_ * std::floor(t / bin_s_);
    if (stretches_.empty() || stretches_.back().time_s != start) {
        std::fill(stretch_impulse_.begin(), stretch_impulse_.end(), 0.0);
        stretches_.push_back({start, 0.0, 0.0, kNoFret});
    }
    for (const auto& [i, f] : forces) {
        if (fret_of_point_[i] == kNoFret) continue;
        const auto fret = static_cast<std::size_t>(fret_of_point_[i]);
        impulse_[fret] += f * dx_ * dt_;
        stretch_impulse_[fret] += f * dx_ * dt_;
    }
    ContactStretch& s = stretches_.back();
    s.impulse_n_s += total * dt_;
    s.peak_force_n = std::max(s.peak_force_n, total);
    s.fret = static_cast<int>(std::max_element(stretch_impulse_.begin(), stretch_impulse_.end()) - stretch_impulse_.begin());
}

int NoteContacts::main_fret() const {
    if (steps_ == 0) return kNoFret;
    return static_cast<int>(std::max_element(impulse_.begin(), impulse_.end()) - impulse_.begin());
}

NotePlayer::NotePlayer(const NoteMaker& maker, std::size_t fret, bool finger, const ListeningSettings& listening)
    : maker_(maker), fret_(fret), finger_(finger), listening_(listening) {}

double NotePlayer::touch_free_size(const Attack& attack, const PluckVariation& pluck) const {
    if (finger_ || attack.strike()) return 0.0;
    // The free motion is linear in the size: the bound of a pluck small enough to touch
    // nothing at release (a micrometre) scales to every size.
    constexpr double kSmall = 1e-6;
    Attack small = attack;
    small.size = kSmall;
    if (z_share(small, pluck) == 0.0) return std::numeric_limits<double>::infinity();
    return touch_free_scale(maker_.stand_in(fret_, small, pluck)) * kSmall;
}

const NotePlayer::Reference* NotePlayer::reference(const Attack& attack, std::size_t member, const Case& played,
                                                   double share, double judged_s) {
    // The clean note: the same pluck with nothing to touch, heard through the same audio path.
    const auto clean_of = [&](const Case& c, double z) {
        Case free = without_obstacle_from(c, 0);
        free.run.duration_s = judged_s;
        return Reference{attack.gesture, member, z, listener_->hear_clean(pickup_audio(free, listening_.rate_hz)), {}};
    };
    // Linear plucks: the clean note of the member's shape, kept for its other sizes. A pluck
    // that rests on a fret when let go (taut_over_obstacle) has a shape of its own.
    Reference* kept = nullptr;
    for (Reference& r : references_)
        if (r.gesture == attack.gesture && r.member == member) kept = &r;
    if (!kept) {
        constexpr double kSmall = 1e-6;  // m: too small to meet any fret
        Attack small = attack;
        small.size = kSmall;
        const PluckVariation& variation = members_at_.at(member);
        const Case unit = maker_.stand_in(fret_, small, variation);
        references_.push_back(clean_of(unit, z_share(small, variation)));
        references_.back().shape = unit.initial_displacement;
        kept = &references_.back();
    }
    const double ratio = share / kept->z_share;
    double largest = 0.0, apart = 0.0;
    for (std::size_t j = 0; j < played.initial_displacement.size(); ++j) {
        largest = std::max(largest, std::abs(played.initial_displacement[j]));
        apart = std::max(apart, std::abs(played.initial_displacement[j] - ratio * kept->shape[j]));
    }
    if (apart <= 1e-9 * largest) return kept;
    scratch_ = clean_of(played, share);
    return &scratch_;
}

PluckOutcome NotePlayer::play(const Attack& attack, double size, std::size_t member, const PluckVariation& pluck,
                              const PluckOptions& options) {
    Attack sized = attack;
    sized.size = size;
    PluckOutcome o;
    o.size = size;
    if (auto why = maker_.unplayable(fret_, sized, pluck, finger_)) {
        o.error = "not played: " + *why;
        return o;
    }
    Case c = finger_ ? maker_.fingered(fret_, sized, pluck) : maker_.stand_in(fret_, sized, pluck, options.polarisations);
    if (!options.keep_details && c.run.output_rate_hz) c.run.output_rate_hz = std::min(*c.run.output_rate_hz, kUnreadRowRateHz);
    if (options.wav.empty() && !options.keep_details && !finger_ && never_touches(c)) return o;
    const double judged_s = c.run.duration_s;
    // A longer sound: the same run, going on (the first judged_s of it are what a run of that length gives).
    const bool longer = !options.wav.empty() && options.sound_s > judged_s;
    if (longer) c.run.duration_s = options.sound_s;
    return judge(c, sized, member, pluck, options, longer ? judged_s : 0.0);
}

PluckOutcome NotePlayer::judge(const Case& c, const Attack& attack, std::size_t member, const PluckVariation& pluck,
                               const PluckOptions& options, double judged_s) {
    PluckOutcome o;
    o.size = attack.size;
    NoteContacts contacts(maker_.fret_positions(fret_, finger_), maker_.fret_numbers(fret_), finger_, 5e-4, judged_s,
                          listening_.rate_hz);
    std::vector<RunObserver*> observers{&contacts};
    std::unique_ptr<AudioWriter> audio;
    if (!options.wav.empty()) {
        audio = std::make_unique<AudioWriter>(std::vector<std::filesystem::path>{options.wav}, 48000.0,
                                              AudioSignal::velocity,
                                              AudioFades{kFadeIn, judged_s > 0.0 ? kSoundFadeOut : kFadeOut});
        observers.push_back(audio.get());
    }
    try {
        simulate(c, observers);
    } catch (const SolverError& e) {
        o.error = std::string("failed: ") + e.what();
        return o;
    }
    o.simulated = true;
    o.touched = contacts.touched();
    o.buzz_fret = contacts.main_fret();
    o.first_contact_s = contacts.first_contact_s();
    o.peak_force_n = contacts.peak_force_n();
    if (options.keep_details) {
        o.signal = contacts.signal();
        o.signal_rate_hz = contacts.output_rate_hz();
        o.contacts = contacts.stretches();
        if (audio) {
            o.audio = audio->samples(0);
            o.audio_rate_hz = audio->rate_hz();
        }
    }
    if (!listener_)
        listener_.emplace(contacts.audio_rate_hz(), contacts.heard().size(), maker_.fundamental_hz(fret_), listening_);
    if (!o.touched) return o;
    const double judged = judged_s > 0.0 ? judged_s : c.run.duration_s;
    if (finger_ || attack.strike() || options.polarisations == Polarisations::both) {
        // Not linear (a finger, a thumb) or in two polarisations: the same note with nothing to buzz against past the stop.
        Case free = without_obstacle_from(c, finger_ ? first_buzz_point(c) : 0);
        free.run.duration_s = judged;
        o.buzz_db = listener_->added_level(contacts.heard(), pickup_audio(free, listening_.rate_hz)).level_db;
        return o;
    }
    const double share = z_share(attack, pluck);
    if (members_at_.size() <= member) members_at_.resize(member + 1);
    members_at_[member] = pluck;
    const Reference* r = reference(attack, member, c, share, judged);
    const double ratio = share / r->z_share;
    o.buzz_db = listener_->added_level(contacts.heard(), r->clean, ratio * ratio).level_db;
    return o;
}

bool heard_to_buzz(const PluckOutcome& o, double audible_db) {
    return o.error.empty() && o.touched && o.buzz_db >= audible_db;
}

PluckOutcome record_pluck(const Instrument& instrument, std::size_t string, std::size_t fret, const Attack& attack,
                          std::size_t member, bool finger, const std::filesystem::path& wav, double sound_s) {
    if (string >= instrument.strings.size())
        throw InputError(out_of_range_message("string", static_cast<double>(string), "must be a string of " +
                                                                                         instrument.name));
    if (fret > instrument.neck.fret_count)
        throw InputError(out_of_range_message("fret", static_cast<double>(fret),
                                              "must be in [0, " + std::to_string(instrument.neck.fret_count) + "]"));
    if (member >= instrument.attack.ensemble)
        throw InputError(out_of_range_message("member", static_cast<double>(member),
                                              "must be in [0, " + std::to_string(instrument.attack.ensemble - 1) + "]"));
    const std::vector<PluckVariation> members = ensemble(instrument.attack, string, fret, member + 1);
    const NoteMaker maker(instrument, string);
    NotePlayer player(maker, fret, finger, listening_settings(instrument.bench));
    // The audio goes through the note's own WAV writer, into a folder of its own.
    std::random_device random;
    const std::filesystem::path folder =
        std::filesystem::temp_directory_path() / ("fretbuzz-note-" + std::to_string(random()) + std::to_string(random()));
    std::filesystem::create_directory(folder);
    PluckOptions options;
    options.keep_details = true;
    options.polarisations = Polarisations::both;
    options.wav = wav.empty() ? folder / "note.wav" : wav;
    options.sound_s = wav.empty() ? 0.0 : sound_s;
    PluckOutcome outcome;
    try {
        outcome = player.play(attack, attack.size, member, members[member], options);
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove_all(folder, ec);
        throw;
    }
    std::error_code ec;
    std::filesystem::remove_all(folder, ec);
    return outcome;
}

ListeningSettings listening_settings(const BenchSettings& bench) {
    ListeningSettings s;
    s.level_db_spl = bench.listening_level_db_spl;
    if (bench.listen_through_rig) s.rig = bench.rig;
    return s;
}

std::vector<double> pickup_audio(const Case& c, double rate_hz) {
    NoteContacts heard({}, {}, false, 5e-4, 0.0, rate_hz);
    std::vector<RunObserver*> observers{&heard};
    simulate(c, observers);
    return heard.heard();
}

}  // namespace fretbuzz
