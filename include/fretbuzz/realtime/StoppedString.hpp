#pragma once
// The part of a string that sounds when it is stopped at x_stop (a finger pressing it onto
// a fret) and rung between there and the bridge at L: a Case of its own, with the same
// tension, density and obstacle (sampled on the shorter string's grid, relative to the string
// at rest, which now runs from the stop to the bridge), and the same physics. With x_stop = 0
// it is the open string with at most `modes` modes.
//
// It stands in for a finger modelled inside the scheme (a lumped mass in contact with the
// string): a fretted note is a different plan prepared once at set-up, not a finger that
// lands on a sounding string. Mode frequencies scale with the length as for a flexible
// string (nu_j L constant); the dampings are kept.
#include <cstddef>

#include "fretbuzz/Case.hpp"

namespace fretbuzz {

// x_k = L (1 - 2^(-k/12)): equal-tempered fret k of a string of length L (k = 0: the nut).
double fret_position(double length_m, int fret);

// Where the finger goes: at x = 0 (the nut of a fretted neck), unless the obstacle lies near
// x = 0 (a sitar's or tanpura's bridge: its centroid within L/4), then at x = L, so the
// bridge keeps sounding. x_stop is measured from that end.
bool stops_at_far_end(const Case& c);
// InputError if x_stop is not in [0, 3L/4] (fret 24) or modes is 0. No initial motion unless x_stop = 0
// (then the open case's, truncated). Observation points before the stop are dropped.
Case stopped_string(const Case& open, double stop_m, std::size_t modes);

}  // namespace fretbuzz
