#pragma once
// Advice: what the bench tells a luthier to do, each answer played on the bench.
//  - The lowest action per string: the gap over fret 12 (0.05 mm grid) at which every note
//    the advice answers for passes at the chosen attack, and the saddle move that sets it
//    from today (in the instrument file's units, mm beside). Found by bisection: the notes'
//    clean_up_to (how much harder than the attack each note stays clean) predicts where the
//    answer lies (PluckReach.hpp), the search starts there, gallops out until it holds a
//    passing action above a failing one, and halves the gap; the answer passes and the step
//    below does not (the note that fails there is named).
//  - Fall-away: where the upper frets set a string's action (the note that fails one step
//    below is stopped above fret 12), how far the frets up to fret 12 would let it go, and the
//    fall-away (the frets from one fret to the last dressed down along a straight line)
//    predicted to get there: a prediction, which `--dress --fall-away` works out by playing.
//  - Proud frets: a fret standing at least 0.02 mm above the line through its neighbours
//    (the board's own curvature stays far below that), against which a note fails, and
//    whose levelling makes some failing note pass and none that passed fail. A level board
//    has none, whatever strings are played.
//  - Relief: the truss-rod setting (the relief gap, 0 to 1 mm on a 0.05 mm grid, nut and
//    saddles where they are) with the fewest failing notes, as predicted from the notes'
//    clean_up_to, then played; the range predicted clean, if any.
// A note passes when its verdict is "clean" (or "marginal" when marginal notes are tolerated,
// as set-ups do unless told "--tolerate none"); the
// advice answers for the strings and frets asked (--strings, --frets), less the notes above
// a fret it is told to tolerate. The searches play only what they must (NoteTrials: a note
// that passed stays passing where every fret lies further from its string).
#include <cstddef>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"
#include "fretbuzz/setup/Attack.hpp"
#include "fretbuzz/setup/BuzzMap.hpp"

