#pragma once
// How one step of a string's contacts is taken: which solve each kind of contact goes through,
// how the step's pushes reach the modes and what the pass forecasts. ContactSet decides it once
// per step, in its solve (the solve's part from the state at the top, the pushes' part when the
// solve's forces are known, at its end); the phases after it (the pass, the screening) read it
// instead of each deriving it again from the contacts' flags.
#include <cstddef>
#include <cstdint>

namespace fretbuzz {

class ExactPluckers;
class ExactPoints;
class GridContact;
class Plan;
class PlayedParts;

struct StepRoute {
    // The unknowns off the grid: the exact points and the exact pluckers.
    enum class OffGrid : std::uint8_t {
        none,           // nothing awake or acting off the grid
        plucker_alone,  // one plucker with nothing beside it: its own scalar solve
        apart,          // the awake points and acting pluckers together, apart from the grid
        with_grid,      // with the grid's active points (and the fingers' pads): PointContact's joint solve
    };
    // The grid's active obstacle points and the fingers' pads.
    enum class OnGrid : std::uint8_t {
        none,        // nothing to solve on the grid
        each,        // each active point its own scalar solve
        batch,       // their equations together (PenaltyContact::solve_all: the same solutions)
        with_points, // in the joint solve (OffGrid::with_grid)
    };
    // How the step's forces reach the modes in the pass.
    enum class Push : std::uint8_t {
        none,        // no force, no load
        rows,        // the grid's forces as rows added by the pass
        point_rows,  // the exact points' rows, then the grid's
        vector,         // one modal impulse vector formed before the pass (many forces)
        loaded_vector,  // the same with the gestures' and pluckers' loads of the step
    };

    OffGrid off_grid = OffGrid::none;
    OnGrid on_grid = OnGrid::none;
    bool by_transform = false;     // the grid's predictions by one transform (else by rows)
    bool fingers_joint = false;    // the fingers' pads in the joint solve (else each finger its own)
    Push push = Push::none;
    bool forecast_points = false;  // the pass forms the awake exact points' next predictions (first)
    bool forecast_grid = false;    // and those at the grid's active points and pads (after them)

    // The solve's part, from the state at the top of the step (pluckers: some act); the rest none.
    static StepRoute of_solve(const Plan& plan, const GridContact& grid, const ExactPoints& points,
                              const ExactPluckers& pluckers, const PlayedParts& parts, bool pluckers_act);
    // The pushes' part and the forecasts, from the solve's `forces` (and whether the step is loaded).
    void choose_pushes(const Plan& plan, const GridContact& grid, const ExactPoints& points, const PlayedParts& parts,
                       std::size_t forces, bool loaded);
};

}  // namespace fretbuzz
