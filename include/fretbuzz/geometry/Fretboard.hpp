#pragma once
// A fretted neck built from a luthier's measurements: frets at equal-tempered positions
// x_n = S (1 - 2^(-n/12)) from the nut (S = scale length), their tops on the "fret line"
// (a straight line between the action at the nut and the action at the last fret, bowed
// down by the neck relief), the fingerboard one fret height below the fret line, and
// past the end of the board the body (or nothing).
// Heights are those of the obstacle under the string at rest (negative, m). With the
// measurements of the Fender Jazz Bass of Issanchou et al. 2017 it reproduces the
// published neck profile (cases/data/bass_fretted_obstacle.csv).
#include <cstddef>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "fretbuzz/geometry/ObstacleProfile.hpp"

namespace fretbuzz {

// How far the fret line sags below the straight line from nut to last fret: either a
// parabolic bow of given depth at mid-span, or a measured curve (depth at points strictly
// between the nut and the last fret, zero at both, linear in between).
class NeckRelief {
public:
    static NeckRelief straight();
    static NeckRelief bow(double depth_m);
    static NeckRelief curve(std::vector<double> x_m, std::vector<double> depth_m);
    double depth_at(double x, double last_fret_m) const;

private:
    double bow_depth_m_ = 0.0;
    std::vector<double> x_m_;
    std::vector<double> depth_m_;
};

struct Fretboard {
    double scale_length_m = 0.0;
    std::size_t fret_count = 0;
    double fret_height_m = 0.0;       // fret top above the board
    double crown_width_m = 0.0;       // flat top; the nearest grid point is always on it
    double action_at_nut_m = 0.0;     // string to fret line, extrapolated to the nut
    double action_at_last_fret_m = 0.0;
    NeckRelief relief = NeckRelief::straight();
    double board_end_m = 0.0;         // the fingerboard covers (0, board_end]
    std::optional<double> body_height_m;  // past board_end; none: nothing to touch
    // Individual frets standing off the fret line (fret n -> m, + raises its top): a high
    // or worn fret, the set-up detail a luthier levels. The board below is unchanged.
    std::map<std::size_t, double> fret_height_offset_m;

    double fret_position(std::size_t n) const;  // n = 1..fret_count
    double fret_line_height(double x) const;    // height of a fret top at x
    double fret_top_height(std::size_t n) const;  // fret n's top: the fret line plus its offset
    // The board and its frets on the grid; a crown of zero width on its nearest grid point.
    std::vector<double> sample(const Grid& grid) const;
    // Crowns of zero width act at their exact x_n instead (sample_board leaves them out: the
    // grid point nearest one keeps the board's height): each as (x_n, top height).
    bool point_crowns() const { return crown_width_m == 0.0; }
    std::vector<double> sample_board(const Grid& grid) const;
    std::vector<std::pair<double, double>> crowns() const;

private:
    std::vector<double> sample(const Grid& grid, bool with_point_crowns) const;
};

}  // namespace fretbuzz
