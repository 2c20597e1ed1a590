#include "fretbuzz/geometry/FretPositions.hpp"

#include <cmath>

namespace fretbuzz {

namespace {
double equal_tempered(double scale_length_m, double fret) { return scale_length_m * (1.0 - std::exp2(-fret / 12.0)); }
}  // namespace

double fret_position(double scale_length_m, std::size_t fret) {
    return equal_tempered(scale_length_m, static_cast<double>(fret));
}

double fret_position(double scale_length_m, int fret) { return equal_tempered(scale_length_m, fret); }

}  // namespace fretbuzz
