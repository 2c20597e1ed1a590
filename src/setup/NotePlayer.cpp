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
#include "fretbuzz/scheme/TimeProfile.hpp"

namespace fretbuzz {

namespace {

constexpr double kFadeIn = 0.005;   // s: a plucked string starts displaced
constexpr double kFadeOut = 0.05;   // s: a note cut at the end of the run must not click

double attack_size(const Attack& a) { return a.kind == AttackKind::slap ? a.velocity : a.amplitude_m; }

double level_db(std::vector<double> u, const std::vector<double>& free, double rate, double band) {
    const std::size_t n = std::min(u.size(), free.size());
    u.resize(n);
    for (std::size_t i = 0; i < n; ++i) u[i] -= free[i];
    const std::span<const double> reference(free.data(), n);
    return buzz_level_db(high_frequency_energy(u, rate, band), high_frequency_energy(reference, rate, band));
}

}  // namespace

NoteContacts::NoteContacts(std::vector<double> fret_x, std::vector<std::size_t> fret_number, double bin_s)
    : fret_x_(std::move(fret_x)), fret_number_(std::move(fret_number)), bin_s_(bin_s) {}

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
    const std::size_t first = first_buzz_point(c);
    for (std::size_t i = 0; i < std::min(first, n); ++i) fret_of_point_[i] = kNoFret;
    const auto mark = [&](double centre, double width) {
        for (std::size_t i : pad_points(centre, width, dx_, n)) fret_of_point_[i] = kNoFret;
    };
    for (const FingerSpec& f : c.fingers) mark(f.position_m, f.width_m);
    for (const ForceSpec& f : c.forces) mark(f.position_m, f.width_m);
    signal_.clear();
    signal_.reserve(static_cast<std::size_t>(layout.steps / layout.output_stride) + 2);
    stretches_.clear();
    steps_ = 0;
}

void NoteContacts::observation(double, std::span<const double> u) {
    if (!u.empty()) signal_.push_back(u[0]);
}

void NoteContacts::contacts(double t, std::span<const std::pair<std::size_t, double>> forces) {
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

std::vector<PluckOutcome> play_plucks(const NoteMaker& maker, std::size_t fret, std::span<const Attack> attacks,
                                      const PluckVariation& pluck, const PluckRequest& request,
                                      std::span<const std::filesystem::path> wav_paths) {
    std::vector<PluckOutcome> outcomes(attacks.size());
    struct Reference {
        const Attack* attack;
        std::vector<double> u;
    };
    std::vector<Reference> references;
    for (std::size_t k = 0; k < attacks.size(); ++k) {
        const Attack& attack = attacks[k];
        PluckOutcome& o = outcomes[k];
        if (auto why = maker.unplayable(fret, attack, pluck, request.finger)) {
            o.error = "not played: " + *why;
            continue;
        }
        const Case c = request.finger ? maker.fingered(fret, attack, pluck) : maker.stand_in(fret, attack, pluck);
        const bool wav = k < wav_paths.size() && !wav_paths[k].empty();
        if (!wav && !request.keep_details && !request.finger && never_touches(c)) continue;
        NoteContacts contacts(maker.fret_positions(fret, request.finger), maker.fret_numbers(fret));
        std::vector<RunObserver*> observers{&contacts};
        std::unique_ptr<AudioWriter> audio;
        if (wav) {
            audio = std::make_unique<AudioWriter>(std::vector<std::filesystem::path>{wav_paths[k]}, 48000.0,
                                                  AudioSignal::displacement, AudioFades{kFadeIn, kFadeOut});
            observers.push_back(audio.get());
        }
        try {
            simulate(c, observers);
        } catch (const SolverError& e) {
            o.error = std::string("failed: ") + e.what();
            continue;
        }
        o.simulated = true;
        o.touched = contacts.touched();
        o.buzz_fret = contacts.main_fret();
        o.first_contact_s = contacts.first_contact_s();
        o.peak_force_n = contacts.peak_force_n();
        if (request.keep_details) {
            o.signal = contacts.signal();
            o.signal_rate_hz = contacts.output_rate_hz();
            o.contacts = contacts.stretches();
            if (audio) {
                o.audio = audio->samples(0);
                o.audio_rate_hz = audio->rate_hz();
            }
        }
        if (!o.touched) continue;
        const double rate = contacts.output_rate_hz();
        if (request.finger) {
            // The same note with nothing to buzz against past the stopping fret.
            Case free = c;
            for (std::size_t i = first_buzz_point(c); i < free.obstacle_height_m.size(); ++i)
                free.obstacle_height_m[i] = -std::numeric_limits<double>::infinity();
            NoteContacts quiet(maker.fret_positions(fret, true), maker.fret_numbers(fret));
            std::vector<RunObserver*> one{&quiet};
            simulate(free, one);
            o.buzz_db = level_db(contacts.signal(), quiet.signal(), rate, request.band_hz);
            continue;
        }
        auto shared = std::find_if(references.begin(), references.end(),
                                   [&](const Reference& r) { return r.attack->same_shape(attack); });
        if (shared == references.end()) {
            references.push_back({&attack, free_motion_at(c, c.observation_points_m[0], 1.0 / rate,
                                                          contacts.signal().size())});
            shared = references.end() - 1;
        }
        std::vector<double> free = shared->u;
        const double ratio = attack_size(attack) / attack_size(*shared->attack);
        for (double& v : free) v *= ratio;
        o.buzz_db = level_db(contacts.signal(), free, rate, request.band_hz);
    }
    return outcomes;
}

PluckOutcome record_pluck(const Instrument& instrument, std::size_t string, std::size_t fret, const Attack& attack,
                          std::size_t member, bool finger) {
    if (string >= instrument.strings.size())
        throw InputError(out_of_range_message("string", static_cast<double>(string), "must be a string of " +
                                                                                         instrument.name));
    if (fret > instrument.neck.fret_count)
        throw InputError(out_of_range_message("fret", static_cast<double>(fret),
                                              "must be in [0, " + std::to_string(instrument.neck.fret_count) + "]"));
    const std::vector<PluckVariation> members = ensemble(instrument.attack, string, fret);
    if (member >= members.size())
        throw InputError(out_of_range_message("member", static_cast<double>(member),
                                              "must be in [0, " + std::to_string(members.size() - 1) + "]"));
    const NoteMaker maker(instrument, string);
    PluckRequest request;
    request.finger = finger;
    request.band_hz = instrument.bench.buzz_band_hz;
    request.keep_details = true;
    // The audio goes through the note's own WAV writer, into a folder of its own.
    std::random_device random;
    const std::filesystem::path folder =
        std::filesystem::temp_directory_path() / ("fretbuzz-note-" + std::to_string(random()) + std::to_string(random()));
    std::filesystem::create_directory(folder);
    const std::vector<std::filesystem::path> wav{folder / "note.wav"};
    const Attack attacks[] = {attack};
    std::vector<PluckOutcome> outcome;
    try {
        outcome = play_plucks(maker, fret, attacks, members[member], request, wav);
    } catch (...) {
        std::error_code ec;
        std::filesystem::remove_all(folder, ec);
        throw;
    }
    std::error_code ec;
    std::filesystem::remove_all(folder, ec);
    return std::move(outcome.front());
}

}  // namespace fretbuzz
