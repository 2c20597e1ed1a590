#pragma once
// Readers of the individual tables of a case file, one file each (src/input/*Section.cpp).
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "TomlSection.hpp"
#include "fretbuzz/Case.hpp"
#include "fretbuzz/input/CaseFile.hpp"
#include "fretbuzz/input/CsvTable.hpp"

namespace fretbuzz {

// The most modes a case may ask for ([string] modes, a mode table's rows).
inline constexpr std::size_t kMaxModes = 100000;

// What [string] says beyond c.string: the mode count and the optional properties the
// frequency and damping models use.
struct StringDescription {
    std::size_t mode_count = 0;
    std::optional<double> diameter_m;              // d (outer)
    std::optional<double> core_diameter_m;         // d_core
    std::optional<double> core_bending_stiffness;  // E_core I_core, N m^2 (given, or E_core pi d_core^4 / 64)
    std::optional<double> inharmonicity;           // B
    bool ideal = false;                            // ideal = true: no stiffness, nu_j = j c / (2L)
};

// Which side of the string an obstacle lies on (obstacle.side).
enum class ObstacleSide { below, above };
std::string to_string(ObstacleSide side);

// [string]: fills c.string.
StringDescription read_string_section(TomlSection& section, Case& c);
// [modes]: fills c.modes for c.string and the requested mode count. lossless: run.lossless
// is set (a missing damping model is then no error).
void read_modes_section(TomlSection& section, const DataSource& data, const StringDescription& string,
                        bool lossless, Case& c);
// obstacle.side: "below" (the default) or "above".
ObstacleSide read_obstacle_side(TomlSection& section);
// Whether an [obstacle] is of type "points", and its points at their exact positions.
bool is_point_section(TomlSection& section);
std::vector<PointObstacle> read_point_section(TomlSection& section, const Case& c);
// [obstacle] (or one entry of [[obstacle]]): heights on the grid of c.
// points: where the obstacle has parts at exact positions (a fretboard's crowns of zero width);
// frets: a fretboard's fret positions, known exactly whatever its crowns' width.
std::vector<double> read_obstacle_section(TomlSection& section, const DataSource& data, const Case& c,
                                          std::vector<PointObstacle>& points, std::vector<double>& frets);
// [excitation]: initial modal displacement and velocity on the modes of c.
void read_excitation_section(TomlSection& section, const DataSource& data, Case& c);

// `fret = k` and [[finger]] (after [run]: their times are checked against the run).
void read_fingers(TomlSection& top, Case& c);
// [[gesture]] (after [run], like the fingers).
void read_gestures(TomlSection& top, Case& c);

// Keys of the second polarisation (PolarisationSection.cpp): string.polarisations,
// [polarisation_y], excitation.angle, contact.friction(_velocity), audio.pickup_angle.
void read_polarisation_count(TomlSection& string_section, Case& c);
void read_polarisation_y_section(TomlSection& section, const DataSource& data, Case& c);
void read_excitation_angle(TomlSection& excitation, Case& c);
void read_friction(TomlSection& contact, Case& c);
void read_pickup_angle(TomlSection& audio, Case& c);

// The CSV file named by section.key; any error in it names the key.
CsvTable read_section_table(TomlSection& section, std::string_view key, const DataSource& data,
                            std::size_t min_columns);

}  // namespace fretbuzz
