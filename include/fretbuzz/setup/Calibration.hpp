#pragma once
// The player's own touch. No published measurement gives a bass finger pluck's size at
// release (docs/setup.md, "Where the attacks come from"); the player's instrument does: a
// report of the notes they hear buzz or ring clean, played as they play, is explained by one
// attack scale s (a multiple of every attack's size) or by none.
//  - The report (REPORT.csv): a header naming the columns `string,fret,heard` and optionally
//    `strength` (an attack as --strength names one: soft, medium, hard, pick, pop, slap,
//    1.2mm, 3m/s; medium when left out), one row per note heard (`heard`: buzz or clean).
//  - The fit: the bench plays each reported note at its attack with the clean_up_to search
//    (setup/NoteJudge): at scale s the note is clean when s <= clean_up_to, and not clean
//    (some of the plucks a clean verdict rests on buzz) when s > clean_up_to. So a buzz row
//    bounds s from below by its clean_up_to, a clean row from above, and the scales that
//    disagree with the fewest rows form intervals between the notes' clean_up_to values.
//    The bench searches clean_up_to up to kCleanUpToCap: scales are fitted in (0, 3].
//  - The pluck's place and direction stay the instrument's: a second free parameter would
//    need several times the notes to be pinned down, and every note costs a clean_up_to search.
//  - --player: a calibration.json scales every later map's, what-if's, advice's and dress's attacks.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"

namespace fretbuzz {

inline constexpr std::size_t kMaxReportRows = 10000;
inline constexpr double kMaxAttackScale = 10.0;  // what --player accepts: (0, 10]

// One row of a player's report, checked against the instrument.
struct HeardNote {
    std::size_t row = 0;   // the data row, from 1 (the header is not counted)
    std::size_t line = 0;  // its line in the file, from 1
    std::size_t string = 0;
    std::string string_name;
    std::size_t fret = 0;
    Attack attack;          // as the row's `strength` names it
    bool buzz = false;      // heard: buzz (true) or clean
};

// Parses a report; InputError naming `option`, the source, the row and the column at fault
// and what is allowed (an unknown string, a fret off the neck, heard other than buzz/clean, no
// rows, more than kMaxReportRows).
std::vector<HeardNote> parse_player_report(std::string_view text, const std::string& source,
                                           const Instrument& instrument, const std::string& option = "--calibrate");
// The same from a file (a regular file of at most 4 MiB).
std::vector<HeardNote> read_player_report(const std::filesystem::path& path, const Instrument& instrument,
                                          const std::string& option = "--calibrate");

// A reported note with what the bench found.
struct CalibratedNote {
    HeardNote heard;
    std::string status;          // the map's: "ok", "frets out", "not played: ...", "failed: ..."
    double clean_up_to = NoteVerdict::nan;  // multiple of the row's attack (inf: at least kCleanUpToCap)
    bool used = false;           // it has a clean_up_to (a note that was not played bounds nothing)
    bool agrees = false;         // at the calibrated scale, the bench hears what the player heard
};

struct Calibration {
    std::vector<CalibratedNote> notes;  // in the report's order
    // The scale and the interval of scales that disagree with the fewest rows: (low, high],
    // as a note buzzes when s > clean_up_to. low = 0: no buzz row bounds it from below;
    // high = kCleanUpToCap with high_at_least: no clean row bounds it from above within the search.
    double attack_scale = NoteVerdict::nan;  // NaN: no note could be used
    double low = NoteVerdict::nan, high = NoteVerdict::nan;
    bool low_bounded = false, high_at_least = false;
    std::size_t disagreements = 0;           // rows the best scales leave unexplained
    // Further intervals as good as (low, high] (the scale then is not one range).
    std::vector<std::pair<double, double>> other_intervals;
    bool explained = false;    // some scale agrees with every used row
    std::string statement;     // the result in one plain sentence or two
    std::size_t plucks_simulated = 0;
    double wall_seconds = 0.0;
};

// The fit alone, from notes whose status and clean_up_to are known (`used` and `agrees` are
// set here). Among equally good intervals it takes the one nearest the instrument's own
// attack (scale 1, in ratio): the defaults are of the right order, and nothing else ranks them.
Calibration fit_attack_scale(std::vector<CalibratedNote> notes);

struct CalibrationRequest {
    bool finger = false;  // stopped notes by the finger model
    unsigned jobs = 0;    // threads; 0: the hardware's
    std::function<void(const NoteVerdict&, std::size_t done, std::size_t total)> on_note;
    // Asked before each pluck: true stops the calibration (Interrupted): a fit needs every note.
    std::function<bool()> stop;
};

// Plays the reported notes (each distinct note and attack once, clean_up_to searched) on the
// instrument as it is, and fits the scale. Throws Interrupted when stopped (Ctrl-C or `stop`).
Calibration calibrate_attack(const Instrument& instrument, const std::vector<HeardNote>& report,
                             const CalibrationRequest& request = {});

// calibration.json (source: the report's name, written into it) and a short summary.
std::string calibration_json(const Calibration& calibration, const Instrument& instrument, const std::string& source,
                             const std::string& command = "");
std::string calibration_text(const Calibration& calibration);

// A player's calibration, as --player reads it.
struct PlayerTouch {
    double attack_scale = 1.0;
    std::filesystem::path file;
};
// Reads calibration.json: a regular file of at most 1 MiB whose attack_scale is a finite number in
// (0, kMaxAttackScale]. InputError naming `option` for a bad file; std::runtime_error (exit 1)
// when it cannot be read.
PlayerTouch read_player_touch(const std::filesystem::path& path, const std::string& option = "--player");
// scale, if a calibration can have found it: finite, in (0, kMaxAttackScale]; else InputError
// "NAME = V is out of range: must be in (0, 10]" and `why` after it.
double checked_attack_scale(const std::string& name, double scale, const std::string& why = "");
// Every attack's size times the scale (its label kept: the map says it was calibrated).
void scale_attacks(std::vector<Attack>& attacks, double scale);

}  // namespace fretbuzz
