#include "fretbuzz/setup/InstrumentGeometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fretbuzz/geometry/FretPositions.hpp"
#include "fretbuzz/model/TautString.hpp"
#include "fretbuzz/setup/StringNeck.hpp"
#include "fretbuzz/setup/WhatIf.hpp"

namespace fretbuzz {

std::vector<StringGeometry> describe_geometry(const Instrument& instrument) {
    const std::size_t count = instrument.strings.size();
    const NeckDescription& neck = instrument.neck;
    std::vector<StringGeometry> out;
    // A fanned neck: every string's perpendicular fret lies on one line square to the neck.
    std::vector<double> square(count, 0.0);
    const std::size_t p = neck.perpendicular_fret.value_or(0);
    for (std::size_t s = 0; s < count; ++s) square[s] = fret_position(instrument.strings[s].scale_length_m, p);
    const double farthest = *std::max_element(square.begin(), square.end());
    for (std::size_t s = 0; s < count; ++s) {
        const InstrumentString& str = instrument.strings[s];
        const StringNeck n(instrument, s);
        StringGeometry g;
        g.name = str.name;
        g.scale_length_m = str.scale_length_m;
        g.frequency_hz = str.frequency_hz;
        g.tension_n = str.tension_n;
        g.linear_density = str.linear_density;
        g.bending_stiffness = str.bending_stiffness;
        g.inharmonicity = TautString{str.scale_length_m, str.tension_n, str.linear_density}.inharmonicity_for(
            str.bending_stiffness);
        g.gauge_m = str.gauge_m;
        g.tension_source = str.tension_source;
        g.nut_height_m = n.nut_height();
        g.saddle_height_m = n.saddle_height();
        g.nut_gap_m = n.gap(1);
        g.action12_m = n.fret_count() >= 12 ? n.gap(12) : std::numeric_limits<double>::quiet_NaN();
        g.relief_fret = n.fret_count() >= 3 ? relief_fret(instrument) : 0;
        g.relief_gap_m = g.relief_fret ? n.relief_gap(g.relief_fret) : 0.0;
        g.nut_axial_m = farthest - square[s];
        const double place = count > 1 ? static_cast<double>(s) / static_cast<double>(count - 1) - 0.5 : 0.0;
        g.lateral_nut_m = place * neck.nut_width_m;
        g.lateral_bridge_m = place * neck.bridge_spacing_m;
        for (std::size_t k = 0; k <= n.fret_count(); ++k) {
            g.fret_x_m.push_back(n.fret_x(k));
            g.fret_top_m.push_back(n.fret_top(k));
            g.fret_line_m.push_back(n.fret_line(k));
            g.gap_m.push_back(k == 0 ? std::numeric_limits<double>::quiet_NaN() : n.gap(k));
        }
        // The surface every 2 mm and at each fret, up to the bridge (a body, or nothing).
        std::vector<double> xs = g.fret_x_m;
        for (double x = 0.0; x < n.length(); x += 2e-3) xs.push_back(x);
        xs.push_back(n.board_end());
        std::sort(xs.begin(), xs.end());
        for (double x : xs) {
            const double z = n.surface(x);
            if (!std::isfinite(z)) continue;
            g.surface_x_m.push_back(x);
            g.surface_z_m.push_back(z);
        }
        out.push_back(std::move(g));
    }
    return out;
}

}  // namespace fretbuzz
