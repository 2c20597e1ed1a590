#pragma once
// What-ifs: the set-up changes a luthier makes, each a new Instrument. What a change leaves
// alone stays where it physically is: turning the truss rod bows the neck under strings
// whose nut and saddle do not move (so the action over fret 12 changes with it); raising a
// fret moves neither the nut nor the saddle; lowering one string's saddle keeps its nut,
// and filing its nut slot keeps its saddle. So every string's ends are first pinned at their
// heights (StringNeck's nut and saddle heights), then the change is made.
//  - relief: the truss rod set so that the relief gap (the luthier's measure under the first
//    string, at the neck's relief fret) is the given one;
//  - action12 / nut / saddle of one string: its gap over fret 12, over fret 1, or the
//    saddle's height above the fret plane;
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

struct SetupChange {
    std::optional<double> relief_m;
    std::vector<std::pair<std::string, double>> action12_m, nut_m, saddle_m;  // string name, value
    std::vector<FretChange> frets;
    std::optional<std::string> string_set;                // the strings replaced by this named set's
    std::vector<std::pair<std::string, double>> pitch_hz;  // string name, its new open pitch
    bool empty() const {
        return !relief_m && action12_m.empty() && nut_m.empty() && saddle_m.empty() && frets.empty() &&
               !string_set && pitch_hz.empty();
    }
};

// Every string's ends as heights above the fret plane (where they physically are).
Instrument with_pinned_string_ends(const Instrument& instrument);

// The instrument after the change. InputError naming the option (--relief, --action12,
// --nut, --saddle, --fret-offset) and its range if a value is out of range or the change
// would put an open string on a fret.
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
