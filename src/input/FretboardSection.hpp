#pragma once
// [obstacle] with type = "fretboard": a fretted neck from its measurements.
#include <vector>

#include "TomlSection.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

std::vector<double> read_fretboard(TomlSection& section, const Grid& grid);

}  // namespace fretbuzz
