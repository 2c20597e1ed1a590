#pragma once
// The buzz map of an instrument: every note of every string (open, every fret, the last one
// included) at each attack, each note's verdict from its ensemble of plucks (Attack.hpp):
//  - buzz_fraction: the share of plucks whose buzz level reaches the audible threshold
//    (BenchSettings::audible_db; docs/setup.md says why that value);
//  - buzz_db: the median buzz level of the plucks, those that touch nothing counting as the
//    quietest (none when half of them or more touch nothing);
//  - buzz_fret: the fret the audible plucks buzz against most often (0: the board or body).
// A note whose string at rest already lies on a fret past the stop (a high fret) frets out:
// it is reported as buzzing against that fret without being played. The notes are played
// on a pool of threads, ensemble members as tasks, and reported as each note completes.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/NotePlayer.hpp"

namespace fretbuzz {

struct NoteVerdict {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::size_t string = 0;
    std::string string_name;
    std::size_t fret = 0;
    std::string strength;          // the attack's label
    std::string status = "ok";     // "ok", "frets out", "not played: ...", "failed: ..."
    double buzz_fraction = 0.0;
    double touch_fraction = 0.0;
    double buzz_db = nan;
    int buzz_fret = kNoFret;
    std::size_t plucks = 0;        // plucks played
    std::vector<double> pluck_db;  // each pluck's buzz level (NaN: touched nothing)
    std::vector<int> pluck_fret;
    double clearance_m = nan;      // the smallest gap between the note's string at rest and a fret past the stop
    std::string audio;             // its WAV (the attack itself), in the map's folder; "" if none
};

// The verdict from the plucks of one note and attack.
NoteVerdict judge(std::vector<PluckOutcome> plucks, double audible_db);

struct MapRequest {
    std::vector<std::size_t> strings;   // indices into Instrument::strings; empty: all
    std::vector<std::size_t> frets;     // empty: 0 .. the last fret
    std::vector<Attack> attacks;
    bool finger = false;
    unsigned jobs = 0;                  // threads; 0: the hardware's
    std::filesystem::path audio_dir;    // where the notes' WAVs go (empty: none), named as note_audio_name says
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
struct MapNote {
    std::size_t string, fret;
};
std::vector<MapNote> map_notes(const Instrument& instrument, const MapRequest& request);

// Plays the map. Throws Interrupted (Ctrl-C) after the notes under way stop; InputError for
// a bad request.
BuzzMapResult play_map(const Instrument& instrument, const MapRequest& request);

// The WAV file name of a note: "note-E-03-soft.wav".
std::string note_audio_name(const std::string& string_name, std::size_t fret, const std::string& attack);

}  // namespace fretbuzz