namespace fretbuzz {

inline constexpr double kActionStep = 0.05e-3;  // m: what a saddle screw's quarter turn moves, about
inline constexpr double kReliefStep = 0.05e-3;
inline constexpr double kProudHeight = 0.02e-3;  // m: a fret this far above its neighbours' line may be proud
inline constexpr std::size_t kUpperFrets = 12;   // notes stopped above this fret: the upper frets

// What the advice may let buzz.
struct AdviceTolerance {
    bool marginal = false;                  // a marginal note passes
    std::optional<std::size_t> above_fret;  // notes stopped above this fret are not asked to pass
    bool practice = false;                  // set by set-up practice, not asked for
    bool ignores(std::size_t fret) const { return above_fret && fret > *above_fret; }
    std::string text() const;  // "marginal notes, notes above fret 15"; "" for none
};

// What set-ups let buzz when the player says nothing: marginal notes, and on a bass (a scale
// of 30 in or more) the notes above fret 15, which bass lines seldom reach. A guitar's player
// may use every fret: only marginal notes.
inline constexpr double kBassScale = 0.762;         // m: 30 in, the short-scale bass
inline constexpr std::size_t kBassPlayedFrets = 15;
AdviceTolerance setup_practice_tolerance(const Instrument& instrument);

// "--tolerate marginal", "above=15", "marginal,above=15", "none" (every note must be clean).
// InputError naming the option and the accepted forms (a fret in [0, fret_count]).
AdviceTolerance parse_tolerance(const std::string& text, std::size_t fret_count, const std::string& option = "--tolerate");
// As a front end reads it: "" is set-up practice, anything else parse_tolerance.
AdviceTolerance tolerance_for(const Instrument& instrument, const std::string& text,
                              const std::string& option = "--tolerate");

// Moves beyond what a set-up does: the advice flags them (beyond_setup_text) and does not
// recommend them.
inline constexpr double kSetupSaddleMove = 1.0e-3;  // m: a saddle raised or lowered further
inline constexpr double kSetupReliefMax = 0.5e-3;   // m: relief past this (or a back bow)

struct AdviceRequest {
    Attack attack;
    bool finger = false;
    unsigned jobs = 0;
    std::vector<std::size_t> strings;  // empty: all
    std::vector<std::size_t> frets;    // the notes answered for (empty: every fret)
    AdviceTolerance tolerate;
    // Asked before each pluck of a probe: true ends the search with Interrupted (Ctrl-C in
    // Python, whose signal handler cannot reach the library's stop flag).
    std::function<bool()> stop;
    // Told of each note a probe plays (not of those recalled from an earlier probe), with the
    // probes so far: a search has no total to count down, so its progress is what it played.
    std::function<void(const NoteVerdict& note, std::size_t probes)> on_note;
};

// The notes of a string the advice answers for (its frets, less the tolerated ones).
std::vector<std::size_t> advice_frets(const Instrument& instrument, const AdviceRequest& request);

struct ActionAdvice {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::string string;
    double current_m = nan;         // the gap over fret 12 now
    double predicted_m = nan;       // where the notes' clean_up_to put the answer (NaN: no clean_up_to)
    double lowest_clean_m = nan;    // NaN: no passing action up to 10 mm
    double saddle_change_m = nan;   // the saddle's move from today to it (+ up)
    // The same two gaps at the fret the file measures the action at (12: the same as above).
    std::size_t measured_fret = 12;
    double current_at_measured_m = nan, lowest_clean_at_measured_m = nan;
    // The step below: it fails (a note and how many of its plucks) or cannot be set.
    std::string below;
    std::size_t limiting_fret = 0;  // the note that fails one step below (its fret), and
    int limiting_against = -1;      // the fret it buzzes against (-1: none; 0: the board)
    bool beyond_setup = false;      // the saddle would move more than kSetupSaddleMove
};

struct FallAwayAdvice {
    std::string string;
    std::size_t limiting_fret = 0;  // the upper note that sets the action now
    double action_now_m = 0.0;      // the lowest passing action, played
    double lower_frets_m = 0.0;     // what the notes up to fret 12 would allow (predicted)
    std::size_t from_fret = 0;      // the fall-away: frets past this one dressed down along a line
    double depth_m = 0.0;           // to this depth at the last fret (predicted)
};

struct ProudFret {
    std::size_t fret = 0;
    double lower_by_m = 0.0;           // levelling it with its neighbours
    std::vector<std::string> cleared;  // the notes that pass once it is levelled ("E 7")
    std::vector<std::string> worse;    // notes that fail after it: none for a proud fret
};

struct ReliefAdvice {
    static constexpr double nan = std::numeric_limits<double>::quiet_NaN();
    std::size_t fret = 0;  // where the relief gap is measured
    double current_m = nan;
    std::size_t failing_now = 0;  // notes failing at today's relief
    double best_m = nan;          // the relief with the fewest failing notes, played
    std::size_t failing_best = 0;
    bool played = false;          // best_m was played (not only predicted)
    double predicted_from_m = nan, predicted_to_m = nan;  // the range predicted clean (NaN: none)
    double searched_from_m = 0.0, searched_to_m = 0.0;
    bool beyond_setup = false;  // best_m lies outside [0, kSetupReliefMax]
};

// What the advice says of a move past a set-up's, in place of a recommendation ("" for one
// within it), the one wording of the text, the JSON and the pages. A saddle: "up, past the
// 1 mm a set-up moves: the neck or the playing needs more than a set-up", or "down, ...: the
// string has that much room to spare, more than a set-up takes". A relief: "past the 0.5 mm of
// relief a set-up gives: the neck or the playing needs more than a set-up".
std::string beyond_setup_text(const ActionAdvice& advice);
std::string beyond_setup_text(const ReliefAdvice& advice);

struct Advice {
    Attack attack;
    ShopUnits units = ShopUnits::mm;
    Adjusters adjusters;    // the file's: the moves said in turns too where it gives them
    std::string frets;      // "0-20"
    std::string tolerated;  // AdviceTolerance::text()
    std::vector<ActionAdvice> actions;
    std::vector<FallAwayAdvice> fall_away;
    std::vector<ProudFret> proud;
    ReliefAdvice relief;
    std::size_t maps = 0;  // probes played for it
    double wall_seconds = 0.0;
    double cpu_seconds = 0.0;  // the process's, all threads
};

// A move in turns of a screw that makes `per_turn` a turn (NaN where the file gives no pitch),
// and as a luthier reads it: "3/4 turn clockwise" to the nearest eighth ("" for NaN).
double screw_turns_for(double move_m, double per_turn_m);
std::string turns_text(double turns);

// Whether every note of `strings` (all if empty) the advice answers for passes at the
// attack; on the first that does not, its description ("E fret 7: buzzes, 2/10 plucks") in `why`.
bool map_is_clean(const Instrument& instrument, const AdviceRequest& request, std::vector<std::size_t> strings,
                  std::string* why = nullptr);

// Each search alone. `map`: the instrument's map at (at least) the advice's attack, with
// clean_up_to where it can be had (without it the searches start from today's setting).
ActionAdvice lowest_clean_action(const Instrument& instrument, std::size_t string, const AdviceRequest& request,
                                 const std::vector<NoteVerdict>& map = {}, std::size_t* maps = nullptr);
std::vector<ProudFret> proud_frets(const Instrument& instrument, const std::vector<NoteVerdict>& map,
                                   const AdviceRequest& request, std::size_t* maps = nullptr);
ReliefAdvice best_relief(const Instrument& instrument, const std::vector<NoteVerdict>& map, const AdviceRequest& request,
                         std::size_t* maps = nullptr);

// All of them.
Advice advise(const Instrument& instrument, const std::vector<NoteVerdict>& map, const AdviceRequest& request);
std::string advice_json(const Advice& advice);
std::string advice_text(const Advice& advice);

}  // namespace fretbuzz
