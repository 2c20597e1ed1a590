#pragma once
// Where the frets lie: x_n = L (1 - 2^(-n/12)) from the nut, equal-tempered on a string of
// scale length L (n = 0: the nut; n = 12: L / 2). Every fret position of the library comes
// from here: the case files' fretboard, instrument files, stopped notes and the set-up
// bench's necks (a fanned neck's strings each on their own L), so a compensated nut or
// another temperament changes in this one place.
#include <cstddef>

namespace fretbuzz {

double fret_position(double scale_length_m, std::size_t fret);
double fret_position(double scale_length_m, int fret);

}  // namespace fretbuzz
