#include "fretbuzz/scheme/StepRoute.hpp"

#include "fretbuzz/numerics/Kernels.hpp"
#include "fretbuzz/scheme/ExactPluckers.hpp"
#include "fretbuzz/scheme/ExactPoints.hpp"
#include "fretbuzz/scheme/GridContact.hpp"
#include "fretbuzz/scheme/Plan.hpp"
#include "fretbuzz/scheme/PlayedParts.hpp"

namespace fretbuzz {

StepRoute StepRoute::of_solve(const Plan& plan, const GridContact& grid, const ExactPoints& points,
                              const ExactPluckers& pluckers, const PlayedParts& parts, bool pluckers_act) {
    StepRoute route;
    const bool grid_awake = !grid.active().empty();
    const std::size_t awake = points.awake(), acting = pluckers.acting();
    // The exact pluckers beside awake obstacle points of the grid or a finger: one solve with them.
    const bool pluck_with_grid = pluckers_act && (grid_awake || parts.fingers_on());
    // Exact points (or the exact pluckers) beside awake obstacle points of the grid or a finger's
    // pad: all in one solve (see PointContact).
    const bool coupled_points = plan.point_contact().grid_coupled() && awake != 0;
    const bool fingers_with_points = (coupled_points || pluck_with_grid) && parts.fingers_on();
    route.fingers_joint = fingers_with_points;
    const bool all_in_one = pluck_with_grid || (coupled_points && grid_awake) || fingers_with_points;
    // A single plucker with nothing beside it: its own scalar solve; several: solved together
    // (their pads move one another), with the exact points where any is awake.
    const bool pads_alone = awake == 0 && !pluck_with_grid;
    if (all_in_one)
        route.off_grid = OffGrid::with_grid;
    else if (pads_alone && acting == 1)
        route.off_grid = OffGrid::plucker_alone;
    else if (awake != 0 || (pads_alone && acting > 1))
        route.off_grid = OffGrid::apart;
    const std::size_t solved = grid.active().size() + parts.pad_points();
    if (solved == 0) return route;  // (on_grid: none)
    // The predicted height at every point to solve: by one transform where there are many, and
    // then their equations together (a string landing on a long obstacle: the same solutions).
    const bool many = solved > plan.transform_threshold();
    route.by_transform = many;
    if (all_in_one)
        route.on_grid = OnGrid::with_points;
    else if (many)
        route.on_grid = OnGrid::batch;
    else
        route.on_grid = OnGrid::each;
    return route;
}

void StepRoute::choose_pushes(const Plan& plan, const GridContact& grid, const ExactPoints& points,
                              const PlayedParts& parts, std::size_t forces, bool loaded) {
    // The pass pushes with the exact points' rows (and the grid's) where they fit in it; it
    // forms the next prediction at the awake points too where the step is fused.
    const std::size_t awake = points.awake();  // (resting points push nothing)
    const bool grid_rows = forces == 0 || plan.pushes_inline(forces);
    const bool by_rows = grid_rows && awake <= kernels::kMaxPassRows && forces + awake <= Plan::kMaxInlinePushes;
    if (loaded)
        push = Push::loaded_vector;  // (the gestures' loads: a few steps' work)
    else if (points.pushed())
        push = by_rows ? Push::point_rows : Push::vector;
    else if (!grid_rows)
        push = Push::vector;
    else
        push = forces == 0 ? Push::none : Push::rows;
    // What the next step reads of the state the pass leaves, formed while it holds it (one pass
    // over the modes instead of one per product): the next prediction at the points solved now
    // (a string resting on a bridge, a finger's pad: most are solved again), the awake points first.
    const bool fused = plan.options().fused_step;
    std::size_t first = 0;
    if (fused && !loaded && awake != 0 && by_rows) first = awake;
    forecast_points = first != 0;
    const std::size_t solved = grid.active().size() + parts.pad_points();
    forecast_grid = fused && solved != 0 && first + solved <= kernels::kMaxPassRows &&
                    solved <= plan.transform_threshold();
}

}  // namespace fretbuzz
