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
// the fret to the nut, a finger behind the fret (the `fret = k` finger at rest, linearised:
// its pad tied to its mass by the pad's springs and Hunt-Crossley dampers) pressing the string
// onto the fret before too. A stiff string held so is partly clamped over the fret: on the
// Jazz Bass E string its stopped notes sound 16 to 23 cents above the pinned piece's pitch,
// and the finger's loss damps partials 6 to 10 at frets 5 to 15 by 2 to 60 1/s on top of
// the string's own (docs/validation.md, section 7). The pinned piece itself would be the open
// string's dispersion at the shorter wavenumbers (StringDispersion): nu_n = n c / (2 L')
// sqrt(1 + B' n^2) with B' = B (L / L')^2. A measured table of the second polarisation is
// held the same way, mode for mode.
//
// It stands in for a finger modelled inside the scheme (a lumped mass in contact with the
// string): a fretted note is a different plan prepared once at set-up, not a finger that
// lands on a sounding string. Building one costs the held string's modes and the finger's
// partials (bench/bench_stopped_string.cpp; docs/performance.md).
#include <cstddef>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/geometry/FretPositions.hpp"  // fret_position, for the stops
#include "fretbuzz/scheme/HeldString.hpp"

namespace fretbuzz {

// Where the finger goes: at x = 0 (the nut of a fretted neck), unless the obstacle lies near
// x = 0 (a sitar's or tanpura's bridge: its centroid within L/4), then at x = L, so the
// bridge keeps sounding. x_stop is measured from that end.
bool stops_at_far_end(const Case& c);
// The finger that stops the string at x_stop (measured as x_stop is, from the end the
// finger is on): where the open case has a fret there (fret k), `fret = k`'s finger
// (finger_behind_fret) pressing with kFretFingerForce, the string on fret k - 1 too (k >= 2);
// elsewhere the same finger behind the stop, the spacing that of equal temperament, and the
// string on the fret a semitone lower only on a string with no obstacle at all (the set-up
// bench's strings, fretted in equal temperament: StringNeck), not on a fretless neck.
HeldString::Finger stopping_finger(const Case& open, double stop_m);
// InputError if x_stop is not in [0, 3L/4] (fret 24) or modes is 0, or the finger does not fit
// behind the stop (HeldString::sounding_partials). No initial motion unless x_stop = 0 (then
// the open case's, truncated). Observation points before the stop are dropped.
Case stopped_string(const Case& open, double stop_m, std::size_t modes, const HeldString::Finger& finger);
// With stopping_finger(open, stop_m).
Case stopped_string(const Case& open, double stop_m, std::size_t modes);
// Where fret k (k >= 1) stops the open string: the case's own fret k where it has one (its
// exact position, as its file placed it), past its last fret or on a case without frets the
// equal-tempered position on the string's length.
double fret_stop_m(const Case& open, int fret);


}  // namespace fretbuzz
