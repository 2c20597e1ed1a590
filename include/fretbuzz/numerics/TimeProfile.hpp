#pragma once
// A quantity given at points in time (t, value), linear in between and held before the
// first and after the last point; empty: zero. Pressing forces and force gestures use it.
#include <array>
#include <cstddef>
#include <vector>

namespace fretbuzz {

class TimeProfile {
public:
    explicit TimeProfile(std::vector<std::array<double, 2>> points);
    double at(double t) const;
    // The earliest time from which it stays zero: -inf if it is zero throughout, +inf if it
    // ends on a non-zero value.
    double zero_from() const;

private:
    std::vector<std::array<double, 2>> points_;
};

// The grid points (x_i = (i + 1) dx, i < points) within width/2 of centre, or the nearest
// one when none is: where a finger or a gesture acts.
std::vector<std::size_t> pad_points(double centre, double width, double dx, std::size_t points);
// The same into `pad` (cleared first: no allocation within its capacity).
void pad_points(double centre, double width, double dx, std::size_t points, std::vector<std::size_t>& pad);

}  // namespace fretbuzz
