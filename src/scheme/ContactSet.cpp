#include "fretbuzz/scheme/ContactSet.hpp"

#include <vector>

#include "FingerPads.hpp"
#include "fretbuzz/scheme/SecondPolarisation.hpp"

namespace fretbuzz {

ContactSet::ContactSet(const Plan& plan, const ForceGestures& gestures)
    : plan_(&plan),
      parts_(plan),
      pluckers_(plan, parts_, gestures),
      grid_(plan.mode_count()),
      points_(plan),
      prediction_(plan),
      pads_(plan),
      forces_(plan),
      pushes_(plan) {}

void ContactSet::first_step(ModalState& modes, Screening& screening) {
    const std::size_t n = modes.size();
    std::vector<double> u0(n);
    std::vector<double> pad_before(pluckers_.size());  // each exact plucker's u_s at level 0
    for (std::size_t j = 0; j < pluckers_.size(); ++j) pad_before[j] = modes.at(pluckers_.pluck(parts_, j).shape().data());
    const std::span<double> u1 = prediction_.field();
    plan_->basis().to_grid(modes.q(), u0);
    modes.first_step();
    plan_->basis().to_grid(modes.q(), u1);
    if (screening.on()) screening.start(modes, 1);
    grid_.classify(plan_->contact(), plan_->obstacle_points(), plan_->obstacle(), u1, u0, parts_.on_pad(),
                   screening.if_on());
    points_.start(modes);
    if (screening.on()) points_.put_to_sleep(screening.scheduler(), modes, false);
    // Each played part starts from the string under its pad at levels 0 and 1.
    for (std::size_t k = 0; k < parts_.size(); ++k) {
        if (pluckers_.is(k)) {
            const std::size_t j = k - pluckers_.first();
            pluckers_.start(parts_, j, pad_before[j], modes.at(pluckers_.pluck(parts_, j).shape().data()));
        } else {
            pads_.start(parts_[k], u0, u1);
        }
    }
}

void ContactSet::restart(const ModalState& modes, Screening& screening, long n) {
    // What the passes formed belongs to the state before the change.
    prediction_.forget();
    points_.forget_forecast();
    if (n == 0) return;  // the first step looks at everything anyway
    // u^n into the field, u^{n-1} = S (q - d) into the impulse (scratch until the next impulse),
    // where they are read: at the obstacle's points and the pads of the parts on the string. By
    // rows where these are at most the transform threshold (a real-time engine sets it beyond
    // every count where FFTW's transform would allocate), else by two transforms.
    const std::span<double> u_now = prediction_.field(), u_before = pushes_.impulse();
    const std::vector<std::size_t>& points = plan_->obstacle_points();
    if (points.size() + parts_.pad_points() > plan_->transform_threshold()) {
        AlignedVector& q_before = prediction_.modal();
        for (std::size_t j = 0; j < modes.size(); ++j) q_before[j] = modes.q()[j] - modes.d()[j];
        plan_->basis().to_grid(q_before, u_before);
        plan_->basis().to_grid(modes.q(), u_now);
    } else {
        const auto by_row = [&](std::size_t i) { modes.at_both(plan_->basis().row(i).data(), u_now[i], u_before[i]); };
        for (std::size_t i : points) by_row(i);
        parts_.each_on([&](const PlayedPart& part) {
            for (std::size_t i : part.pad()) by_row(i);
        });
    }
    screening.scheduler().clear();
    grid_.clear();
    points_.start(modes);
    if (screening.on()) {
        screening.start(modes, n);
        points_.put_to_sleep(screening.scheduler(), modes, false);
    }
    parts_.each_on([&](PlayedPart& part) { part.read_obstacle(plan_->obstacle()); });
    pluckers_.restart(parts_, modes);
    grid_.classify(plan_->contact(), points, plan_->obstacle(), u_now, u_before, parts_.on_pad(), screening.if_on());
}

void ContactSet::solve(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    forces_.list().clear();
    record.touched_obstacle = false;
    grid_.begin_step();
    record.stats.points_solved += static_cast<double>(grid_.active().size() + parts_.pad_points() + points_.awake());
    pluckers_.clear_loads();
    const bool pluckers_act = pluckers_.act(parts_);
    route_ = StepRoute::of_solve(*plan_, grid_, points_, pluckers_, parts_, pluckers_act);
    points_.set_pushed(false);  // (until a solve of the points says otherwise)
    switch (route_.off_grid) {
        case StepRoute::OffGrid::plucker_alone:
            grid_.add_potential(pluckers_.solve_alone(parts_, modes, gestures, n, record));
            break;
        case StepRoute::OffGrid::apart: solve_exact(modes, gestures, n, record); break;
        case StepRoute::OffGrid::none:
        case StepRoute::OffGrid::with_grid: break;  // (with_grid: in solve_on_grid)
    }
    if (route_.on_grid == StepRoute::OnGrid::none) {
        if (points_.pushed()) ++record.stats.contact_steps;
    } else {
        solve_on_grid(modes, gestures, n, record);
    }
    route_.choose_pushes(*plan_, grid_, points_, parts_, forces_.list().size(), record.loaded);
}

void ContactSet::solve_on_grid(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    // The predicted height at every point to solve.
    if (route_.by_transform)
        prediction_.everywhere(modes);
    else
        prediction_.at(grid_.active(), modes);
    const std::span<double> field = prediction_.field();
    if (record.loaded)
        for (std::size_t i : grid_.active()) field[i] += gestures.at_grid(i);
    if (!parts_.empty())
        pads_.solve(parts_, pluckers_, route_, prediction_, grid_, forces_.list(), modes, gestures, n, record);
    const double k = plan_->force_to_displacement();
    switch (route_.on_grid) {
        case StepRoute::OnGrid::with_points:
            grid_.gather_equations(plan_->obstacle(), field);
            solve_exact(modes, gestures, n, record);
            break;
        case StepRoute::OnGrid::batch:
            grid_.gather_equations(plan_->obstacle(), field);
            plan_->contact().solve_all(grid_.a(), grid_.b(), k, grid_.solutions());
            break;
        case StepRoute::OnGrid::none:
        case StepRoute::OnGrid::each: break;
    }
    grid_.solve(plan_->contact(), k, plan_->obstacle(), field, route_.on_grid != StepRoute::OnGrid::each,
                forces_.list(), record);
}

void ContactSet::solve_exact(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    const bool with_grid = route_.off_grid == StepRoute::OffGrid::with_grid;
    const PointContact& points = plan_->point_contact();
    if (!with_grid || !points.empty())
        points_.predict(modes, n, prediction_.modal(), record.loaded ? &gestures : nullptr);
    PointContact::Grid grid{grid_.active(), grid_.a(), grid_.b(), grid_.solutions(), plan_->basis().grid_step()};
    FingerPads fingers = pads_.joint(parts_);
    if (route_.fingers_joint) grid.pads = &fingers;
    // Each plucker at its exact position presses on its u_s, which every point's row (and every
    // other pad) overlaps: one more unknown each in the points' system (each acting plucker is
    // beside the grid or a finger where the grid joins).
    const bool pluckers = pluckers_.acting() != 0;
    const std::span<PointContact::Pad> pads =
        pluckers ? pluckers_.pads(parts_, modes, gestures, n, record.loaded, with_grid) : std::span<PointContact::Pad>();
    const double k = plan_->force_to_displacement();
    PointContact::State& state = points_.state();
    points_.set_pushed(with_grid ? points.solve(state, points_.predicted(), plan_->contact(), k, grid, pads)
                                 : points.solve(state, points_.predicted(), plan_->contact(), k, pads));
    if (pluckers) pluckers_.conclude(parts_, n, record);
    if (route_.fingers_joint) pads_.take_joint(fingers, state.pad_force, grid_, forces_.list(), record);
    if (with_grid && state.joint) ++record.stats.joint_steps;
    record.iterations(state.iterations);
    record.touched_obstacle = record.touched_obstacle || points_.pushed();
}

void ContactSet::step_friction(SecondPolarisation& y, long n) {
    const std::span<const double> point_forces =
        points_.pushed() ? std::span<const double>(points_.state().force) : std::span<const double>();
    y.step(n, forces_.rubbing(parts_), point_forces);
}

void ContactSet::fill_pass(kernels::StepPass& pass, const ForceGestures& gestures) {
    pushes_.fill(pass, route_.push, forces_.list(), prediction_.field(), points_, gestures, pluckers_, parts_);
    prediction_.ask(pass, route_, points_, grid_, parts_);
}

void ContactSet::end_step(Screening& screening, const ModalState& modes, long next) {
    prediction_.keep(points_, next);
    if (screening.on()) {
        ContactScheduler& scheduler = screening.scheduler();
        scheduler.end_step();
        // The bounds grow by the step's pushes, as the pass took them (else the bound is
        // recomputed from the motion as it is).
        if (!screening.refresh_after_step(modes, next)) pushes_.tell(scheduler, route_.push, modes, forces_.list(), points_);
        // A point out of contact over both recent levels, and far enough from the obstacle, leaves
        // the solve until the scheduler says it could be back.
        points_.put_to_sleep(scheduler, modes, true);
        grid_.put_to_sleep(scheduler, modes.q(), modes.d());
    }
    forces_.add_off_grid(points_, pluckers_);
}

bool ContactSet::lift_finger(std::size_t f) {
    if (!parts_.on(f)) return false;
    Finger& finger = parts_.finger(f);
    parts_.release(finger.pad());
    parts_.set_on(f, false);
    finger.rest();
    return true;
}

bool ContactSet::place_finger(std::size_t f, double centre_m, double width_m) {
    Finger& finger = parts_.finger(f);
    finger.place(centre_m, width_m, plan_->obstacle());
    if (!parts_.hold(finger.pad())) return false;  // another part acts there: the finger stays off
    parts_.set_on(f, true);
    return true;
}

void ContactSet::land(std::size_t f) {
    // Lands at rest on the highest pad point, as at the first step (u^{n-1}, u^n from the restart).
    pads_.start(parts_.finger(f), pushes_.impulse(), prediction_.field());
}

}  // namespace fretbuzz
