#include "fretbuzz/scheme/PadContacts.hpp"

#include <cmath>

#include "FingerPads.hpp"

namespace fretbuzz {

PadContacts::PadContacts(const Plan& plan) : plan_(&plan) {
    const std::size_t n = plan.mode_count();  // (a running string never allocates)
    pad_w_.reserve(n);
    pad_f_.reserve(n);
    joint_pads_.reserve(n);
    joint_w_.reserve(n);
    joint_trial_.reserve(n);
}

void PadContacts::solve(PlayedParts& parts, const ExactPluckers& pluckers, const StepRoute& route,
                        FreePrediction& prediction, GridContact& grid, ContactForces::List& forces,
                        const ModalState& modes, const ForceGestures& gestures, long n, StepRecord& record) {
    const bool use_transform = route.by_transform;
    const std::span<double> field = prediction.field();
    bool acted = false;
    joint_pads_.clear();
    joint_w_.clear();
    const auto solve = [&](PlayedPart& part, std::size_t k) {
        // The pad's predicted heights: from the transform, or the forecast and rows (into the field
        // at the pad's points, which are not active points: their values stay).
        if (!use_transform) prediction.at(part.pad(), modes);
        pad_w_.clear();
        for (std::size_t i : part.pad()) pad_w_.push_back(record.loaded ? field[i] + gestures.at_grid(i) : field[i]);
        if (route.fingers_joint && k < parts.fingers().size()) {  // stepped in the points' solve
            parts.finger(k).prepare(n);
            joint_pads_.insert(joint_pads_.end(), part.pad().begin(), part.pad().end());
            joint_w_.insert(joint_w_.end(), pad_w_.begin(), pad_w_.end());
            return;
        }
        pad_f_.assign(pad_w_.size(), 0.0);
        take(part, part.step(n, pad_w_, pad_f_), pad_f_, grid, forces, record);
        acted = acted || part.acted();
    };
    for (std::size_t k = 0; k < parts.size(); ++k) {
        if (!parts.on(k) || pluckers.is(k)) continue;  // (the exact pluckers have their own solve)
        if (parts[k].left()) {
            // Its pad's points join this step's obstacle solve below: they need this step's
            // predicted heights (formed for the active points only), loads included.
            const std::vector<std::size_t>& pad = parts[k].pad();
            if (!use_transform) prediction.at(pad, modes);
            if (record.loaded)
                for (std::size_t i : pad) field[i] += gestures.at_grid(i);
            retire(parts, parts[k], grid);
            parts.set_on(k, false);
            continue;
        }
        solve(parts[k], k);
    }
    record.played_by_parts(acted);
}

FingerPads PadContacts::joint(PlayedParts& parts) { return FingerPads(parts, joint_pads_, joint_w_, joint_trial_); }

void PadContacts::take_joint(const FingerPads& fingers, std::span<const double> force, GridContact& grid,
                             ContactForces::List& forces, StepRecord& record) {
    // The fingers' last trial is the joint solution: their steps move on with it.
    bool acted = false;
    fingers.each([&](Finger& finger, std::size_t, std::size_t at, std::size_t count) {
        take(finger, finger.commit(), force.subspan(at, count), grid, forces, record);
        acted = acted || finger.acted();
    });
    record.played_by_parts(acted);
}

void PadContacts::take(const PlayedPart& part, double obstacle_psi, std::span<const double> force, GridContact& grid,
                       ContactForces::List& forces, StepRecord& record) {
    grid.add_potential(obstacle_psi);
    record.iterations(part.max_iterations());
    record.touched_obstacle = record.touched_obstacle || part.touched_obstacle();
    for (std::size_t p = 0; p < force.size(); ++p)
        if (force[p] != 0.0) forces.emplace_back(part.pad()[p], force[p]);
}

void PadContacts::retire(PlayedParts& parts, const PlayedPart& part, GridContact& grid) const {
    const std::vector<std::size_t>& pad = part.pad();
    const std::vector<double>& g = plan_->obstacle();
    parts.release(pad);
    for (std::size_t p = 0; p < pad.size(); ++p)
        if (std::isfinite(g[pad[p]])) grid.activate(pad[p], g[pad[p]], part.current()[p], part.previous()[p]);
}

void PadContacts::pad_values(const std::vector<std::size_t>& pad, std::span<const double> field) {
    pad_w_.clear();
    for (std::size_t i : pad) pad_w_.push_back(field[i]);
}

void PadContacts::start(PlayedPart& part, std::span<const double> u_before, std::span<const double> u_now) {
    pad_values(part.pad(), u_now);
    pad_f_ = pad_w_;  // within the reserved capacity: no allocation
    pad_values(part.pad(), u_before);
    part.start(pad_w_, pad_f_);
}

}  // namespace fretbuzz
