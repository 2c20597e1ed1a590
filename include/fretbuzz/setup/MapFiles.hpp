#pragma once
// The files of a buzz map, and a map compared with an earlier one.
//  - buzz_map.csv: one row per note and attack: string, fret, strength, verdict,
//    buzz_fraction with its 90 % interval (buzz_fraction_low, _high), buzz_dB (the median level
//    above the masked threshold), buzz_fret ("board" for the board or body, empty for none),
//    touch_fraction, plucks, clean_up_to (a multiple of the attack; inf: at least 3),
//    clean_up_to_value and its unit, stiffness_sensitive, status, clearance_mm, audio,
//    pluck_dB (each pluck's level, ';'-separated, empty where it touched nothing). Numbers
//    in their shortest form that reads back exactly.
//  - map.json: everything a page or the studio draws: the instrument's geometry, the
//    settings, the units the instrument file gives its gaps in, the verdicts, the comparison,
//    the advice and the fret dress (with the map after it) when there are.
#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"
#include "fretbuzz/setup/InstrumentGeometry.hpp"

namespace fretbuzz {

// The shortest decimal text that reads back as the same double ("" for NaN).
std::string shortest_text(double value);

void write_buzz_map_csv(const std::filesystem::path& path, std::span<const NoteVerdict> notes);
// An earlier map's buzz_map.csv (for --compare): InputError naming `option` and the file if
// it is missing, too large (64 MiB) or not a buzz map.
std::vector<NoteVerdict> read_buzz_map_csv(const std::filesystem::path& path, const std::string& option);

// How a note changed against the map before: "worse", "better" or "moved" by the first rule
// that applies (its reason): its verdict ("verdict"), then how many of its plucks buzz
// ("plucks"), then how much harder it stays clean, by a factor over kChangeCleanUpTo
// ("margin"), then, buzzing, kChangeDb louder or quieter ("loudness"), then the fret it buzzes
// against ("fret": moved); else "same", or "new" (not in the map before).
struct NoteChange {
    NoteVerdict now, before;
    std::string change;  // worse, better, moved, same, new
    std::string reason;  // the rule that decided it ("" for same and new)
};
inline constexpr double kChangeDb = 3.0;
inline constexpr double kChangeCleanUpTo = 1.1;
std::vector<NoteChange> compare_maps(std::span<const NoteVerdict> now, std::span<const NoteVerdict> before);
void write_comparison_csv(const std::filesystem::path& path, std::span<const NoteChange> changes);

// What map.json holds besides the instrument.
struct MapDocument {
    std::string command;                 // the command line that made it
    std::vector<std::string> changes;    // the what-ifs applied, as given
    std::vector<Attack> attacks;         // as played (calibrated, with --player)
    std::string player_file;             // the calibration.json the attacks were scaled by ("": none)
    double attack_scale = 1.0;           // that file's attack_scale
    bool finger = false;
    std::vector<NoteVerdict> notes;
    std::vector<NoteChange> comparison;  // empty: no comparison
    std::string compared_with;
    std::string advice_json;             // the advice as JSON text ("": none)
    std::string dress_json;              // the fret dress as JSON text ("": none), and the map after it
    std::vector<NoteVerdict> dressed_notes;
    double wall_seconds = 0.0;
};
void write_map_json(const std::filesystem::path& path, const Instrument& instrument, const MapDocument& document);

}  // namespace fretbuzz
