#pragma once
// The buzz map of an instrument: every note of every string (open, every fret, the last one
// included) at each attack, each note's verdict from an ensemble of plucks grown until it is
// sure (NoteJudge):
//  - verdict: "clean", "marginal" or "buzzes" (a note buzzes when more than one pluck in ten
//    is heard to buzz), with the buzz fraction and its 90 % interval;
//  - buzz_db: the median level of the plucks above the masked threshold (0 dB: just heard),
//    those that touch nothing counting as the quietest (none when half of them or more
//    touch nothing);
//  - buzz_fret: the fret the audible plucks buzz against most often (0: the board or body);
//  - clean_up_to: how much harder than the attack the note can be played and stay clean;
//  - first_touch_s: when its plucks first touch a fret past the stop (the median over the
//    plucks that touch), with each pluck's own: a touch long after the release comes from the
//    partials drifting out of phase and meeting again, not from the release shape itself;
//  - stiffness_sensitive: with MapRequest::stiffness_check, whether the verdict changes when
//    the string's bending stiffness is halved or made 1.5 times (the wound strings' cores are
//    rarely published: the stiffness is the least sure input).
// A note whose string at rest already lies on a fret past the stop (a high fret) frets out:
// it is reported as buzzing against that fret without being played. The notes are played
// on a pool of threads, one note a task, and reported as each note completes.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/NoteJudge.hpp"
#include "fretbuzz/setup/NotePlayer.hpp"

namespace fretbuzz {

struct NoteVerdict {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::size_t string = 0;
    std::string string_name;
    std::size_t fret = 0;
    std::string strength;          // the attack's label
    std::string status = "ok";     // "ok", "frets out", "not played: ...", "failed: ..."
    std::string verdict;           // "clean", "marginal", "buzzes" ("buzzes" when it frets out; "" not played)
    double buzz_fraction = 0.0;
    double buzz_fraction_low = nan, buzz_fraction_high = nan;  // its 90 % interval
    double touch_fraction = 0.0;
    double buzz_db = nan;          // median level above the masked threshold (dB)
    int buzz_fret = kNoFret;
    std::size_t plucks = 0;        // plucks played
    std::vector<double> pluck_db;  // each pluck's level (NaN: touched nothing)
    std::vector<int> pluck_fret;
    std::vector<double> pluck_touch_s;  // each pluck's first touch past the stop (NaN: none)
    double first_touch_s = nan;    // the median of those that touch (NaN: none touches)
    double clean_up_to = nan;       // the strongest attack that stays clean, as a multiple of this one (inf: >= 3)
    double clean_up_to_value = nan;  // the same in the attack's unit (mm or m/s)
    std::string unit;                // "mm" or "m/s"
    std::string stiffness_sensitive;  // "" not checked; "no"; or the factors that change it: "0.5", "1.5", "0.5,1.5"
    double clearance_m = nan;      // the smallest gap between the note's string at rest and a fret past the stop
    std::string audio;             // its WAV (the attack itself), in the map's folder; "" if none
    // The ensemble member whose outcome agrees with the verdict, to be heard for it: the loudest
    // pluck of a note that buzzes or is marginal, the loudest one not heard of a clean note.
    std::size_t deciding_pluck = 0;
};

// The verdict of one note and attack from its judgement (the fraction, levels and frets).
NoteVerdict summarise(const AttackJudgement& judgement, double audible_db);

// A note of the map: a string (index into Instrument::strings) stopped at a fret (0: open).
struct MapNote {
    std::size_t string, fret;
};

// How long each note's sound (its WAV) lasts: long enough to judge by ear. The note is judged
// on the bench's own duration (BenchSettings::duration_s); its first pluck runs on to this.
inline constexpr double kNoteSoundSeconds = 1.5;

struct MapRequest {
    std::vector<std::size_t> strings;   // indices into Instrument::strings; empty: all
    std::vector<std::size_t> frets;     // empty: 0 .. the last fret
    // Instead of strings x frets: these notes, played in this order (the searches play the
    // notes likeliest to buzz first, and stop at the first that does).
    std::vector<MapNote> notes;
    std::vector<Attack> attacks;
    bool finger = false;
    bool clean_up_to = true;            // search each note's clean_up_to
    bool stiffness_check = false;       // replay each note with the bending stiffness x 0.5 and x 1.5
    unsigned jobs = 0;                  // threads; 0: the hardware's
    std::filesystem::path audio_dir;    // where the notes' WAVs go (empty: none), named as note_audio_name says
    double sound_s = kNoteSoundSeconds;  // each WAV's length (at least the bench's duration)
    // Called (from a worker thread, one call at a time) as each note's verdicts are ready.
    std::function<void(const NoteVerdict&, std::size_t done, std::size_t total)> on_note;
    // Stops the map early (the notes under way finish) once a verdict satisfies it: a search
    // that only asks whether a map is clean needs no more than its first buzzing note.
    std::function<bool(const NoteVerdict&)> stop_when;
    // Asked before each pluck starts: true stops the map there (the plucks under way finish),
    // as stop_when does.
    std::function<bool()> stop;
};

struct BuzzMapResult {
    std::vector<NoteVerdict> notes;     // string by string, fret by fret, attack by attack
    std::size_t plucks_simulated = 0;   // runs of the scheme
    std::size_t plucks_clear = 0;       // plucks shown clear of every fret without a run
    double wall_seconds = 0.0;
    unsigned jobs = 1;
    bool stopped_early = false;         // stop_when ended it: notes after the one that did are missing
};

// The notes of a map request, checked: InputError naming --strings or --frets (a fret that
// does not exist) before anything runs.
std::vector<MapNote> map_notes(const Instrument& instrument, const MapRequest& request);

// Plays the map. Throws Interrupted (Ctrl-C) after the notes under way stop; InputError for
// a bad request.
BuzzMapResult play_map(const Instrument& instrument, const MapRequest& request);

// The WAV file name of a note: "note-E-03-soft.wav".
std::string note_audio_name(const std::string& string_name, std::size_t fret, const std::string& attack);

}  // namespace fretbuzz
