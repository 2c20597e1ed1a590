#pragma once
// Advice: searches the bench runs for the luthier, each probe a map played with a what-if.
//  - The lowest action per string: the gap over fret 12, on a 0.05 mm grid, at which every
//    note of the string is clean at the chosen attack; found by bisection between a clean action and a buzzing one (or one
//    that would put the open string on a fret), so that the answer is clean and the step
//    below it is not.
//  - The proud frets: a fret the buzzing notes buzz against, whose lowering by at most
//    0.1 mm (0.02 mm steps) removes their buzz without making any note buzz more (the notes
//    stopped on it are played too: lowering a fret that is merely in line with its
//    neighbours moves the buzz onto its own note, the next fret now standing higher).
//  - The relief range: the truss-rod settings (the luthier's relief gap, 0.05 mm grid, the
//    strings' nut and saddle left where they are) over which the whole map is clean.
// "Clean" here is the map's verdict: "clean" for every note of the strings searched (a marginal
// note, whose plucks cannot show it clean, is not).
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"

namespace fretbuzz {

inline constexpr double kActionStep = 0.05e-3;  // m: what a saddle screw's quarter turn moves, about
inline constexpr double kReliefStep = 0.05e-3;

struct AdviceRequest {
    Attack attack;
    bool finger = false;
    unsigned jobs = 0;
    std::vector<std::size_t> strings;  // empty: all
};

struct ActionAdvice {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::string string;
    double current_m = nan;       // the gap over fret 12 now
    double lowest_clean_m = nan;  // NaN: no clean action up to 10 mm
    // The step below: it buzzes (a note and how many of its plucks) or cannot be set (the
    // open string would lie on a fret).
    std::string below;
};

struct ProudFret {
    std::size_t fret = 0;
    double lower_by_m = 0.0;
    std::vector<std::string> cleared;  // the notes whose buzz it removes ("E 7")
    std::vector<std::string> worse;    // notes that buzz more after it ("E 8"): none for a proud fret
};

struct ReliefAdvice {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::size_t fret = 0;   // where the relief gap is measured
    double current_m = nan;
    double lowest_m = nan, highest_m = nan;  // the clean range (NaN: none found)
    double searched_from_m = 0.0, searched_to_m = 0.0;
};

struct Advice {
    Attack attack;
    std::vector<ActionAdvice> actions;
    std::vector<ProudFret> proud;
    ReliefAdvice relief;
    std::size_t maps = 0;  // maps played for it
    double wall_seconds = 0.0;
};

// Whether every note of `strings` (all if empty) is clean at the attack; on the first note
// that is not, its description ("E fret 7: 2/5 plucks") in `why`.
bool map_is_clean(const Instrument& instrument, const AdviceRequest& request, std::vector<std::size_t> strings,
                  std::string* why = nullptr);

ActionAdvice lowest_clean_action(const Instrument& instrument, std::size_t string, const AdviceRequest& request,
                                 std::size_t* maps = nullptr);
std::vector<ProudFret> proud_frets(const Instrument& instrument, const std::vector<NoteVerdict>& map,
                                   const AdviceRequest& request, std::size_t* maps = nullptr);
ReliefAdvice clean_relief_range(const Instrument& instrument, const AdviceRequest& request, std::size_t* maps = nullptr);

// All three; `map` is the instrument's map at (at least) the advice's attack.
Advice advise(const Instrument& instrument, const std::vector<NoteVerdict>& map, const AdviceRequest& request);
std::string advice_json(const Advice& advice);
std::string advice_text(const Advice& advice);

}  // namespace fretbuzz
