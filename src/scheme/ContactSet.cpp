#include "fretbuzz/scheme/ContactSet.hpp"

#include <algorithm>
#include <cmath>

#include "FingerPads.hpp"

namespace fretbuzz {

ContactSet::ContactSet(const Plan& plan, const ForceGestures& gestures)
    : plan_(&plan),
      parts_(plan),
      pluckers_(plan, parts_, gestures),
      grid_(plan.mode_count()),
      points_(plan),
      predicted_(plan.mode_count(), 0.0),
      impulse_(plan.mode_count(), 0.0),
      field_(plan.mode_count(), 0.0) {
    // Every list the step fills is bounded by the grid: reserved once, so that a running string
    // never allocates (real-time use).
    const std::size_t n = plan.mode_count();
    forces_.reserve(n);
    pushes_.reserve(n + plan.point_contact().size());
    rubbing_.reserve(n);
    pad_w_.reserve(n);  // any pad, even one moved at run time (place_finger)
    pad_f_.reserve(n);
    joint_pads_.reserve(n);
    joint_w_.reserve(n);
    joint_trial_.reserve(n);
    others_.reserve(n);
}

void ContactSet::first_step(ModalState& modes, Screening& screening) {
    const std::size_t n = modes.size();
    std::vector<double> u0(n);
    std::vector<double> pad_before(pluckers_.size());  // each exact plucker's u_s at level 0
    for (std::size_t j = 0; j < pluckers_.size(); ++j) pad_before[j] = modes.at(pluckers_.pluck(parts_, j).shape().data());
    plan_->basis().to_grid(modes.q(), u0);
    modes.first_step();
    plan_->basis().to_grid(modes.q(), field_);
    if (screening.on()) screening.start(modes, 1);
    grid_.classify(plan_->contact(), plan_->obstacle_points(), plan_->obstacle(), field_, u0, parts_.on_pad(),
                   screening.if_on());
    points_.start(modes);
    if (screening.on()) points_.put_to_sleep(screening.scheduler(), modes, false);
    // Each played part starts from the string under its pad at levels 0 and 1.
    for (std::size_t k = 0; k < parts_.size(); ++k) {
        if (pluckers_.is(k)) {
            const std::size_t j = k - pluckers_.first();
            pluckers_.start(parts_, j, pad_before[j], modes.at(pluckers_.pluck(parts_, j).shape().data()));
        } else {
            start_part(parts_[k], u0, field_);
        }
    }
}

void ContactSet::forget_forecasts() {
    forecast_.count = 0;
    points_.forget_forecast();
}

void ContactSet::restart(const ModalState& modes, Screening& screening, long n) {
    // u^n into field_, u^{n-1} = S (q - d) into impulse_ (scratch until the next impulse), where
    // they are read: at the obstacle's points and the pads of the parts on the string. By
    // rows where these are at most the transform threshold (a real-time engine sets it beyond
    // every count where FFTW's transform would allocate), else by two transforms.
    const std::vector<std::size_t>& points = plan_->obstacle_points();
    if (points.size() + parts_.pad_points() > plan_->transform_threshold()) {
        for (std::size_t j = 0; j < modes.size(); ++j) predicted_[j] = modes.q()[j] - modes.d()[j];
        plan_->basis().to_grid(predicted_, impulse_);
        plan_->basis().to_grid(modes.q(), field_);
    } else {
        const auto by_row = [&](std::size_t i) { modes.at_both(plan_->basis().row(i).data(), field_[i], impulse_[i]); };
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
    grid_.classify(plan_->contact(), points, plan_->obstacle(), field_, impulse_, parts_.on_pad(), screening.if_on());
}

void ContactSet::solve(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    forces_.clear();
    record.touched_obstacle = false;
    grid_.begin_step();
    record.stats.points_solved += static_cast<double>(grid_.active().size() + parts_.pad_points() + points_.awake());
    pluckers_.clear_loads();
    route_ = route_of(pluckers_.act(parts_));
    points_.set_pushed(false);  // (until a solve of the points says otherwise)
    switch (route_.off_grid) {
        case StepRoute::OffGrid::plucker_alone:
            grid_.add_potential(pluckers_.solve_alone(parts_, modes, gestures, n, record));
            break;
        case StepRoute::OffGrid::apart: points_.set_pushed(solve_points(modes, gestures, n, record)); break;
        case StepRoute::OffGrid::none:
        case StepRoute::OffGrid::with_grid: break;  // (with_grid: in solve_on_grid)
    }
    if (route_.on_grid == StepRoute::OnGrid::none) {
        if (points_.pushed()) ++record.stats.contact_steps;
    } else {
        solve_on_grid(modes, gestures, n, record);
    }
    route_pushes(record.loaded);
}

StepRoute ContactSet::route_of(bool pluckers) const {
    StepRoute route;
    const bool grid_awake = !grid_.active().empty();
    const std::size_t awake = points_.awake(), acting = pluckers_.acting();
    // The exact pluckers beside awake obstacle points of the grid or a finger: one solve with them.
    const bool pluck_with_grid = pluckers && (grid_awake || parts_.fingers_on());
    // Exact points (or the exact pluckers) beside awake obstacle points of the grid or a finger's
    // pad: all in one solve (see PointContact).
    const bool coupled_points = plan_->point_contact().grid_coupled() && awake != 0;
    const bool fingers_with_points = (coupled_points || pluck_with_grid) && parts_.fingers_on();
    route.fingers_joint = fingers_with_points;
    const bool all_in_one = pluck_with_grid || (coupled_points && grid_awake) || fingers_with_points;
    // A single plucker with nothing beside it: its own scalar solve; several: solved together
    // (their pads move one another), with the exact points where any is awake.
    const bool pads_alone = awake == 0 && !pluck_with_grid;
    if (all_in_one)
        route.off_grid = StepRoute::OffGrid::with_grid;
    else if (pads_alone && acting == 1)
        route.off_grid = StepRoute::OffGrid::plucker_alone;
    else if (awake != 0 || (pads_alone && acting > 1))
        route.off_grid = StepRoute::OffGrid::apart;
    const std::size_t solved = grid_.active().size() + parts_.pad_points();
    if (solved == 0) return route;  // (on_grid: none)
    // The predicted height at every point to solve: by one transform where there are many, and
    // then their equations together (a string landing on a long obstacle: the same solutions).
    const bool many = solved > plan_->transform_threshold();
    route.by_transform = many;
    if (all_in_one)
        route.on_grid = StepRoute::OnGrid::with_points;
    else if (many)
        route.on_grid = StepRoute::OnGrid::batch;
    else
        route.on_grid = StepRoute::OnGrid::each;
    return route;
}

void ContactSet::solve_on_grid(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    // The predicted height at every point to solve, into field_.
    if (route_.by_transform) {
        modes.predict(predicted_);
        plan_->basis().to_grid(predicted_, field_);
    } else {
        predict_points(grid_.active(), modes);
    }
    if (record.loaded)
        for (std::size_t i : grid_.active()) field_[i] += gestures.at_grid(i);
    if (!parts_.empty()) solve_fingers(modes, gestures, n, record);
    const double k = plan_->force_to_displacement();
    switch (route_.on_grid) {
        case StepRoute::OnGrid::with_points:
            grid_.gather_equations(plan_->obstacle(), field_);
            solve_with_grid(modes, gestures, n, record);
            break;
        case StepRoute::OnGrid::batch:
            grid_.gather_equations(plan_->obstacle(), field_);
            plan_->contact().solve_all(grid_.a(), grid_.b(), k, grid_.solutions());
            break;
        case StepRoute::OnGrid::none:
        case StepRoute::OnGrid::each: break;
    }
    grid_.solve(plan_->contact(), k, plan_->obstacle(), field_, route_.on_grid != StepRoute::OnGrid::each, forces_,
                record);
}

void ContactSet::route_pushes(bool loaded) {
    // The pass pushes with the exact points' rows (and the grid's) where they fit in it; it
    // forms the next prediction at the awake points too where the step is fused.
    const std::size_t awake = points_.awake(), forces = forces_.size();  // (resting points push nothing)
    const bool grid_rows = forces == 0 || plan_->pushes_inline(forces);
    const bool by_rows = grid_rows && awake <= kernels::kMaxPassRows && forces + awake <= Plan::kMaxInlinePushes;
    using Push = StepRoute::Push;
    if (loaded)
        route_.push = Push::loaded_vector;  // (the gestures' loads: a few steps' work)
    else if (points_.pushed())
        route_.push = by_rows ? Push::point_rows : Push::vector;
    else if (!grid_rows)
        route_.push = Push::vector;
    else
        route_.push = forces == 0 ? Push::none : Push::rows;
    // What the next step reads of the state the pass leaves, formed while it holds it (one pass
    // over the modes instead of one per product): the next prediction at the points solved now
    // (a string resting on a bridge, a finger's pad: most are solved again), the awake points first.
    const bool fused = plan_->options().fused_step;
    std::size_t first = 0;
    if (fused && !loaded && awake != 0 && by_rows) first = awake;
    route_.forecast_points = first != 0;
    const std::size_t solved = grid_.active().size() + parts_.pad_points();
    route_.forecast_grid = fused && solved != 0 && first + solved <= kernels::kMaxPassRows &&
                           solved <= plan_->transform_threshold();
}

void ContactSet::predict_points(std::span<const std::size_t> points, const ModalState& modes) {
    // The last step's pass formed the prediction at the points it was given: most often these
    // very points, in this order (a string resting on a point or a bridge).
    const Forecast& f = forecast_;
    if (points.size() == f.count && std::equal(points.begin(), points.end(), f.points.begin())) {
        for (std::size_t r = 0; r < points.size(); ++r) field_[points[r]] = f.values[r];
        return;
    }
    // The others (woken since, or no forecast): row products, the prediction formed on the fly
    // for a few, stored first for many (then read by each pass of rows).
    others_.clear();
    for (std::size_t i : points) {
        std::size_t r = 0;
        while (r < f.count && f.points[r] != i) ++r;
        if (r < f.count)
            field_[i] = f.values[r];
        else
            others_.push_back(i);
    }
    if (others_.empty()) return;
    if (others_.size() <= kernels::kMaxRowsPerPass) {
        plan_->predicted_at(others_, {}, modes.q(), modes.d(), field_);
        return;
    }
    modes.predict(predicted_);
    plan_->predicted_at(others_, predicted_, modes.q(), modes.d(), field_);
}

void ContactSet::solve_fingers(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    const bool use_transform = route_.by_transform;
    bool acted = false;
    joint_pads_.clear();
    joint_w_.clear();
    const auto solve = [&](PlayedPart& part, std::size_t k) {
        // The pad's predicted heights: from the transform, or the forecast and rows (into field_
        // at the pad's points, which are not active points: their values stay).
        if (!use_transform) predict_points(part.pad(), modes);
        pad_w_.clear();
        for (std::size_t i : part.pad()) pad_w_.push_back(record.loaded ? field_[i] + gestures.at_grid(i) : field_[i]);
        if (route_.fingers_joint && k < parts_.fingers().size()) {  // stepped in the points' solve
            parts_.finger(k).prepare(n);
            joint_pads_.insert(joint_pads_.end(), part.pad().begin(), part.pad().end());
            joint_w_.insert(joint_w_.end(), pad_w_.begin(), pad_w_.end());
            return;
        }
        pad_f_.assign(pad_w_.size(), 0.0);
        take_part(part, part.step(n, pad_w_, pad_f_), pad_f_, record);
        acted = acted || part.acted();
    };
    for (std::size_t k = 0; k < parts_.size(); ++k) {
        if (!parts_.on(k) || pluckers_.is(k)) continue;  // (the exact pluckers have their own solve)
        if (parts_[k].left()) {
            // Its pad's points join this step's obstacle solve below: they need this step's
            // predicted heights (formed above for the active points only), loads included.
            const std::vector<std::size_t>& pad = parts_[k].pad();
            if (!use_transform) predict_points(pad, modes);
            if (record.loaded)
                for (std::size_t i : pad) field_[i] += gestures.at_grid(i);
            retire(parts_[k]);
            parts_.set_on(k, false);
            continue;
        }
        solve(parts_[k], k);
    }
    record.played_by_parts(acted);
}

void ContactSet::take_part(const PlayedPart& part, double obstacle_psi, std::span<const double> force, StepRecord& record) {
    grid_.add_potential(obstacle_psi);
    record.iterations(part.max_iterations());
    record.touched_obstacle = record.touched_obstacle || part.touched_obstacle();
    for (std::size_t p = 0; p < force.size(); ++p)
        if (force[p] != 0.0) forces_.emplace_back(part.pad()[p], force[p]);
}

void ContactSet::retire(const PlayedPart& part) {
    // The part has left the string (a plucker gone): its pad points go back to the obstacle's
    // own solve (the loop over active points that follows solves them in this same step).
    const std::vector<std::size_t>& pad = part.pad();
    const std::vector<double>& g = plan_->obstacle();
    parts_.release(pad);
    for (std::size_t p = 0; p < pad.size(); ++p)
        if (std::isfinite(g[pad[p]])) grid_.activate(pad[p], g[pad[p]], part.current()[p], part.previous()[p]);
}

void ContactSet::pad_values(const std::vector<std::size_t>& pad, std::span<const double> field) {
    pad_w_.clear();
    for (std::size_t i : pad) pad_w_.push_back(field[i]);
}

void ContactSet::start_part(PlayedPart& part, std::span<const double> u_before, std::span<const double> u_now) {
    pad_values(part.pad(), u_now);
    pad_f_ = pad_w_;  // within the reserved capacity: no allocation
    pad_values(part.pad(), u_before);
    part.start(pad_w_, pad_f_);
}

bool ContactSet::solve_points(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    points_.predict(modes, n, predicted_, record.loaded ? &gestures : nullptr);
    const PointContact& points = plan_->point_contact();
    const double k = plan_->force_to_displacement();
    bool pushed = false;
    if (pluckers_.acting() != 0) {
        // Each plucker at its exact position presses on its u_s, which every point's row (and
        // every other pad) overlaps: one more unknown each in the points' system.
        pushed = points.solve(points_.state(), points_.predicted(), plan_->contact(), k,
                              pluckers_.pads(parts_, modes, gestures, n, record.loaded, false));
        pluckers_.conclude(parts_, n, record);
    } else {
        pushed = points.solve(points_.state(), points_.predicted(), plan_->contact(), k);
    }
    record.iterations(points_.state().iterations);
    record.touched_obstacle = record.touched_obstacle || pushed;
    return pushed;
}

void ContactSet::solve_with_grid(const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    const bool with_fingers = route_.fingers_joint;
    const PointContact& points = plan_->point_contact();
    if (!points.empty()) points_.predict(modes, n, predicted_, record.loaded ? &gestures : nullptr);
    PointContact::Grid grid{grid_.active(), grid_.a(), grid_.b(), grid_.solutions(), plan_->basis().grid_step()};
    FingerPads pads(parts_, joint_pads_, joint_w_, joint_trial_);
    if (with_fingers) grid.pads = &pads;
    const double k = plan_->force_to_displacement();
    PointContact::State& state = points_.state();
    if (pluckers_.acting() != 0) {  // (each acting plucker is beside the grid or a finger here)
        points_.set_pushed(points.solve(state, points_.predicted(), plan_->contact(), k, grid,
                                        pluckers_.pads(parts_, modes, gestures, n, record.loaded, true)));
        pluckers_.conclude(parts_, n, record);
    } else {
        points_.set_pushed(points.solve(state, points_.predicted(), plan_->contact(), k, grid));
    }
    if (with_fingers) {
        // The fingers' last trial is the joint solution: their steps move on with it.
        bool acted = false;
        pads.each([&](Finger& finger, std::size_t, std::size_t at, std::size_t count) {
            take_part(finger, finger.commit(), std::span<const double>(state.pad_force).subspan(at, count), record);
            acted = acted || finger.acted();
        });
        record.played_by_parts(acted);
    }
    if (state.joint) ++record.stats.joint_steps;
    record.iterations(state.iterations);
    record.touched_obstacle = record.touched_obstacle || points_.pushed();
}

void ContactSet::form_impulse() {
    if (forces_.empty())
        std::fill(impulse_.begin(), impulse_.end(), 0.0);
    else
        plan_->forces_to_modes(forces_, field_, impulse_);
    if (points_.pushed()) points_.add_impulse(plan_->force_to_displacement(), impulse_);
}

void ContactSet::fill_pass(kernels::StepPass& pass, const ForceGestures& gestures) {
    std::size_t pushes = 0;
    switch (route_.push) {
        case StepRoute::Push::none: break;
        case StepRoute::Push::vector:
            form_impulse();
            pass.impulse = impulse_.data();
            break;
        case StepRoute::Push::loaded_vector: {
            form_impulse();
            const double k = plan_->force_to_displacement();
            gestures.add_impulse(k, impulse_);
            pluckers_.add_impulse(parts_, k, impulse_);
            pass.impulse = impulse_.data();
            break;
        }
        case StepRoute::Push::point_rows: {
            const PointContact& points = plan_->point_contact();
            const PointContact::State& state = points_.state();
            for (std::size_t p = 0; p < points.size(); ++p)
                if (state.force[p] != 0.0) {
                    rows_.coefficients[pushes] = plan_->force_to_displacement() * points.weight(p) * state.force[p];
                    rows_.push[pushes++] = points.row(p).data();
                }
        }
            [[fallthrough]];
        case StepRoute::Push::rows:
            for (const auto& [i, f] : forces_) {
                rows_.coefficients[pushes] = plan_->impulse_scale() * f;
                rows_.push[pushes++] = plan_->basis().row(i).data();
            }
            pass.push_rows = rows_.push.data();
            pass.push_coefficients = rows_.coefficients.data();
            pass.pushes = pushes;
            break;
    }
    // The forecasts: the awake exact points', then the grid's active points and pads.
    std::size_t count = route_.forecast_points ? points_.awake_rows(rows_.which.data(), rows_.predict.data()) : 0;
    rows_.awake = count;
    forecast_.count = 0;
    if (route_.forecast_grid) {
        const auto add = [&](std::size_t i) {
            forecast_.points[forecast_.count++] = i;
            rows_.predict[count++] = plan_->basis().row(i).data();
        };
        for (std::size_t i : grid_.active()) add(i);
        parts_.each_on([&](const PlayedPart& part) {
            for (std::size_t i : part.pad()) add(i);
        });
    }
    pass.predict_rows = rows_.predict.data();
    pass.predict_count = count;
    pass.predicted = rows_.values.data();
}

void ContactSet::tell_screening(Screening& screening, const ModalState& modes, long next) {
    ContactScheduler& scheduler = screening.scheduler();
    scheduler.end_step();
    if (!screening.refresh_after_step(modes, next)) {  // (else the bound is recomputed from the motion as it is)
        // The motion from here on is a new free motion: the bounds grow by the step's pushes,
        // as the pass took them.
        switch (route_.push) {
            case StepRoute::Push::none: break;
            case StepRoute::Push::vector:
            case StepRoute::Push::loaded_vector: scheduler.pushed(modes.q(), modes.d(), impulse_); break;
            case StepRoute::Push::rows:
                scheduler.pushed(modes.q(), modes.d(), forces_, plan_->impulse_scale());
                break;
            case StepRoute::Push::point_rows: {
                // Each push times its point's weight (exact point p screened as N + p, its force
                // as one per dx).
                pushes_.assign(forces_.begin(), forces_.end());
                const PointContact& points = plan_->point_contact();
                const PointContact::State& state = points_.state();
                const double dx = plan_->basis().grid_step();
                for (std::size_t p = 0; p < points.size(); ++p)
                    if (state.force[p] != 0.0) pushes_.emplace_back(modes.size() + p, points.weight(p) * state.force[p] / dx);
                scheduler.pushed(modes.q(), modes.d(), pushes_, plan_->impulse_scale());
                break;
            }
        }
    }
    // A point out of contact over both recent levels, and far enough from the obstacle, leaves
    // the solve until the scheduler says it could be back.
    points_.put_to_sleep(scheduler, modes, true);
    grid_.put_to_sleep(scheduler, modes.q(), modes.d());
}

void ContactSet::report_force_at(double x, double force) {
    // As a force per length at the grid point nearest x, the same total force.
    const double dx = plan_->basis().grid_step();
    const double index = std::clamp(std::round(x / dx) - 1.0, 0.0, static_cast<double>(plan_->mode_count() - 1));
    forces_.emplace_back(static_cast<std::size_t>(index), force / dx);
}

void ContactSet::report_off_grid() {
    const auto report = [this](double x, double force) { report_force_at(x, force); };
    if (points_.pushed()) points_.each_force(report);
    pluckers_.each_force(*plan_, report);
}

bool ContactSet::quiet() const {
    return parts_.pad_points() == 0 && !pluckers_.any_on(parts_) && points_.awake() == 0 && grid_.active().empty() &&
           grid_.at_rest();
}

double ContactSet::energy() const { return grid_.energy(plan_->basis().grid_step()) + points_.energy(plan_->contact()); }

std::span<const double> ContactSet::point_forces() const {
    return points_.pushed() ? std::span<const double>(points_.state().force) : std::span<const double>();
}

std::span<const std::pair<std::size_t, double>> ContactSet::rubbing_points() {
    // Friction along y acts where the string is pressed along z: on the obstacle, and under a
    // finger (which does not move along y) with the finger's push plus the obstacle's. Force
    // gestures and pluckers drag nothing sideways.
    if (parts_.pad_points() == 0) return forces_;
    rubbing_.clear();
    for (const auto& [i, f] : forces_)
        if (!parts_.on_pad(i)) rubbing_.emplace_back(i, f);
    parts_.each_on([&](const PlayedPart& part) {
        for (std::size_t p = 0; p < part.pad().size(); ++p)
            if (const double f = part.rubbing_force(p); f > 0.0) rubbing_.emplace_back(part.pad()[p], f);
    });
    return rubbing_;
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
    start_part(parts_.finger(f), impulse_, field_);  // lands at rest on the highest pad point, as at the first step
}

}  // namespace fretbuzz
