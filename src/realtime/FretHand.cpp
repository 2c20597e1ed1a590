#include "fretbuzz/realtime/FretHand.hpp"

#include <algorithm>
#include <cmath>

#include "fretbuzz/scheme/Finger.hpp"
#include "fretbuzz/numerics/TimeProfile.hpp"

namespace fretbuzz {

void FretHand::add_to(Case& c, double internal_rate_hz) {
    if (c.fret_positions_m.empty()) return;
    // Exact frets keep their exact positions beside the finger wherever it is placed (the Plan
    // solves it with them), so the frets stay where the case puts them whatever the mode count.
    const std::size_t frets = c.fret_positions_m.size();
    FingerSpec spare = c.fret_finger(1, "the engine's finger: fret");
    for (std::size_t k = 1; k <= frets; ++k) {
        const FingerSpec f = c.fret_finger(k, "fret");
        pads_.push_back({f.position_m, f.width_m});
        spare.width_m = std::max(spare.width_m, f.width_m);
    }
    // The pressing force of `fret = k`: a ramp from 0 to its last value.
    force_ = spare.force_profile.back()[1];
    ramp_steps_ = std::max(1L, std::lround(spare.force_profile.back()[0] * internal_rate_hz));
    spare.force_profile.clear();
    spare.default_force = false;
    finger_ = c.fingers.size();
    c.fingers.push_back(std::move(spare));
}

void FretHand::prepare_rows(Plan& plan, const Case& c) const {
    std::vector<std::size_t> pad;
    for (const auto& [centre, width] : pads_) {
        pad_points(centre, width, c.grid_step(), c.mode_count(), pad);
        for (std::size_t i : pad) plan.basis().row(i);
    }
}

bool FretHand::down(VibratingString& s, int k) {
    const auto& [centre, width] = pads_[static_cast<std::size_t>(k - 1)];
    const bool placed = s.place_finger(finger_, centre, width);
    if (placed) s.press_finger(finger_, force_, ramp_steps_);
    fret_ = placed ? k : 0;
    lifting_ = false;
    return placed;
}

void FretHand::up(VibratingString& s) {
    if (!on(s) || lifting_) return;
    s.press_finger(finger_, 0.0, ramp_steps_);  // changes no energy now
    lifting_ = true;
    lifted_at_ = s.step_index() + ramp_steps_;
    fret_ = 0;
}

bool FretHand::ready_to_retire(const VibratingString& s) const {
    if (!lifting_ || s.step_index() < lifted_at_) return false;
    const Finger& finger = s.contacts().parts().fingers()[finger_];
    return !finger.acted() && finger.contact_energy() == 0.0;
}

void FretHand::take_off(VibratingString& s) {
    if (present()) s.lift_finger(finger_);
    fret_ = 0;
    lifting_ = false;
}

}  // namespace fretbuzz
