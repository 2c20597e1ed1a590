#pragma once
// A stopped note as a Case of its own: the part of a string that sounds when a finger holds
// it down on a fret at x_stop and it rings between there and the bridge at L. The same
// tension, density and obstacle (sampled on the shorter string's grid, relative to the string
// at rest, which now runs from the stop to the bridge), the same physics, on the sine modes
// of the piece from x_stop to L (the contact grid needs them). With x_stop = 0 it is the open
// string with at most `modes` modes.
//
// The modes' frequencies and dampings are those of the held string (scheme/HeldString.hpp):
// the open string's own modal model with u(x_stop) = 0 imposed and the string going on over
// the fret to the nut, its near side damped by the finger. A stiff string held over a fret is
// half clamped there: its stopped notes sound 1.8-4 cents above the pinned piece's pitch at
// frets 1-15 of the bass (docs/validation.md, section 7). The pinned piece itself would be the open
// string's dispersion at the shorter wavenumbers (StringDispersion): nu_n = n c / (2 L')
// sqrt(1 + B' n^2) with B' = B (L / L')^2. A measured table of the second polarisation is
// held the same way, mode for mode.
//
// It stands in for a finger modelled inside the scheme (a lumped mass in contact with the
// string): a fretted note is a different plan prepared once at set-up, not a finger that
// lands on a sounding string. Building one costs the held string's modes
// (bench/bench_stopped_string.cpp; docs/performance.md).
#include <cstddef>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/geometry/FretPositions.hpp"  // fret_position, for the stops

namespace fretbuzz {

// Where the finger goes: at x = 0 (the nut of a fretted neck), unless the obstacle lies near
// x = 0 (a sitar's or tanpura's bridge: its centroid within L/4), then at x = L, so the
// bridge keeps sounding. x_stop is measured from that end.
bool stops_at_far_end(const Case& c);
// InputError if x_stop is not in [0, 3L/4] (fret 24) or modes is 0. No initial motion unless x_stop = 0
// (then the open case's, truncated). Observation points before the stop are dropped.
Case stopped_string(const Case& open, double stop_m, std::size_t modes);


}  // namespace fretbuzz
