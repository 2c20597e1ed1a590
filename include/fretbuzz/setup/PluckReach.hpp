#pragma once
// How close a plucked note comes to the frets past its stop, from the geometry alone.
// The note's string (from the stopping fret's top to the saddle, length L) let go from a
// triangle of height h at the pluck point swings as an ideal string does: by d'Alembert, at
// half a period its shape is the first one turned end for end, so its largest excursion at a
// distance s from the stop is h max(phi(s), phi(L - s)), phi the triangle of height 1. The
// note's reach margin is the height h at which that excursion first meets a fret:
//   margin(k) = min over the frets n past k of clearance(k, n) / max(phi(s_n), phi(L - s_n)).
// A change of geometry that multiplies a note's margin by r multiplies the attack it stands
// by about r (a linear string scaled with its clearances is the same motion scaled, and the
// listener hears levels relative to the clean note), so a note clean up to c times the attack
// is predicted clean up to about c r after the change. The advice and the fret dress place
// their searches with this prediction; every answer they give is played.
#include <cstddef>

#include "fretbuzz/setup/StringNeck.hpp"

namespace fretbuzz {

// The reach margin of the note stopped at fret k (0: open), plucked pluck_from_bridge_m from
// the bridge (m; <= 0 when it rests on a fret; +infinity when no fret lies past k).
double reach_margin(const StringNeck& neck, std::size_t k, double pluck_from_bridge_m);

// A note's clean_up_to after a change of geometry (neck `before` to `after`), predicted from
// its clean_up_to before (infinity: at least `cap`); 0 when it would rest on a fret.
double predicted_clean_up_to(double clean_up_to, double cap, const StringNeck& before, const StringNeck& after,
                             std::size_t k, double pluck_from_bridge_m);

}  // namespace fretbuzz
