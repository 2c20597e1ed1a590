#pragma once
// The neck under one string, in the string's own frame: x from its nut along the string,
// z up from the fret plane (the straight line through the nut end of the fret line and the
// last fret; relief is measured down from it, as in the case files' fretboard).
//  - Frets at equal-tempered positions x_n = L (1 - 2^(-n/12)) on the string's scale L (a
//    measured profile: where its frets are).
//  - The fret line: the relief (a bow fitted to the luthier's gap, or a measured curve), a
//    truss-rod bow added by what-ifs, the bow of a pull other than the one the relief was
//    measured under (a retuning, another set: geometry/NeckBeam.hpp), and the fretboard
//    radius as this string sees it (the strings fan out over a cylinder, or a cone for a
//    compound radius: the outer ones see a crowned fret line). Each fret's top is the fret
//    line plus its own offset (proud or low); a scan gives the tops directly.
//  - The board one fret height below the fret line, straight from fret to fret, flat past
//    the last fret up to the board's end; past it the body, parallel to the fret plane.
//  - The open string: the straight line from the nut to the saddle, placed by the gap over
//    fret 1 and the action over fret 12 (or the heights of its ends).
// From this come what a luthier measures (the gap over each fret, the relief) and the
// obstacle of every stopped note (the string from fret k's top to the saddle, over the frets
// beyond): the geometry is computed here and nowhere else.
#include <cstddef>
#include <optional>
#include <vector>

#include "fretbuzz/Case.hpp"
#include "fretbuzz/geometry/ObstacleProfile.hpp"
#include "fretbuzz/input/Instrument.hpp"

namespace fretbuzz {

class StringNeck {
public:
    // InputError (naming the string's keys) if the open string would touch a fret or the board.
    StringNeck(const Instrument& instrument, std::size_t string);

    const std::string& name() const { return name_; }
    std::size_t fret_count() const { return top_.size() - 1; }
    double length() const { return length_; }
    double fret_x(std::size_t n) const { return x_[n]; }       // n = 0 (the nut) .. N
    double fret_top(std::size_t n) const { return top_[n]; }   // n = 1 .. N; n = 0: the fret line at the nut
    double fret_line(std::size_t n) const { return line_[n]; }  // without the fret's own offset
    double fret_height() const { return fret_height_; }
    double board_end() const { return board_end_; }
    // The surface under the string at x (z): the board, or the body past the board's end
    // (-infinity where there is none).
    double surface(double x) const;
    // The open string at rest.
    double string_height(double x) const { return nut_height_ + (saddle_height_ - nut_height_) * x / length_; }
    double nut_height() const { return nut_height_; }
    double saddle_height() const { return saddle_height_; }
    // Gap between the open string and fret n's top (the action at fret n), n = 1 .. N.
    double gap(std::size_t n) const { return string_height(x_[n]) - top_[n]; }
    // The relief as a luthier measures it: the string pressed at fret 1 and the last fret, the
    // gap over fret m.
    double relief_gap(std::size_t m) const;
    // The note stopped at fret k (0: the open string) at rest: from fret k's top to the saddle.
    double rest_height(std::size_t k, double x) const;
    // How far fret n's top lies below the string stopped at fret k (n > k); <= 0: the string rests on it.
    double clearance(std::size_t k, std::size_t n) const { return rest_height(k, x_[n]) - top_[n]; }
    // What the note stopped at fret k rests on before it is even played (it frets out): the
    // first fret past k whose top reaches its string at rest, or 0 for the board or body
    // (checked every 0.5 mm); nothing when it lies clear.
    std::optional<std::size_t> rests_on(std::size_t k) const;
    // The obstacle of the note stopped at fret k, relative to the note's string at rest, on
    // its grid (points s = (i + 1) dx from fret k, the sounding length L - x_k): the surface
    // below on the grid points, and each fret beyond k at its exact position s = x_n - x_k,
    // acting over one grid step of string (as a case file's crown of zero width).
    std::vector<double> note_board(std::size_t k, const Grid& grid) const;
    std::vector<PointObstacle> note_frets(std::size_t k, const Grid& grid) const;
    // Both on the grid, each fret on its nearest grid point (as Case::obstacle_on_grid draws them).
    std::vector<double> note_obstacle(std::size_t k, const Grid& grid) const;
    bool measured_profile() const { return measured_; }
    std::optional<double> body_height() const { return body_; }

private:
    std::string name_;
    double length_ = 0.0;
    double fret_height_ = 0.0;
    std::vector<double> x_, line_, top_;           // 0 .. N
    std::vector<double> board_x_, board_z_;        // the board surface, point by point
    double board_end_ = 0.0;
    std::optional<double> body_;                   // the body's height past the board (none: nothing)
    double nut_height_ = 0.0, saddle_height_ = 0.0;
    bool measured_ = false;
};

// The relief gap a bow of depth 1 m adds under a string (see StringNeck::relief_gap): the
// what-ifs of the truss rod solve for the bow that gives a wanted gap with it.
double relief_gap_per_bow(const StringNeck& neck, std::size_t at_fret);

// The strings' total pull on the neck (N), and the bow (m, at mid-span of `span_m`, + down)
// the neck takes beyond its measured relief because they pull more than when the relief was
// measured (NeckBeam.hpp; 0 when the instrument says nothing of that pull).
double strings_pull(const Instrument& instrument);
double pull_bow(const Instrument& instrument, double span_m);

}  // namespace fretbuzz
