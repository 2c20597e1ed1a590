#pragma once
// What-ifs: the set-up changes a luthier makes, each a new Instrument. What a change leaves
// alone stays where it physically is: turning the truss rod bows the neck under strings
// whose nut and saddle do not move (so the action over fret 12 changes with it); raising a
// fret moves neither the nut nor the saddle; lowering one string's saddle keeps its nut,
// and filing its nut slot keeps its saddle. So every string's ends are first pinned at their
// heights (StringNeck's nut and saddle heights), then the change is made.
//  - relief: the truss rod set so that the relief gap (the luthier's measure under the first
//    string, at the neck's relief fret) is the given one;
//  - action of one string at fret K (action12: K = 12): its saddle raised or lowered, the nut
//    and the neck held, until its gap over fret K is the given one (the saddle moves about
//    L / x_K times the gap's change: twice at fret 12); nut / saddle of one string: its gap
//    over fret 1, or the saddle's height above the fret plane;
//  - relative moves: the relief, a nut or a saddle changed by an amount from where it is
//    (--relief-change, --nut-change: the nut's height, --saddle-change: the saddle's);
//  - screw turns, where the instrument file says what a turn does ([adjusters]): the truss
//    rod (+ clockwise, tighter: less relief) and a saddle's height screws (+ clockwise: up),
//    each the relative move it makes;
//  - fret offset: fret k raised (+) or lowered (-) by an amount, or levelled: dressed down
//    until its top lies on the line through its neighbours' tops under every string;
//  - strings: a named set's strings at the same pitches, or one string retuned (drop D):
//    their tensions change, and the neck, its truss rod left as it was, bows with the pull
//    (geometry/NeckBeam.hpp). These come first: a --relief with them is the truss rod set
//    again under the new strings.
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"

namespace fretbuzz {

struct FretChange {
    std::size_t fret = 0;
    std::optional<double> by_m;  // nothing: level it
};

// One string's action: its gap over a fret (2 to the last), set by its saddle.
struct ActionChange {
    std::string string;
    std::size_t fret = 12;
    double gap_m = 0.0;
};

struct SetupChange {
    std::optional<double> relief_m, relief_change_m;
    std::vector<ActionChange> action_m;
    std::vector<std::pair<std::string, double>> nut_m, saddle_m;                // string name, value
    std::vector<std::pair<std::string, double>> nut_change_m, saddle_change_m;  // string name, by how much (+ up)
    std::optional<double> truss_rod_turns;                               // + clockwise (tighter)
    std::vector<std::pair<std::string, double>> saddle_turns;            // string name, turns (+ up)
    std::vector<FretChange> frets;
    std::optional<std::string> string_set;                // the strings replaced by this named set's
    std::vector<std::pair<std::string, double>> pitch_hz;  // string name, its new open pitch
    bool empty() const {
        return !relief_m && !relief_change_m && action_m.empty() && nut_m.empty() && saddle_m.empty() &&
               nut_change_m.empty() && saddle_change_m.empty() && !truss_rod_turns && saddle_turns.empty() && frets.empty() && !string_set && pitch_hz.empty();
    }
};

// The what-ifs as the command line types them, each as written: "E=2.2mm", "17:E=3/32in",
// "+0.002in", "7=level". A length takes its unit (mm, in, a fraction of an inch in any
// denominator: "3/32 in", '5/64"', or thou: 0.001 in); a bare number is in the instrument
// file's own units (written_length_unit: in for a file that gives its action in inches).
struct WhatIfWords {
    std::string relief, relief_change, truss_rod_turns, string_set;
    std::vector<std::string> action12, action, nut, nut_change, saddle, saddle_change, saddle_turns, fret_offsets, tune;
    // "--relief 0.012", ... in the command's order of kinds, for the map's record.
    std::vector<std::string> words() const;
};

// The change the words ask for, and each value as it was read ("relief: 0.012 in (0.305 mm)",
// "action at fret 17, E: 3/32 in (2.381 mm)"). InputError naming the option and the form it
// takes if a value is not of it (the ranges are apply_change's).
// The most turns a what-if takes: a truss rod is turned an eighth to a half at a time, and
// past a couple of turns it is near the end of its travel; a saddle screw's thread is short.
inline constexpr double kMostTrussRodTurns = 2.0;
inline constexpr double kMostSaddleTurns = 20.0;

struct WhatIfReading {
    SetupChange change;
    std::vector<std::string> as_read;
};
WhatIfReading read_what_ifs(const WhatIfWords& words, const Instrument& instrument);

// Every string's ends as heights above the fret plane (where they physically are).
Instrument with_pinned_string_ends(const Instrument& instrument);

// The instrument after the change. InputError naming the option (--relief, --action12,
// --action, --nut, --saddle, their -change forms, --truss-rod-turns, --saddle-turns,
// --fret-offset) and its range if a value is
// out of range, one string end is set twice, or the change would put an open string on a fret.
Instrument apply_change(const Instrument& instrument, const SetupChange& change);

// How far fret `fret`'s top stands above the line through its neighbours' tops (the last fret:
// through the two before it), under the string where it stands most (m; <= 0: not proud).
// Levelling it (FretChange without by_m) takes this off.
double proud_height(const Instrument& instrument, std::size_t fret);

// The fret the neck's relief is measured at (the relief's own, else 8 or the last fret but one).
std::size_t relief_fret(const Instrument& instrument);

// What a change of the strings' pull did to the neck: the pull before and after (N), the bow
// it added (m, + down, NeckBeam.hpp) and the relief gap under the first string at the relief
// fret before and after. Nothing when the pull is the same.
struct PullChange {
    double before_n = 0.0, after_n = 0.0, bow_m = 0.0;
    double relief_before_m = 0.0, relief_after_m = 0.0;
    std::size_t fret = 0;
};
std::optional<PullChange> pull_change(const Instrument& before, const Instrument& after);

}  // namespace fretbuzz
