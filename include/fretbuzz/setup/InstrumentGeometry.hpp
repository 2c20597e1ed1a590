#pragma once
// The instrument's geometry as a luthier reads it and as a side view draws it: for each
// string its frets (positions, tops, the fret line), the board and body under it, the open
// string from nut to saddle, the gaps over every fret, the relief, and where it lies on the
// neck (its nut along the neck axis for a fanned multiscale neck, its distance from the
// neck's centre line at the nut and at the bridge). Heights in the string's frame (z up
// from the fret plane, see StringNeck).
#include <cstddef>
#include <string>
#include <vector>

#include "fretbuzz/input/Instrument.hpp"

namespace fretbuzz {

struct StringGeometry {
    std::string name;
    double scale_length_m = 0.0, frequency_hz = 0.0, tension_n = 0.0, linear_density = 0.0;
    double bending_stiffness = 0.0, inharmonicity = 0.0, gauge_m = 0.0;
    std::string tension_source;
    double nut_height_m = 0.0, saddle_height_m = 0.0;  // the open string's ends above the fret plane
    double nut_gap_m = 0.0;        // over fret 1
    double action12_m = 0.0;       // over fret 12 (NaN with fewer frets)
    double relief_gap_m = 0.0;     // under this string, at relief_fret
    std::size_t relief_fret = 0;
    double nut_axial_m = 0.0;      // the nut's place along the neck axis (0 for the string whose nut is nearest the head)
    double lateral_nut_m = 0.0, lateral_bridge_m = 0.0;  // off the neck's centre line
    std::vector<double> fret_x_m, fret_top_m, fret_line_m, gap_m;  // frets 0 (the nut end) .. N; gap_m[0] NaN
    std::vector<double> surface_x_m, surface_z_m;  // the board (and body) under the string, for drawing
};

std::vector<StringGeometry> describe_geometry(const Instrument& instrument);

}  // namespace fretbuzz
