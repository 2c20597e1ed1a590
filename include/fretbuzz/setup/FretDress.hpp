#pragma once
// The virtual fret dress: the least fret material to take off, fret by fret, so that every
// note it answers for passes at the chosen attack and set-up (a note passes as the advice
// judges it: AdviceRequest's attack, strings, frets and tolerance). Plek's Virtual Fret Dress
// works it out from a static scan of the fret tops; here it comes from the strings' dynamics,
// by playing:
//  - first, if asked, a fall-away: the frets past fret F dressed down along a straight line,
//    nothing at F, the depth at the last fret the shallowest at which no note fails against
//    a fret past F (bisection on a 0.01 mm grid);
//  - then round after round: for each fret a failing note buzzes against, up the neck, the
//    least taken off it (bisection on a 0.01 mm grid, at least kFileCut off a fret not yet
//    touched, starting where the notes' clean_up_to predicts) that stops those notes failing
//    against it. Lowering a fret gives the notes stopped below it more room and the note stopped on it less (its string starts lower):
//    such a note, failing now against a fret further up, joins that fret's turn; the next
//    round plays every note again on the dressed neck, until every note passes, or no fret a note
//    fails against can go lower (at most max_depth_m off a fret, its crown kept min_crown_m
//    above the board), or nothing more helps.
// The frets are dressed through the what-ifs' fret offsets (setup/WhatIf: the strings' nut
// and saddle stay where they are). A fret standing proud comes down by about what it stands
// above its neighbours (no more: the notes pass once it is back in line); a level neck on
// which every note passes needs nothing.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Advice.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"

namespace fretbuzz {

inline constexpr double kDressStep = 0.01e-3;  // m: about what one pass of a levelling beam takes
inline constexpr double kFileCut = 0.02e-3;    // m: the least a fret file takes off a fret it touches

struct DressRequest {
    AdviceRequest play;
    double max_depth_m = 0.3e-3;   // off any one fret, at most
    // The crown's height above the board kept, at least (none: 0.75 mm, or half the frets'
    // height on lower frets).
    std::optional<double> min_crown_m;
    std::optional<std::size_t> fall_away_from;  // a fall-away over the frets past this one
};

// InputError naming --dress-depth, --crown or --fall-away and the range when out of range.
void check_dress_request(const Instrument& instrument, const DressRequest& request);

struct DressResult {
    std::vector<double> remove_m;   // per fret (index 0, the nut, unused): what comes off its top
    std::size_t fall_away_from = 0;  // the fall-away's start (0: none), and its depth at the last fret
    double fall_away_m = 0.0;
    std::vector<std::string> unresolved;  // what the dress could not clear, and why
    std::vector<NoteVerdict> after;       // the map after the dress (the notes answered for, at the attack)
    bool clean = false;                   // every note answered for passes after it
    Instrument dressed;
    ShopUnits units = ShopUnits::mm;
    std::string attack;
    std::size_t maps = 0;  // probes played
    double wall_seconds = 0.0;
    double cpu_seconds = 0.0;  // the process's, all threads
};

// `before`: the instrument's map at the attack (clean_up_to helps place the searches).
DressResult dress_frets(const Instrument& instrument, const std::vector<NoteVerdict>& before, const DressRequest& request);

// dress.csv: fret, remove_mm, remove_thou (thousandths of an inch), every fret.
std::string dress_csv(const DressResult& dress);
std::string dress_json(const DressResult& dress);
std::string dress_text(const DressResult& dress);

}  // namespace fretbuzz
