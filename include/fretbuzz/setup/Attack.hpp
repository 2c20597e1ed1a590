#pragma once
// How a note is played on the bench, and the small ensemble of plucks its verdict comes
// from. One pluck's outcome is chaotic (where and how hard the string first meets a fret
// decides the rest), so each note is played several times around the chosen attack: the
// pluck point jittered within +- position_spread and the strength within 1 +- strength_spread,
// by a deterministic generator (the same instrument and seed give the same plucks on every
// machine). Member 0 is the attack itself.
//  - finger plucks (soft, medium, hard, or an amplitude): the string released from rest,
//    displaced away from the board by the amplitude at the pluck point, a rounded triangle
//    the width of the fingertip (Issanchou et al. 2017's pluck); it swings as far toward the
//    frets half a period later;
//  - pop: the same, pulled further (the player's finger hooked under the string);
//  - slap: the thumb throws the string toward the board, a raised-cosine velocity the width
//    of the thumb over the end of the fingerboard.
#include <cstddef>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"

namespace fretbuzz {

enum class AttackKind { pluck, slap };

struct Attack {
    std::string label;            // "soft", "medium", "hard", "pop", "slap", "1.2 mm"
    AttackKind kind = AttackKind::pluck;
    double amplitude_m = 0.0;     // pluck: displacement at the pluck point
    double velocity = 0.0;        // slap: peak velocity toward the board, m/s
    double from_bridge_m = 0.0;   // where, from the bridge
    double width_m = 0.0;         // fingertip or thumb
    // Attacks of one shape (kind, place, width) differ only in size: the string's motion
    // without the frets scales with it, so one obstacle-free reference serves them all.
    bool same_shape(const Attack& other) const;
};

// The attacks named by a list such as "soft,medium,hard", "pop", "slap" or "1.2mm" (a finger
// pluck of that amplitude, in mm unless a unit is given). InputError naming `option` and
// what is allowed.
std::vector<Attack> parse_attacks(const std::string& list, const AttackSettings& settings,
                                  const std::string& option = "--strength");

// One member of a note's ensemble: the pluck point moved by `shift_m` (toward the bridge if
// negative) and the attack scaled by `scale`.
struct PluckVariation {
    double shift_m = 0.0;
    double scale = 1.0;
};

// The members of the ensemble of note (string, fret): the same for every attack (member m of
// "hard" is member m of "soft", harder), so that attacks of one shape share their
// obstacle-free references. Deterministic in (settings.seed, string, fret).
std::vector<PluckVariation> ensemble(const AttackSettings& settings, std::size_t string, std::size_t fret);

}  // namespace fretbuzz
