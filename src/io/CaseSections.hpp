#pragma once
// Readers of the individual tables of a case file, one file each (src/io/*Section.cpp).
#include <cstddef>
#include <vector>

#include "TomlSection.hpp"
#include "fretbuzz/Case.hpp"
#include "fretbuzz/io/CaseFile.hpp"

namespace fretbuzz {

// [modes]: fills c.modes for c.string and the requested mode count.
void read_modes_section(TomlSection& section, const DataSource& data, std::size_t mode_count, Case& c);
// [obstacle]: heights on the grid of c.
void read_obstacle_section(TomlSection& section, const DataSource& data, Case& c);
// [excitation]: initial modal displacement and velocity on the modes of c.
void read_excitation_section(TomlSection& section, const DataSource& data, Case& c);

}  // namespace fretbuzz
