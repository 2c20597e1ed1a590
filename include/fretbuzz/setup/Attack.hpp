#pragma once
// How a note is played on the bench (a gesture of a size), and the ensemble of plucks its
// verdict comes from. One pluck's outcome is chaotic (where and how hard the string first
// meets a fret decides the rest), so each note is played several times around the chosen
// attack: the place jittered within +- position_spread, the direction within +- angle_spread
// and the size within 1 +- strength_spread, by a deterministic generator (the same instrument
// and seed give the same plucks on every machine). Member 0 is the attack itself.
// The gestures (cases/attacks/STYLE.toml gives their defaults and sources):
//  - finger plucks (soft, medium, hard, or an amplitude) and a pick stroke: the string pulled
//    from rest and released, displaced by the amplitude along the gesture's direction (mostly
//    along the board, a little toward it), a rounded triangle the width of the fingertip or
//    the plectrum's edge; it swings in both polarisations;
//  - pop: the same, pulled straight away from the board (a finger hooked under the string);
//  - slap: the thumb, a lumped mass with a pad (the finger model), strikes the string toward
//    the board at a speed, over the end of the fingerboard, and bounces off.
#include <cstddef>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"

namespace fretbuzz {

enum class Gesture { finger, pick, pop, slap };

struct Attack {
    std::string label;             // "soft", "medium", "hard", "pick", "pop", "slap", "1.2 mm"
    Gesture gesture = Gesture::finger;
    double size = 0.0;             // plucks: displacement at release (m); slap: the thumb's speed (m/s)
    GestureSettings where;         // place, width, direction
    bool strike() const { return gesture == Gesture::slap; }
    // The size in the unit players read ("mm" or "m/s"), and that unit.
    double shown_size() const { return strike() ? size : size * 1e3; }
    const char* unit() const { return strike() ? "m/s" : "mm"; }
};

const char* gesture_name(Gesture gesture);

// The attacks named by a list such as "soft,medium,hard", "pop", "slap", "pick", "1.2mm" (a
// finger pluck of that amplitude, in mm unless a unit is given) or "3m/s" (a slap of that
// speed). InputError naming `option` and what is allowed.
std::vector<Attack> parse_attacks(const std::string& list, const AttackSettings& settings,
                                  const std::string& option = "--strength");

// One member of a note's ensemble: the place moved by `shift_m` (toward the bridge if
// negative), the direction turned by `turn_deg` and the size scaled by `scale`.
struct PluckVariation {
    double shift_m = 0.0;
    double turn_deg = 0.0;
    double scale = 1.0;
};

// The first `count` members of the ensemble of note (string, fret): the same for every attack
// (member m of "hard" is member m of "soft", harder) and for every count (the first members
// of a larger ensemble are the smaller one). Deterministic in (settings.seed, string, fret).
std::vector<PluckVariation> ensemble(const AttackSettings& settings, std::size_t string, std::size_t fret,
                                     std::size_t count);

}  // namespace fretbuzz
