#pragma once
// The forces a step's contacts put on the string, as forces per unit length at grid points:
// the grid's and the pads' as their solves found them, then (reported after the pass) those
// off the grid, the exact points' and the pluckers', each at its nearest grid point with the
// same total force; and where friction along y acts.
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "fretbuzz/scheme/ExactPluckers.hpp"
#include "fretbuzz/scheme/ExactPoints.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"

namespace fretbuzz {

class ContactForces {
public:
    using List = std::vector<std::pair<std::size_t, double>>;

    explicit ContactForces(const Plan& plan);

    // Points with a non-zero force in the last step and that force (N/m); the solves append theirs.
    const List& list() const { return forces_; }
    List& list() { return forces_; }
    // The forces off the grid added: the exact points' where they pushed, the pluckers'.
    void add_off_grid(const ExactPoints& points, const ExactPluckers& pluckers);
    // Where friction along y acts, with the normal force per unit length there.
    std::span<const std::pair<std::size_t, double>> rubbing(const PlayedParts& parts);

private:
    // A force (N) at x off the grid, reported as a force per length at the nearest grid point.
    void report_at(double x, double force);

    const Plan* plan_;
    List forces_;
    List rubbing_;  // scratch: where friction acts, F_n
};

}  // namespace fretbuzz
